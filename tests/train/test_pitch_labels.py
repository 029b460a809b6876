"""Self-training on pitch (loss.pitch_label_weight, `radar train --pitch-labels`): the labels are read from a
`radar derender` results folder by sample id, reach the batch, and the term pulls only f_S's pitch towards them."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
import torch
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.errors import ConfigError, InputError
from radar_cli.model.radar import RadarModel
from radar_cli.model.weights import read_checkpoint
from radar_cli.train.checkpoint import MODEL_FILE
from radar_cli.train.data import VaseDataset, to_batch
from radar_cli.train.step import generator_losses
from radar_cli.train.trainer import train

from .conftest import tiny_config

PRESET = Path(__file__).resolve().parents[2] / "pipelines" / "bundled" / "stage8_selftrain.toml"


def write_labels(results: Path, dataset: Path, pitches: dict[str, float]) -> Path:
    """A results folder as `radar derender DATA/train` writes it: <sample id>/material.json with a pitch."""
    for sample_id, pitch in pitches.items():
        (results / sample_id).mkdir(parents=True, exist_ok=True)
        (results / sample_id / "material.json").write_text(json.dumps({"pitch": pitch, "pitch_source": "search"}))
    return results


def labelled_config(weight: float = 1.0, **train_fields):
    base = tiny_config(**train_fields)
    return dataclasses.replace(base, loss=dataclasses.replace(base.loss, pitch_label_weight=weight)).validate()


def test_labels_are_read_by_sample_id_into_the_batch(vases32, tmp_path):
    ds = VaseDataset(vases32, "train", 32)
    ids = [r.sample_id for r in ds.refs]
    write_labels(tmp_path / "res", vases32, {i: float(k) + 0.5 for k, i in enumerate(ids)})
    ds.load_pitch_labels(tmp_path / "res")
    items = ds.batch([3, 0, 5])
    assert torch.equal(items["pitch_label"], torch.tensor([3.5, 0.5, 5.5]))
    assert torch.equal(to_batch(items, torch.device("cpu")).pitch_label, torch.tensor([3.5, 0.5, 5.5]))
    assert "pitch_label" not in VaseDataset(vases32, "train", 32).batch([0])  # none loaded: none in the batch


def test_missing_or_bad_labels_name_the_file(vases32, tmp_path):
    ds = VaseDataset(vases32, "train", 32)
    ids = [r.sample_id for r in ds.refs]
    results = write_labels(tmp_path / "res", vases32, {i: 1.0 for i in ids[1:]})
    with pytest.raises(InputError, match=f"{ids[0]}.material.json: missing"):
        ds.load_pitch_labels(results)
    write_labels(results, vases32, {ids[0]: float("nan")})
    with pytest.raises(InputError, match=f"{ids[0]}.material.json: 'pitch' must be a finite number"):
        ds.load_pitch_labels(results)
    assert ds.pitch_labels is None


def test_the_term_pulls_only_the_pitch_towards_its_label(vases32, tmp_path):
    config = labelled_config()
    torch.manual_seed(0)
    model = RadarModel(config.model)
    ds = VaseDataset(vases32, "train", 32)
    items = ds.batch([0, 1, 2, 3])
    with torch.no_grad():
        pitch = model(to_batch(items, torch.device("cpu")).image).pose[:, 0]
    lo, hi = config.model.geometry.pitch_range
    items["pitch_label"] = pitch + torch.tensor([2.0, -2.0, 4.0, 0.0])
    batch = to_batch(items, torch.device("cpu"))
    pred = model(batch.image)
    terms, _ = generator_losses(pred, batch, config, None, model)
    assert terms["pitch_label"].item() == pytest.approx(2.0 / (hi - lo), rel=1e-4)  # mean |error| / range
    model.zero_grad()
    terms["pitch_label"].backward()
    grads = {name: any(p.grad is not None and p.grad.abs().sum() > 0 for p in net.parameters())
             for name, net in (("shape", model.shape_net), ("light", model.light_net), ("albedo", model.albedo_net))}
    assert grads == {"shape": True, "light": False, "albedo": False}
    # the weighted sum: the same batch without the term differs by exactly weight x term
    off = dataclasses.replace(config, loss=dataclasses.replace(config.loss, pitch_label_weight=0.0))
    without, _ = generator_losses(pred, batch, off, None, model)
    assert "pitch_label" not in without
    assert (terms["total"] - without["total"]).item() == pytest.approx(terms["pitch_label"].item(), rel=1e-4)


def test_runs_with_labels_and_refuses_without(vases32, tmp_path):
    ids = [r.sample_id for r in VaseDataset(vases32, "train", 32).refs]
    results = write_labels(tmp_path / "res", vases32, {i: 7.0 for i in ids})
    summary = train(labelled_config(iterations=2), vases32, tmp_path / "run", progress=False, pitch_labels=results)
    assert summary.losses["pitch_label"] >= 0
    with pytest.raises(InputError, match="--pitch-labels"):
        train(labelled_config(iterations=1), vases32, tmp_path / "run2", progress=False)
    with pytest.raises(ConfigError, match="pitch_label_weight"):
        labelled_config(weight=-1.0)


def test_the_preset_trains_from_the_cli_with_labels(vases64, tmp_path):
    """pipelines/bundled/stage8_selftrain.toml through `radar train --pitch-labels`; without them, one line."""
    ids = [r.sample_id for r in VaseDataset(vases64, "train", 64).refs]
    results = write_labels(tmp_path / "res", vases64, {i: 7.0 for i in ids})
    args = ["train", "--config", str(PRESET), "--data", str(vases64), "--out", str(tmp_path / "run"),
            "--iterations", "1", "--device", "cpu"]
    out = CliRunner().invoke(cli, args + ["--pitch-labels", str(results)])
    assert out.exit_code == 0, out.output
    assert "pitch_label=" in out.output
    _, meta, config = read_checkpoint(tmp_path / "run" / MODEL_FILE)
    stored = json.loads(meta["config"])  # the resolved preset: values from every base in its chain, no `base`
    assert "base" not in stored and stored["name"] == "syn_cpu_selftrain"
    assert stored["model"]["render"]["sil_sigma_px"] == 0.25 and stored["loss"]["cycle_albedo"] == "divided"
    assert config.loss.pitch_label_weight == 1.0 and config.model.render.image_size == 64
    refused = CliRunner().invoke(cli, args)
    assert refused.exit_code != 0 and "--pitch-labels" in refused.output
