"""Tests of where photos come from (harvest catalog or folder) and of the ONNX detector's output contract."""

from __future__ import annotations

import json
import sys
import types

import cv2
import numpy as np
import pytest
from PIL import Image

from radar_cli.errors import InputError
from radar_cli.masks.prepare import list_sources, prepare
from radar_cli.masks.synthetic import sor_mask


def _studio(seed: int) -> np.ndarray:
    img = np.full((240, 200, 3), 210, np.uint8)
    m = cv2.resize(sor_mask(128, np.random.default_rng(seed)).astype(np.uint8), (170, 170)) > 0
    img[35:205, 15:185][m] = (90, 50, 30)
    return img


def test_catalog_folder_gives_attribution_in_meta(tmp_path):
    from radar_cli.harvest.catalog import open_catalog

    (tmp_path / "images").mkdir()
    Image.fromarray(_studio(0)).save(tmp_path / "images" / "42.jpg")
    Image.fromarray(_studio(1)).save(tmp_path / "images" / "stray.jpg")  # not in the catalog: ignored
    with open_catalog(tmp_path) as cat:
        cat.add_searched([42])
        cat.set_record(42, {"title": "Jar", "creditLine": "Gift", "isPublicDomain": True,
                            "objectURL": "https://example.org/42"}, "records/42.json", "u", "record")
        cat.set_image(42, "images/42.jpg", 1, "0" * 64, "")
    sources = list_sources(tmp_path)
    assert [s.key for s in sources] == ["met_42"]
    prepare(tmp_path, tmp_path / "out", progress=False)
    meta = json.loads(next((tmp_path / "out").glob("*/met_42/meta.json")).read_text())
    assert meta["attribution"]["title"] == "Jar" and meta["attribution"]["licence"] == "CC0-1.0"


def test_output_inside_the_photo_folder_is_not_read_back(tmp_path):
    Image.fromarray(_studio(2)).save(tmp_path / "vase.png")
    prepare(tmp_path, tmp_path / "prepared", progress=False)
    assert [s.key for s in list_sources(tmp_path, exclude=tmp_path / "prepared")] == ["vase"]
    again = prepare(tmp_path, tmp_path / "prepared", progress=False)
    assert again.photos == 1 and again.skipped_done == 1


def test_missing_folder_is_an_input_error(tmp_path):
    with pytest.raises(InputError):
        list_sources(tmp_path / "nope")


class _FakeSession:
    """Stands in for onnxruntime.InferenceSession: returns one box-shaped mask and one low-score mask."""

    def __init__(self, path, providers=None):
        self.path = path

    def get_inputs(self):
        return [types.SimpleNamespace(name="image", shape=[1, 3, "h", "w"])]

    def get_outputs(self):
        return [types.SimpleNamespace(name="masks"), types.SimpleNamespace(name="scores")]

    def run(self, names, feeds):
        x = feeds["image"]
        assert x.shape == (1, 3, 512, 512) and x.dtype == np.float32 and x.max() <= 1.0
        masks = np.zeros((2, 1, 512, 512), np.float32)
        masks[0, 0, 100:400, 200:320] = 0.9
        masks[1, 0, 10:50, 10:50] = 0.9
        return [masks, np.array([0.95, 0.2], np.float32)]


def test_onnx_detector_follows_the_contract(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "onnxruntime", types.SimpleNamespace(InferenceSession=_FakeSession))
    from radar_cli.masks.onnx import OnnxDetector

    model = tmp_path / "m.onnx"
    model.write_bytes(b"fake")
    found = OnnxDetector(model)(np.zeros((1024, 2048, 3), np.uint8))
    assert len(found) == 1
    x0, y0, x1, y1 = found[0].box
    assert (x0, y0, x1, y1) == pytest.approx((800, 200, 1280, 800))
    assert found[0].mask.shape == (512, 1024)


def test_onnx_detector_without_runtime_says_how_to_install(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "onnxruntime", None)  # import fails
    from radar_cli.masks.onnx import OnnxDetector

    with pytest.raises(InputError, match="onnxruntime"):
        OnnxDetector(tmp_path / "m.onnx")


def test_a_crashing_photo_is_recorded_and_the_batch_goes_on(tmp_path, monkeypatch):
    from radar_cli.masks import prepare as prep

    for i in range(2):
        Image.fromarray(_studio(i)).save(tmp_path / f"v{i}.png")
    real = prep.process_photo

    def flaky(path, *args, **kwargs):
        if path.name == "v0.png":
            raise IndexError("boom")
        return real(path, *args, **kwargs)

    monkeypatch.setattr(prep, "process_photo", flaky)
    summary = prepare(tmp_path, tmp_path / "out", progress=False)
    assert summary.failed == 1 and summary.photos == 2
    assert "IndexError: boom" in (tmp_path / "out" / "failures.csv").read_text()
