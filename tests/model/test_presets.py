"""Every preset in pipelines/ loads, and the inherited presets resolve to the values they had as full copies."""

from __future__ import annotations

from pathlib import Path

import pytest

from radar_cli.config import to_dict
from radar_cli.model.config import load_run_config

PIPELINES = Path(__file__).resolve().parents[2] / "pipelines"
RUN_PRESETS = sorted(p for p in PIPELINES.rglob("*.toml") if p.parent.name != "readers")

# Values each preset held written out in full, before presets named a base; dotted keys into the resolved config.
PINNED = {
    "paper/syn_vases_no_alb.toml": {
        "name": "syn_vases_no_alb", "loss.no_alb": True, "loss.no_sad": False, "model.render.image_size": 256,
        "model.albedo_depth": 6, "loss.sad_patch": 64, "train.iterations": 40000, "train.log_every": 20,
        "train.device": "auto", "train.threads": 0},
    "paper/met_vases.toml": {"name": "met_vases", "model.shape_width": 64, "train.log_every": 20},
    "cpu/syn_vases_cpu_no_sad.toml": {
        "name": "syn_vases_cpu_no_sad", "loss.no_sad": True, "model.render.image_size": 64,
        "model.render.shading_height": 16, "model.max_channels": 128, "loss.sad_patch": 16,
        "train.iterations": 4000, "train.checkpoint_every": 250, "train.log_every": 10, "train.threads": 1,
        "train.device": "cpu"},
    "bundled/stage3_mouth.toml": {"train.threads": 2, "train.iterations": 18000, "train.lr_decay_steps": 6000,
                                  "model.render.sil_sigma_px": 0.25, "loss.mouth_weight": 1.0},
    "bundled/stage9_finetune.toml": {
        "name": "syn_cpu_finetune", "loss.pitch_label_weight": 0.0, "loss.cycle_albedo": "divided",
        "train.lr": 1e-4, "train.iterations": 2000, "train.threads": 1},
    "bundled/stage10_selftrain.toml": {
        "name": "syn_cpu_selftrain2", "model.render.sil_sigma_px": 0.25, "model.render.image_size": 64,
        "loss.dt_margin_px": 1.0, "loss.mouth_weight": 1.0, "loss.cycle_weight": 1.0,
        "loss.light_cycle_weight": 1.0, "loss.cycle_albedo": "divided", "loss.pitch_label_weight": 1.0,
        "train.lr": 1e-4, "train.iterations": 1000, "train.lr_decay_steps": 1000, "train.keep_checkpoints": 16,
        "train.threads": 1, "model.geometry.pitch_range": [0.0, 20.0]},
}


def lookup(data: dict, dotted: str):
    for key in dotted.split("."):
        data = data[key]
    return data


@pytest.mark.parametrize("path", RUN_PRESETS, ids=lambda p: str(p.relative_to(PIPELINES)))
def test_every_preset_resolves(path):
    config = to_dict(load_run_config(path))
    assert "base" not in config  # the stored config is the resolved one
    assert config["name"] != "run"  # each preset names its run


@pytest.mark.parametrize("preset", sorted(PINNED))
def test_pinned_values(preset):
    config = to_dict(load_run_config(PIPELINES / preset))
    got = {key: lookup(config, key) for key in PINNED[preset]}
    assert got == PINNED[preset]


def test_names_are_unique():
    names = [load_run_config(p).name for p in RUN_PRESETS]
    assert len(names) == len(set(names))
