"""`radar derender` end to end with a hand-built model: the folder layout, every file type opening with its usual
reader, failures, resuming and --overwrite."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import cv2
import numpy as np
import pytest
import trimesh
from click.testing import CliRunner
from PIL import Image

from radar_cli.cli import cli
from radar_cli.derender.export.mesh import OBJ_HEADER, OBJ_MTL, TEXTURE_PNG, glb_texture
from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor
from radar_cli.results import MATERIAL_KEYS, ResultPaths, list_results

from .conftest import SETUP, SIZE, write_photo
from .test_gallery import gallery_data

EXPORT = ExportConfig(views=4, view_size=32)
PNGS = ("input.png", "mask.png", "mask_front.png", "albedo.png", "texture.png", "normal.png", "diffuse.png",
        "specular.png", "env_map.png", "recon.png", "albedo_rendered.png", "normal_rendered.png",
        "material_sphere.png", "turntable.png", "relit_studio.png", "relit_sunset.png", "relit_overcast.png",
        "relit_two_lights.png", "relit_gallery.png")


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> Path:
    """Two photos (one square, one needing a crop) de-rendered once for the layout tests."""
    from .conftest import FakeModel

    root = tmp_path_factory.mktemp("derender")
    write_photo(root / "in" / "square.png", 1, (80, 80))
    write_photo(root / "in" / "wide.jpg", 2, (96, 144))
    predictor = Predictor(FakeModel(), SETUP, "fake-model", "cpu")
    gallery_env = root / "gallery.hdr"  # a user environment map, any size: resampled to the model's
    cv2.imwrite(str(gallery_env), np.ones((10, 20, 3), np.float32))
    options = DerenderOptions(out=root / "out", envs=(gallery_env,), export=EXPORT, resolution=SIZE)
    summary = derender([root / "in"], predictor, options)
    assert summary.done == ["square", "wide"] and not summary.failures
    return root / "out"


def test_layout_and_readers(results: Path) -> None:
    folders = list_results(results)
    assert [p.folder.name for p in folders] == ["square", "wide"]
    for paths in folders:
        assert paths.is_complete()
        for name in PNGS:
            with Image.open(paths.folder / name) as im:
                im.load()
                assert im.size[0] >= 8
        with Image.open(paths.folder / "input.png") as im:
            assert im.size == (SIZE, SIZE)
        with Image.open(paths.folder / "albedo.png") as im:
            assert im.size == (3 * SETUP.render.tex_width, SETUP.render.tex_height)  # 360 deg
        with Image.open(paths.folder / "turntable.gif") as im:
            assert im.n_frames == EXPORT.views
        env = np.load(paths.env_map)
        assert env.shape == (SETUP.render.env_height, SETUP.render.env_width) and env.dtype == np.float32
        hdr = cv2.imread(str(paths.folder / "env_map.hdr"), cv2.IMREAD_UNCHANGED)
        np.testing.assert_allclose(hdr[..., 0], env, rtol=0.02, atol=1e-3)  # RGBE keeps ~1% precision
        material = json.loads(paths.material.read_text())
        assert set(MATERIAL_KEYS) <= set(material)
        assert len(material["radius"]) == SETUP.geometry.n_rows and material["model"] == "fake-model"
        assert material["roughness"] == pytest.approx(np.sqrt(2 / (material["alpha"] + 2)))


def test_meshes_load_with_texture(results: Path) -> None:
    folder = results / "square"
    scene = trimesh.load(folder / "mesh.glb")
    (mesh,) = scene.geometry.values()
    assert len(mesh.faces) > 0 and mesh.visual.uv.min() >= 0 and mesh.visual.uv.max() <= 1
    texture = mesh.visual.material.baseColorTexture
    assert texture.size == (3 * SETUP.render.tex_width, SETUP.render.tex_height)
    alpha = json.loads((folder / "material.json").read_text())["alpha"]
    assert mesh.visual.material.roughnessFactor == pytest.approx(np.sqrt(2 / (alpha + 2)), rel=1e-4)
    obj = trimesh.load(folder / "mesh.obj")
    assert len(obj.faces) == len(mesh.faces)
    assert obj.visual.material.image.size == texture.size


def test_the_obj_texture_and_material_are_trimesh_s(results: Path) -> None:
    """albedo.png is the PNG inside mesh.glb (encoded once), and it and mesh.mtl are the bytes trimesh's OBJ
    exporter writes for that texture and material."""
    folder = results / "square"
    png = (folder / "albedo.png").read_bytes()
    assert png == glb_texture((folder / "mesh.glb").read_bytes())
    obj = trimesh.load(folder / "mesh.obj")
    texture = Image.open(io.BytesIO(png))
    texture.encoderinfo = dict(TEXTURE_PNG)
    texture.format = None  # as build_mesh's image from an array
    material = obj.visual.material
    files, name = trimesh.visual.material.SimpleMaterial(
        name="albedo", image=texture, diffuse=material.diffuse, ambient=material.ambient,
        specular=material.specular, glossiness=material.glossiness).to_obj(name="albedo")
    assert files["albedo.png"] == png
    assert (folder / OBJ_MTL).read_bytes() == f"# {OBJ_HEADER}\n\n".encode() + files[f"{name}.mtl"]


def test_crop_box_recorded(results: Path) -> None:
    wide = json.loads((results / "wide" / "material.json").read_text())
    x0, y0, side = wide["crop_box"]
    assert wide["photo_size"] == [144, 96]
    # the object (a centred ellipse 67 px tall) fills ~85% of a square crop around the photo's centre
    assert 65 <= side <= 95 and abs(x0 + side / 2 - 72) < 4 and abs(y0 + side / 2 - 48) < 4


def test_a_leaning_photo_is_straightened_and_its_turn_recorded(tmp_path: Path) -> None:
    from .conftest import FakeModel

    photo = np.full((144, 144, 3), 225, np.uint8)
    cv2.ellipse(photo, (72, 72), (24, 44), 4.0, 0, 360, (90, 60, 40), -1)  # its axis 4 deg clockwise of vertical
    (tmp_path / "in").mkdir()
    cv2.imwrite(str(tmp_path / "in" / "leaning.png"), photo)
    options = DerenderOptions(out=tmp_path / "out", export=EXPORT, resolution=SIZE)
    summary = derender([tmp_path / "in"], Predictor(FakeModel(), SETUP, "fake-model", "cpu"), options)
    assert summary.done == ["leaning"]
    material = json.loads((tmp_path / "out" / "leaning" / "material.json").read_text())
    assert material["crop_turn"] == pytest.approx(4.0, abs=1.0)  # turned back counter-clockwise
    with open(tmp_path / "out" / "summary.csv", newline="") as table:
        assert float(next(csv.DictReader(table))["crop_turn"]) == material["crop_turn"]
    silhouette = np.asarray(Image.open(tmp_path / "out" / "leaning" / "silhouette.png")) > 127
    rows = np.nonzero(silhouette.any(1))[0]
    mids = [np.nonzero(silhouette[y])[0].mean() for y in rows]
    assert abs(np.degrees(np.arctan(np.polyfit(rows, mids, 1)[0]))) < 1.5  # upright in the crop


def test_gallery_and_summary(results: Path) -> None:
    page = (results / "index.html").read_text()
    assert "http" not in page  # no network needed
    objects = {o["id"]: o for o in gallery_data(results)["objects"]}
    assert sorted(objects) == ["square", "wide"]
    assert objects["wide"]["relit"] == ["gallery", "overcast", "studio", "sunset", "two_lights"]  # --env's too
    for src in ("square/recon.png", "wide/turntable.gif", "wide/relit_gallery.png", "square/mesh.glb",
                "square/thumbnail.png", "wide/env_viewer.hdr"):
        assert (results / src).is_file()
    rows = list(csv.DictReader((results / "summary.csv").open()))
    assert [r["object"] for r in rows] == ["square", "wide"] and float(rows[0]["alpha"]) > 0
    assert (results / "failures.csv").read_text().strip() == "source,problem"


def test_cli_bad_inputs_one_line_each(tmp_path: Path, fake_checkpoint) -> None:
    good = write_photo(tmp_path / "good.png", 3)
    corrupt = tmp_path / "corrupt.png"
    corrupt.write_bytes(b"\x89PNG\r\n\x1a\n" + b"garbage" * 10)
    text = tmp_path / "notes.txt"
    text.write_text("not an image")
    empty = tmp_path / "empty"
    empty.mkdir()
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["derender", str(good), str(corrupt), str(text), str(empty), "--out",
                                      str(out), "--views", "2", "--view-size", "32"])
    assert result.exit_code == 1, result.output
    lines = result.stderr.splitlines()
    for bad in (corrupt, text, empty):
        assert sum(str(bad) in line for line in lines) == 1, result.stderr
    failures = list(csv.DictReader((out / "failures.csv").open()))
    assert sorted(f["source"] for f in failures) == sorted(str(p) for p in (corrupt, text, empty))
    assert ResultPaths(out / "good").is_complete()
    assert "gallery:" in result.stdout and "1 de-rendered" in result.stdout


def test_cli_no_overwrite_without_flag(tmp_path: Path, fake_checkpoint) -> None:
    write_photo(tmp_path / "in" / "a.png", 4)
    args = ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "out"), "--views", "0",
            "--view-size", "32"]
    assert CliRunner().invoke(cli, args).exit_code == 0
    recon = tmp_path / "out" / "a" / "recon.png"
    recon.write_bytes(b"marker")  # if the folder were redone, this would be replaced
    second = CliRunner().invoke(cli, args)
    assert second.exit_code == 0 and "skipped" in second.stderr and "--overwrite" in second.stderr
    assert recon.read_bytes() == b"marker"
    third = CliRunner().invoke(cli, args + ["--overwrite"])
    assert third.exit_code == 0 and "1 de-rendered" in third.stdout
    assert recon.read_bytes() != b"marker"


def test_incomplete_folder_is_redone(tmp_path: Path, predictor: Predictor) -> None:
    write_photo(tmp_path / "in" / "a.png", 5)
    (tmp_path / "out" / "a").mkdir(parents=True)
    (tmp_path / "out" / "a" / "input.png").write_bytes(b"half-written by a killed run")
    summary = derender([tmp_path / "in"], predictor, DerenderOptions(out=tmp_path / "out",
                                                                      export=ExportConfig(0, 32)))
    assert summary.done == ["a"] and ResultPaths(tmp_path / "out" / "a").is_complete()


def test_parallel_exports_write_the_same_bytes_and_keep_going_past_a_failure(tmp_path: Path, predictor: Predictor,
                                                                              monkeypatch) -> None:
    from radar_cli.derender.run import batch

    for i, name in enumerate(["a", "b", "c", "d"]):
        write_photo(tmp_path / "in" / f"{name}.png", 10 + i)
    real = batch.export_object

    def failing_c(folder, *args, **kwargs):
        if folder.name == "c":
            raise OSError("disk full")
        return real(folder, *args, **kwargs)

    monkeypatch.setattr(batch, "export_object", failing_c)
    runs = {}
    for workers in (1, 3):
        options = DerenderOptions(out=tmp_path / f"out{workers}", workers=workers, export=ExportConfig(0, 32))
        runs[workers] = derender([tmp_path / "in"], predictor, options, say=lambda _: None)
    for summary in runs.values():
        assert summary.done == ["a", "b", "d"]
        assert [f.problem for f in summary.failures] == ["export failed (OSError: disk full)"]
    for name in ("a", "b", "d"):
        one, three = tmp_path / "out1" / name, tmp_path / "out3" / name
        files = sorted(p.name for p in one.iterdir())
        assert files == sorted(p.name for p in three.iterdir()) and "material.json" in files
        for f in files:
            if f != "material.json":  # it records the source path, which differs
                assert (one / f).read_bytes() == (three / f).read_bytes(), f
