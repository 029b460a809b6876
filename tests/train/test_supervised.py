"""The supervised baseline reads `radar synth` ground truth (params.json, albedo.png, env_map.npy)."""

from __future__ import annotations

import dataclasses
import json

import pytest
import torch

from radar_cli.errors import InputError
from radar_cli.synth.generator import SynthConfig, make_sample, write_sample_folder
from radar_cli.train.data import VaseDataset, target_batch
from radar_cli.train.trainer import train

from .conftest import tiny_config


@pytest.fixture(scope="module")
def synth32(tmp_path_factory):
    root = tmp_path_factory.mktemp("synth32")
    cfg = SynthConfig(size=32, seed=0)
    for i in range(4):
        files, params = make_sample(cfg, "train", i, None)
        write_sample_folder(root, "train", f"{i:06d}", files, params)
    return root


def test_targets_match_params(synth32):
    config = tiny_config()
    ds = VaseDataset(synth32, "train", 32)
    ds.load_targets()
    t = target_batch(ds, torch.tensor([0, 2]), config, torch.device("cpu"))
    p = json.loads((synth32 / "train" / "000002" / "params.json").read_text())
    assert t.radius.shape == (2, 16) and t.albedo.shape == (2, 3, 32, 32) and t.env.shape == (2, 4, 12)
    assert t.alpha[1].item() == pytest.approx(p["alpha"]) and t.rho[1].item() == pytest.approx(p["rho"])
    assert torch.allclose(t.pose[1], torch.tensor(p["pose"]))
    assert t.albedo.min() >= 0 and t.albedo.max() <= 1


def test_supervised_run_trains_on_ground_truth(synth32, tmp_path):
    base = tiny_config(iterations=2)
    config = dataclasses.replace(base, loss=dataclasses.replace(base.loss, supervised=True))
    summary = train(config, synth32, tmp_path / "run", progress=False)
    assert {"sup_radius", "sup_pose", "sup_albedo", "sup_env", "sup_alpha", "sup_rho"} < set(summary.losses)


def test_supervised_without_ground_truth_is_an_error(vases32, tmp_path):
    base = tiny_config(iterations=1)
    config = dataclasses.replace(base, loss=dataclasses.replace(base.loss, supervised=True))
    with pytest.raises(InputError, match="params.json"):
        train(config, vases32, tmp_path / "run", progress=False)
