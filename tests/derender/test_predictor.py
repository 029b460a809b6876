"""Loading a checkpoint into the predictor: a tiny randomly initialised RadarModel end to end, and a clear error
for weights that do not fit their config."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.derender.run.predictor import Predictor
from radar_cli.errors import CheckpointError, InputError
from radar_cli.model import weights

from .conftest import write_photo

model_config = pytest.importorskip("radar_cli.model.config")


def tiny_config(width: int = 4):
    from radar_cli.config import GeometryConfig, RenderConfig

    render = RenderConfig(image_size=32, tex_height=16, tex_width=16, env_height=4, env_width=12,
                          shading_height=8, shading_width=8)
    model = model_config.ModelConfig(render=render, geometry=GeometryConfig(n_rows=16, n_cols=24),
                                     shape_width=width, light_width=width, albedo_width=width, disc_width=width,
                                     max_channels=16, latent=8, albedo_depth=2)
    return model_config.RunConfig(model=model, loss=model_config.LossConfig(sad_patch=8)).validate()


def save_weights(path: Path, config, weights_config=None) -> Path:
    """An exported-weights file: the model's tensors of `weights_config` (default: config) + `config` as JSON."""
    from safetensors.torch import save_file

    from radar_cli.model.radar import RadarModel

    model = RadarModel((weights_config or config).model)
    tensors = {f"model.{k}": v.contiguous() for k, v in model.state_dict().items()}
    meta = {"format": weights.FORMAT, "config": json.dumps(model_config.to_dict(config)), "step": "0"}
    save_file(tensors, str(path), metadata=meta)
    return path


def test_tiny_model_predicts(tmp_path: Path) -> None:
    path = save_weights(tmp_path / "tiny.safetensors", tiny_config())
    predictor = Predictor.from_checkpoint(path, "cpu")
    assert predictor.setup.render.image_size == 32 and predictor.version.startswith("tiny.safetensors#")
    dec = predictor.predict([np.full((32, 32, 3), 128, np.uint8)] * 2)
    assert dec.radius.shape == (2, 16) and dec.albedo.shape == (2, 3, 16, 16) and dec.env.shape == (2, 4, 12)
    assert not dec.radius.requires_grad


def test_albedo_sources(tmp_path: Path) -> None:
    path = save_weights(tmp_path / "tiny.safetensors", tiny_config())
    images = [np.random.default_rng(1).integers(0, 256, (32, 32, 3), dtype=np.uint8)] * 2
    network = Predictor.from_checkpoint(path, "cpu", albedo="network").predict(images)
    divided = Predictor.from_checkpoint(path, "cpu").predict(images)  # the default
    for name in ("radius", "height", "pose", "env", "alpha", "rho"):
        assert torch.equal(getattr(network, name), getattr(divided, name))  # only the albedo is refined
    assert divided.albedo.shape == network.albedo.shape and not torch.allclose(divided.albedo, network.albedo)
    assert divided.albedo.min() >= 0 and divided.albedo.max() <= 1
    # texels that unwrap from off the object keep the network's albedo; no silhouette counts as all object
    predictor = Predictor.from_checkpoint(path, "cpu")
    off = predictor.predict(images, [np.zeros((32, 32), bool), None])
    # (to float rounding: a bilinear sample of an all-ones silhouette can come out 1 - 6e-8)
    assert torch.allclose(off.albedo[0], network.albedo[0], atol=1e-6)
    assert torch.allclose(off.albedo[1], divided.albedo[1], atol=1e-6)
    with pytest.raises(InputError, match="silhouettes"):
        predictor.predict(images, [np.ones((16, 16), bool), None])
    with pytest.raises(InputError, match="albedo source"):
        Predictor.from_checkpoint(path, "cpu", albedo="painted")  # type: ignore[arg-type]


def test_cli_with_a_real_checkpoint(tmp_path: Path) -> None:
    path = save_weights(tmp_path / "tiny.safetensors", tiny_config())
    write_photo(tmp_path / "in" / "a.png", 1, (80, 80))
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "out"),
                                      "--checkpoint", str(path), "--views", "2", "--view-size", "32",
                                      "--device", "cpu"])
    assert result.exit_code == 0, result.output
    material = json.loads((tmp_path / "out" / "a" / "material.json").read_text())
    assert material["model"].startswith("tiny.safetensors#") and material["image_size"] == 32
    assert material["albedo_source"] == "divided"
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "net"),
                                      "--checkpoint", str(path), "--views", "0", "--albedo", "network"])
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "net" / "a" / "material.json").read_text())["albedo_source"] == "network"
    assert material["pitch_source"] == "network"
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "search"),
                                      "--checkpoint", str(path), "--views", "0", "--pitch", "search"])
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "search" / "a" / "material.json").read_text())["pitch_source"] == "search"


def test_checkpoint_from_another_config_is_one_clear_error(tmp_path: Path) -> None:
    config = tiny_config(4)
    path = save_weights(tmp_path / "other.safetensors", config, weights_config=tiny_config(8))
    with pytest.raises(CheckpointError, match="other.safetensors"):
        Predictor.from_checkpoint(path, "cpu")
    write_photo(tmp_path / "in" / "a.png", 1, (80, 80))
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "out"),
                                      "--checkpoint", str(path)])
    assert result.exit_code == 2
    (line,) = result.output.strip().splitlines()
    assert line.startswith("Error: ") and "other.safetensors" in line and "fit" in line


def test_missing_checkpoint(tmp_path: Path) -> None:
    with pytest.raises(CheckpointError, match="no such checkpoint"):
        Predictor.from_checkpoint(tmp_path / "nope.safetensors", "cpu")


def test_missing_specular_reader_is_one_clear_error(tmp_path: Path) -> None:
    path = save_weights(tmp_path / "model.safetensors", tiny_config(4))
    with pytest.raises(CheckpointError, match="nope.safetensors"):
        Predictor.from_checkpoint(path, "cpu", refine="shape", reader=tmp_path / "nope.safetensors")
    assert Predictor.from_checkpoint(path, "cpu", refine="none", reader=tmp_path / "nope.safetensors").reader is None
    assert Predictor.from_checkpoint(path, "cpu", refine="shape", reader="none").reader is None
    bundled = Predictor.from_checkpoint(path, "cpu", refine="shape")
    assert bundled.reader is not None and " + specular_albedo.safetensors#" in bundled.version  # material.json
    write_photo(tmp_path / "in" / "a.png", 1, (80, 80))
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "out"),
                                      "--checkpoint", str(path),
                                      "--specular-reader", str(tmp_path / "nope.safetensors")])
    assert result.exit_code == 2
    (line,) = result.output.strip().splitlines()
    assert line.startswith("Error: ") and "nope.safetensors" in line
