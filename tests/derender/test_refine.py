"""Per-object refinement: the fit recovers a synthetic vase's pitch and silhouette from a perturbed prediction,
and a failed fit falls back to the network's prediction."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine import driver as refine_module
from radar_cli.derender.refine.driver import refine_object
from radar_cli.masks.refine import iou
from radar_cli.model.outputs import Decomposition
from radar_cli.render.raycast import hit_mask
from radar_cli.synth.generator import SynthConfig, make_sample

SIZE = 512  # the default output side, where the lip's contrast was tuned


class Appearance:
    """Stands in for RadarModel.read_appearance: fixed lighting, material and albedo at any shape."""

    def __init__(self, rho: float = 0.3):
        self.rho = rho

    def read_appearance(self, image, solid):
        b = solid.batch
        return Decomposition(solid.radius, solid.height, solid.pose, torch.full((b, 3, 8, 8), 0.5),
                             torch.ones(b, 4, 12), torch.full((b,), 20.0), torch.full((b,), self.rho))


def _sample(index: int):
    files, params = make_sample(SynthConfig(size=SIZE, seed=11), "test", index, None)
    image = (np.clip(files["image.png"], 0, 1) * 255 + 0.5).astype(np.uint8)
    return image, files["mask.png"] > 0.5, params


def _perturbed(params: dict, pitch_offset: float, radius_scale: float) -> Decomposition:
    pose = torch.tensor([params["pose"]], dtype=torch.float32)
    pose[0, 0] += pitch_offset
    radius = torch.tensor([params["radius"]], dtype=torch.float32) * radius_scale
    return Decomposition(radius, torch.tensor([params["height"]]), pose, torch.zeros(1, 3, 8, 8),
                         torch.ones(1, 4, 12), torch.tensor([50.0]), torch.tensor([0.5]))


@pytest.mark.parametrize("index, pitch_offset, radius_scale", [(0, 6.0, 1.15), (3, -6.0, 0.85)])
def test_refinement_recovers_pitch_and_silhouette(index, pitch_offset, radius_scale):
    image, mask, params = _sample(index)
    start = _perturbed(params, pitch_offset, radius_scale)
    refined, report = refine_object(Appearance(), torch.zeros(1, 3, 64, 64), start, image, mask, CameraConfig())
    assert report.status == "refined", report
    assert abs(float(refined.pose[0, 0]) - params["pose"][0]) <= 0.5
    assert iou(hit_mask(refined.solid, SIZE, CameraConfig())[0].numpy(), mask) >= 0.99  # the ray-cast silhouette
    assert report.iou[0] >= 0.99 and report.iou[1] < report.iou[0]
    assert refined.radius.shape[1] >= 64


def test_failed_fit_falls_back_to_the_network(monkeypatch):
    image, mask, params = _sample(1)
    start = _perturbed(params, 3.0, 1.0)

    def broken(*args, **kwargs):
        raise ValueError("the silhouette covers fewer than two rows")

    monkeypatch.setattr(refine_module, "fit_shape", broken)
    kept, report = refine_object(Appearance(), torch.zeros(1, 3, 64, 64), start, image, mask, CameraConfig())
    assert kept is None and report.status == "fallback" and "ValueError" in report.reason
    assert report.record()["silhouette_iou"]["refined"] is None


def test_no_silhouette_keeps_the_network():
    image, _, params = _sample(1)
    start = _perturbed(params, 0.0, 1.0)
    kept, report = refine_object(Appearance(), torch.zeros(1, 3, 64, 64), start, image, None, CameraConfig())
    assert kept is None and report.status == "fallback" and "silhouette" in report.reason


@pytest.mark.slow
def test_lighting_fit_runs_after_the_shape_and_repeats_bit_for_bit():
    """--refine full: the environment map is fitted (or the network's kept, and said so); the same object gives the
    same tensors again, on one thread or two (the export workers run it on any)."""
    image, mask, params = _sample(0)
    start = _perturbed(params, 2.0, 1.05)
    runs = []
    threads = torch.get_num_threads()
    try:
        for n in (1, 2):
            torch.set_num_threads(n)
            runs.append(refine_object(Appearance(), torch.zeros(1, 3, 64, 64), start, image, mask, CameraConfig()))
    finally:
        torch.set_num_threads(threads)
    (first, report), (second, _) = runs
    assert report.light in ("fitted", "kept") and report.record()["light"] == report.light
    if report.light == "fitted":
        assert report.light_rmse[0] < report.light_rmse[1]
    else:
        assert torch.equal(first.env, start.env)
    for a, b in zip(first.tensors(), second.tensors()):
        assert torch.equal(a, b)


def test_shape_only_keeps_the_re_read_lighting():
    image, mask, params = _sample(0)
    start = _perturbed(params, 2.0, 1.05)
    refined, report = refine_object(Appearance(), torch.zeros(1, 3, 64, 64), start, image, mask, CameraConfig(),
                                    light=None)
    assert report.light == "" and torch.equal(refined.env, torch.ones(1, 4, 12))


@pytest.mark.parametrize("read, kept", [(1.6, 1.0), (0.3, 0.3)])
def test_re_read_specular_albedo_is_at_most_one(read, kept):
    """Without a reader: f_L reads 0..2; a specular albedo above 1 would reflect more light than arrives."""
    image, mask, params = _sample(0)
    start = _perturbed(params, 2.0, 1.05)
    refined, report = refine_object(Appearance(rho=read), torch.zeros(1, 3, 64, 64), start, image, mask,
                                    CameraConfig(), light=None)
    assert report.status == "refined" and report.record()["specular_albedo"] == "network"
    assert float(refined.rho[0]) == pytest.approx(kept)


def test_the_reader_reads_the_specular_albedo_at_the_fitted_shape():
    image, mask, params = _sample(0)
    start = _perturbed(params, 2.0, 1.05)
    seen = []

    def reader(network_input, solid):
        seen.append(float(solid.pose[0, 0]))
        return torch.tensor([0.42])

    refined, report = refine_object(Appearance(rho=1.6), torch.zeros(1, 3, 64, 64), start, image, mask,
                                    CameraConfig(), light=None, reader=reader)
    assert report.record()["specular_albedo"] == "reader" and float(refined.rho[0]) == pytest.approx(0.42)
    assert seen == [pytest.approx(float(refined.pose[0, 0]))]  # read at the refined pose, not the network's
