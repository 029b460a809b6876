"""An object photographed from several sides in the results: a picture per view (views/<photo>.png: the crop
beside the object drawn as that view sees it, with the fused albedo), named from the photo safely, recorded in
material.json and listed by the gallery's data; its mesh carries the fused texture; a single photo's object is
listed without views or coverage."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest
import torch
from PIL import Image

from radar_cli.derender.export import mesh
from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.multiview.fit import ViewFit
from radar_cli.derender.multiview.pictures import VIEW_TILE, picture_names
from radar_cli.derender.present.gallery import view_entries
from radar_cli.derender.present.report import write_report
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor
from radar_cli.render.texture import front_third, full_from_front

from .conftest import SETUP, FakeModel, write_photo
from .test_gallery import gallery_data

COLOURS = {"front": (170, 40, 30), "back": (30, 50, 170), "side": (40, 150, 50)}  # a pot painted differently all round


def coloured_photo(path: Path, colour: tuple[int, int, int]) -> None:
    """A one-colour ellipse on a light backdrop (conftest.vase_photo's shape)."""
    h = w = 80
    yy, xx = np.mgrid[0:h, 0:w]
    inside = ((xx - w / 2) / (0.2 * h)) ** 2 + ((yy - h / 2) / (0.35 * h)) ** 2 < 1
    image = np.full((h, w, 3), 225, np.uint8)
    image[inside] = colour
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(image).save(path)


def derender_pot(root: Path) -> Path:
    """root/out with `pot` (three photos of different colours and an unreadable one) and `single` (one photo)
    de-rendered by the fake model; returns root/out."""
    for name, colour in COLOURS.items():
        coloured_photo(root / "in" / "pot" / f"{name}.png", colour)
    (root / "in" / "pot" / "broken.jpg").write_bytes(b"not a jpeg")
    write_photo(root / "in" / "single.png", 1, (80, 80))
    options = DerenderOptions(out=root / "out", export=ExportConfig(views=2, view_size=32))
    summary = derender([root / "in"], Predictor(FakeModel(), SETUP, "fake-model", "cpu"), options,
                       say=lambda line: None)
    assert sorted(summary.done) == ["pot", "single"]
    return root / "out"


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> Path:
    return derender_pot(tmp_path_factory.mktemp("views"))


def test_every_readable_view_gets_its_picture_recorded(results: Path) -> None:
    record = json.loads((results / "pot" / "material.json").read_text())
    views = {Path(v["source"]).stem: v for v in record["views"]}
    assert views["broken"]["picture"] is None and not (results / "pot" / "views" / "broken.png").exists()
    for name in COLOURS:
        assert views[name]["picture"] == f"views/{name}.png"
        with Image.open(results / "pot" / views[name]["picture"]) as im:
            picture = np.asarray(im.convert("RGB"))
        used = views[name]["used"]
        assert picture.shape == ((VIEW_TILE, 2 * VIEW_TILE, 3) if used else (VIEW_TILE, VIEW_TILE, 3))
        photo = picture[:, :VIEW_TILE].reshape(-1, 3).astype(int)
        assert np.abs(photo - COLOURS[name]).max(axis=1).min() < 20  # the left tile is this view's photograph
        if used:
            drawing = picture[:, VIEW_TILE:]
            assert (drawing.min(axis=-1) < 200).mean() > 0.1  # the object drawn over white
    assert sum(v["used"] for v in views.values()) >= 2
    assert not (results / "single" / "views").exists()


def test_the_drawing_shows_the_view_its_own_side_of_the_fused_texture(results: Path) -> None:
    """Each used view's drawing is turned to its own side: its colour is nearer its photo's than the other
    views' are (the fused albedo holds every side)."""
    record = json.loads((results / "pot" / "material.json").read_text())
    used = [v for v in record["views"] if v["used"]]
    for view in used:
        with Image.open(results / "pot" / view["picture"]) as im:
            drawing = np.asarray(im.convert("RGB"))[:, VIEW_TILE:].reshape(-1, 3).astype(float)
        on_object = drawing[drawing.min(axis=1) < 200]
        chroma = on_object / on_object.sum(axis=1, keepdims=True)
        mean = chroma.mean(axis=0)
        own = COLOURS[Path(view["source"]).stem]
        distance = {name: np.abs(mean - np.array(c) / sum(c)).sum() for name, c in COLOURS.items()}
        assert min(distance, key=distance.get) == Path(view["source"]).stem, (own, mean, distance)


def glb_texture(path: Path) -> np.ndarray:
    """The base colour texture embedded in a GLB, H x W x 3 uint8."""
    with Image.open(io.BytesIO(mesh.glb_texture(path.read_bytes()))) as im:
        return np.asarray(im.convert("RGB"))


def mirror_difference(texture: np.ndarray) -> float:
    """Mean |texture - its front third mirrored round| over the back third, levels (0: a single view's map)."""
    t = torch.from_numpy(texture.copy()).permute(2, 0, 1)[None].float()
    mirrored = full_from_front(front_third(t))
    w = t.shape[-1]
    back = lambda x: torch.cat([x[..., : w // 6], x[..., -w // 6 :]], -1)  # noqa: E731
    return float((back(t) - back(mirrored)).abs().mean())


def test_the_mesh_carries_the_fused_texture(results: Path) -> None:
    for name in ("pot", "single"):
        with Image.open(results / name / "albedo.png") as im:
            assert np.array_equal(glb_texture(results / name / "mesh.glb"), np.asarray(im.convert("RGB")))
    assert mirror_difference(glb_texture(results / "single" / "mesh.glb")) < 1.0
    assert mirror_difference(glb_texture(results / "pot" / "mesh.glb")) > 10.0  # the back from the other views


def test_the_gallery_lists_the_views_and_single_objects_without_them(results: Path) -> None:
    write_report(results, [])
    objects = {o["id"]: o for o in gallery_data(results)["objects"]}
    assert objects["single"]["views"] == [] and not objects["single"]["coverage"]
    pot = objects["pot"]
    assert pot["coverage"] and pot["thumbnail"]
    assert [v["name"] for v in pot["views"]][:1] == ["front"]  # the first view first
    by_name = {v["name"]: v for v in pot["views"]}
    assert set(by_name) == {"front", "back", "side", "broken"}
    assert by_name["broken"]["picture"] is None and not by_name["broken"]["used"]
    assert "unreadable" in by_name["broken"]["reason"]
    assert by_name["front"] == {"name": "front", "picture": "views/front.png", "used": True, "reason": "",
                                "turn_deg": 0.0}
    assert all(isinstance(v["turn_deg"], float) for v in pot["views"] if v["used"])


def test_picture_names_are_safe_and_unique() -> None:
    views = [ViewFit(source, prepared) for source, prepared in
             [("/p/front.jpg", object()), ("/p/front.png", object()), ("/p/a b;rm.jpg", object()),
              ("/p/..jpg", object()), ("/p/broken.jpg", None), ("/p/FRONT.tif", object())]]
    assert picture_names(views) == ["views/front.png", "views/front-2.png", "views/a_b_rm.png", "views/view4.png",
                                    None, "views/FRONT-3.png"]


def test_the_gallery_ignores_picture_names_radar_does_not_write(tmp_path: Path) -> None:
    (tmp_path / "views").mkdir()
    (tmp_path / "views" / "front.png").write_bytes(b"")
    rec = {"views": [{"source": "/x/front.jpg", "used": True, "picture": "views/front.png", "turn_deg": 0.0},
                     {"source": "/x/a.jpg", "used": True, "picture": "../../secret.png", "turn_deg": 90.0},
                     {"source": "/x/b.jpg", "used": True, "picture": "views/../material.png", "turn_deg": "x"},
                     {"source": "/x/c.jpg", "used": False, "picture": "views/missing.png"}, "not a view"]}
    entries = view_entries(tmp_path, rec)
    assert [e["picture"] for e in entries] == ["views/front.png", None, None, None]
    assert [e["turn_deg"] for e in entries] == [0.0, 90.0, None, None]
    assert view_entries(tmp_path, {"views": "nonsense"}) == [] and view_entries(tmp_path, {}) == []
