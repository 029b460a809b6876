"""The gallery's files: data.js describes every object (quality status, scores, attribution, which pictures
exist), thumbnails are small, the viewer's lighting is turned into three.js's convention, and the page's code and
the vendored viewer are copied in so the folder works alone."""

from __future__ import annotations

import base64
import json
import math
import shutil
import sqlite3
from pathlib import Path

import cv2
import numpy as np
import pytest
from PIL import Image

from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.present.gallery import (
    GALLERY_DIR,
    PAGE_FILES,
    THUMB_SIDE,
    THUMBNAIL_FILE,
    VIEWER_ENV_FILE,
    attribution,
    viewer_environment,
    write_gallery,
)
from radar_cli.derender.present.report import read_records, write_report
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor
from radar_cli.render.lighting import env_directions

from .conftest import SETUP, FakeModel, write_photo

QUALITY = {
    "a_ok": {"status": "ok", "reasons": [], "silhouette_iou": 0.95, "symmetry": 0.9, "recon_psnr": 28.0,
             "appendage_fraction": 0.0, "cut_edges": [], "frame_coverage": 0.6},
    "b_failed": {"status": "failed", "reasons": ["silhouette IoU 0.41 < 0.7"], "silhouette_iou": 0.41,
                 "symmetry": None, "recon_psnr": 15.5, "appendage_fraction": 0.3, "cut_edges": ["left"],
                 "frame_coverage": 0.9},
    "c_review": {"status": "review", "reasons": ["handles"], "silhouette_iou": 0.8, "symmetry": 0.7,
                 "recon_psnr": 22.0, "appendage_fraction": 0.12, "cut_edges": [], "frame_coverage": 0.5},
}


def gallery_data(root: Path) -> dict:
    text = (root / GALLERY_DIR / "data.js").read_text("utf-8")
    prefix = "window.RADAR_GALLERY = "
    assert text.startswith(prefix) and text.rstrip().endswith(";")
    return json.loads(text[len(prefix):].rstrip().rstrip(";"))


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> Path:
    """Four objects; three get hand-written quality records (as the quality checks write them), one none."""
    root = tmp_path_factory.mktemp("gallery")
    for k, name in enumerate(["a_ok", "b_failed", "c_review", "d_plain"]):
        write_photo(root / "in" / f"{name}.png", k, (80, 80))
    options = DerenderOptions(out=root / "out", export=ExportConfig(views=0, view_size=32))
    derender([root / "in"], Predictor(FakeModel(), SETUP, "fake-model", "cpu"), options)
    out = root / "out"
    for name, quality in QUALITY.items():
        material = json.loads((out / name / "material.json").read_text())
        material["quality"] = quality
        (out / name / "material.json").write_text(json.dumps(material))
    plain = json.loads((out / "d_plain" / "material.json").read_text())
    plain.pop("quality")  # a result written without a quality record
    (out / "d_plain" / "material.json").write_text(json.dumps(plain))
    Image.new("RGB", (40, 40), (255, 0, 0)).save(out / "c_review" / "appendages.png")
    write_report(out, [])
    return out


def test_data_carries_status_scores_and_pictures(results: Path) -> None:
    data = gallery_data(results)
    objects = {o["id"]: o for o in data["objects"]}
    assert sorted(objects) == ["a_ok", "b_failed", "c_review", "d_plain"]
    assert {k: o["status"] for k, o in objects.items()} == {"a_ok": "ok", "b_failed": "failed",
                                                           "c_review": "review", "d_plain": "unknown"}
    assert objects["b_failed"]["reasons"] == ["silhouette IoU 0.41 < 0.7"]
    assert objects["b_failed"]["cut_edges"] == ["left"]
    assert objects["b_failed"]["scores"]["symmetry"] is None
    assert objects["a_ok"]["scores"]["recon_psnr"] == 28.0 and objects["d_plain"]["scores"] == {}
    assert objects["c_review"]["appendages"] and not objects["a_ok"]["appendages"]
    assert objects["a_ok"]["relit"] == ["overcast", "studio", "sunset", "two_lights"]
    assert data["builtin_envs"] == ["overcast", "studio", "sunset", "two_lights"]
    assert all(o["attribution"] is None for o in objects.values())  # plain photos: no catalogue record


def test_page_files_are_copied_and_index_points_at_them(results: Path) -> None:
    for name in PAGE_FILES:
        assert (results / GALLERY_DIR / name).stat().st_size > 0
    viewer = (results / GALLERY_DIR / "model-viewer-umd.min.js").read_text("utf-8")
    assert 'customElements.define("model-viewer"' in viewer  # the vendored web component, not a stub
    assert "Apache License" in (results / GALLERY_DIR / "LICENSE-model-viewer.txt").read_text("utf-8")
    index = (results / "index.html").read_text("utf-8")
    assert ".gallery/data.js" in index and ".gallery/gallery.js" in index and "4 object(s)" in index
    assert "http://" not in index and "https://" not in index  # nothing from the network
    env_script = (results / GALLERY_DIR / "env.js").read_text("ascii")
    assert env_script.startswith("window.RADAR_ENVS = ")
    embedded = json.loads(env_script.removeprefix("window.RADAR_ENVS = ").rstrip().rstrip(";"))
    for name in ("overcast", "studio", "sunset", "two_lights"):
        hdr_file = results / GALLERY_DIR / "env" / f"{name}.hdr"
        hdr = cv2.imread(str(hdr_file), cv2.IMREAD_UNCHANGED)
        assert hdr.shape == (64, 128, 3) and hdr.min() >= 0 and hdr.max() > 0
        assert base64.b64decode(embedded[name]) == hdr_file.read_bytes()  # the same file for a page from disk


def test_thumbnails_are_small_and_written_once(results: Path) -> None:
    thumb = results / "a_ok" / THUMBNAIL_FILE
    with Image.open(thumb) as im:
        assert im.size == (2 * THUMB_SIDE, THUMB_SIDE)  # input | reconstruction
    before = thumb.stat().st_mtime_ns
    write_gallery(results, read_records(results), 0)
    assert thumb.stat().st_mtime_ns == before  # up to date: not rewritten for every report


def test_an_unreadable_picture_costs_only_its_thumbnail(results: Path, tmp_path: Path) -> None:
    root = tmp_path / "copy"
    shutil.copytree(results, root)
    (root / "d_plain" / THUMBNAIL_FILE).unlink()
    (root / "d_plain" / "input.png").write_bytes(b"not a png")
    write_report(root, [])
    objects = {o["id"]: o for o in gallery_data(root)["objects"]}
    assert not objects["d_plain"]["thumbnail"] and objects["a_ok"]["thumbnail"] and len(objects) == 4


def test_viewer_environment_puts_the_camera_side_at_three_js_plus_z() -> None:
    """A light towards the camera (radar az 0) must land where three.js reads direction +z of the exported mesh
    (u = 3/4), and one on radar's -x side (camera-frame x, which the export flips) at three.js's +x (u = 1/2)."""
    h, w = 8, 24
    dirs = env_directions(h, w)[0].numpy().reshape(h, w, 3)
    for target, u_expected in (((0.0, 0.0, -1.0), 0.75), ((-1.0, 0.0, 0.0), 0.5)):
        env = np.zeros((h, w), np.float32)
        i, j = np.unravel_index(np.argmax(dirs @ np.array(target)), (h, w))
        env[i, j] = 1.0
        out = viewer_environment(env, 4)
        assert out.shape == (4 * h, 4 * w, 3) and np.allclose(out[..., 0], out[..., 2])
        cols = np.nonzero(out[..., 0].max(axis=0))[0]
        u = (cols.mean() + 0.5) / out.shape[1]
        assert u == pytest.approx(u_expected, abs=1.0 / w)
        assert out.max() == pytest.approx(math.pi)  # three.js divides a Lambertian surface by pi


def test_object_lighting_file_is_written(results: Path) -> None:
    hdr = cv2.imread(str(results / "a_ok" / VIEWER_ENV_FILE), cv2.IMREAD_UNCHANGED)
    env = np.load(results / "a_ok" / "env_map.npy")
    assert hdr.shape == (4 * env.shape[0], 4 * env.shape[1], 3)
    assert float(hdr.mean()) == pytest.approx(math.pi * float(env.mean()), rel=0.03)


def test_attribution_from_masks_meta_and_fetch_catalog(tmp_path: Path) -> None:
    sample = tmp_path / "prepared" / "train" / "met_1"
    sample.mkdir(parents=True)
    (sample / "meta.json").write_text(json.dumps({"attribution": {
        "object_id": 1, "title": "Jar", "credit_line": "Gift, 1917", "licence": "CC0",
        "object_url": "https://www.metmuseum.org/art/collection/search/1"}}))
    found = attribution(str(sample / "image.png"), {})
    assert found == {"title": "Jar", "credit": "Gift, 1917", "licence": "CC0", "object_id": "1",
                     "url": "https://www.metmuseum.org/art/collection/search/1"}
    (sample / "meta.json").write_text(json.dumps({"attribution": {"title": "x", "object_url": "javascript:alert(1)"}}))
    assert attribution(str(sample / "image.png"), {})["url"] == ""  # only http(s) links reach the page

    fetched = tmp_path / "met"
    (fetched / "images").mkdir(parents=True)
    with sqlite3.connect(fetched / "catalog.sqlite") as db:
        db.execute("CREATE TABLE objects (object_id INTEGER, image_path TEXT, title TEXT, credit_line TEXT, "
                   "licence TEXT, object_url TEXT)")
        db.execute("INSERT INTO objects VALUES (7, 'images/7.jpg', 'Vase', 'Rogers Fund', 'CC0', "
                   "'https://www.metmuseum.org/art/collection/search/7')")
    catalogs: dict = {}
    found = attribution(str(fetched / "images" / "7.jpg"), catalogs)
    assert found["title"] == "Vase" and found["object_id"] == "7" and found["url"].endswith("/7")
    assert attribution(str(fetched / "images" / "8.jpg"), catalogs) is None
    for db in catalogs.values():
        db.close()
    assert attribution(str(tmp_path / "elsewhere" / "photo.jpg"), {}) is None
