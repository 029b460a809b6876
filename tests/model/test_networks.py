"""Shapes and ranges of every network output, for the tiny config and the real presets."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

from radar_cli.config import load_toml
from radar_cli.errors import ConfigError, InputError
from radar_cli.model.config import RunConfig, load_run_config
from radar_cli.model.discriminator import PatchDiscriminator
from radar_cli.model.radar import RadarModel
from radar_cli.train.specular_reader import ReaderConfig

PIPELINES = Path(__file__).resolve().parents[2] / "pipelines"


def check_decomposition(d, config: RunConfig, batch: int) -> None:
    m, r, g = config.model, config.model.render, config.model.geometry
    expected = {"radius": (batch, g.n_rows), "height": (batch,), "pose": (batch, 4),
                "albedo": (batch, 3, r.tex_height, r.tex_width), "env": (batch, r.env_height, r.env_width),
                "alpha": (batch,), "rho": (batch,)}
    for name, shape in expected.items():
        value = getattr(d, name)
        assert tuple(value.shape) == shape, name
        assert torch.isfinite(value).all(), name
    ranges = {"radius": g.radius_range, "height": g.height_range, "alpha": m.shininess_range,
              "rho": m.spec_albedo_range, "env": m.env_range, "albedo": (0.0, 1.0)}
    for name, (lo, hi) in ranges.items():
        value = getattr(d, name)
        assert value.min() >= lo - 1e-5 and value.max() <= hi + 1e-5, name
    for col, (lo, hi) in enumerate([g.pitch_range, g.roll_range, g.trans_range, g.trans_range]):
        assert d.pose[:, col].min() >= lo - 1e-5 and d.pose[:, col].max() <= hi + 1e-5


def test_tiny_model_outputs(tiny):
    model = RadarModel(tiny.model)
    d = model(torch.rand(3, 3, 32, 32))
    check_decomposition(d, tiny, 3)


@pytest.mark.parametrize("preset", ["cpu/syn_vases_cpu.toml", "cpu/met_vases_cpu.toml"])
def test_cpu_presets_outputs(preset):
    config = load_run_config(PIPELINES / preset)
    model = RadarModel(config.model)
    size = config.model.render.image_size
    check_decomposition(model(torch.rand(2, 3, size, size)), config, 2)
    assert sum(p.numel() for p in model.parameters()) * 4 < 25e6  # the bundled weights fit in 25 MB


def test_paper_preset_architecture():
    """The 256 px model builds with the paper's layer counts (U-Net depth 6, 32-row radius column)."""
    config = load_run_config(PIPELINES / "paper" / "syn_vases.toml")
    model = RadarModel(config.model)
    assert len(model.albedo_net.down) == 6
    convs = [m for m in model.shape_net.encoder if isinstance(m, torch.nn.Conv2d)]
    assert [c.out_channels for c in convs] == [64, 128, 256, 512, 512, 512, 128]
    z = torch.rand(2, 128)
    assert model.shape_net.radius_decoder(z[..., None]).shape == (2, 1, 32)
    assert model.light_net.env_decoder(z[..., None, None]).shape == (2, 1, 16, 48)


def test_discriminator_scores_one_per_patch():
    disc = PatchDiscriminator(16, 8, 32)
    assert disc(torch.rand(5, 3, 16, 16)).shape == (5,)


def test_wrong_image_size_is_rejected(tiny):
    with pytest.raises(InputError, match="image"):
        RadarModel(tiny.model)(torch.rand(1, 3, 64, 64))


def test_all_presets_load_strictly(tmp_path):
    for path in sorted(PIPELINES.rglob("*.toml")):
        if path.parent.name == "readers":  # `radar train-reader` settings
            load_toml(ReaderConfig, path)
        else:
            load_run_config(path)
    bad = tmp_path / "bad.toml"
    bad.write_text((PIPELINES / "cpu" / "syn_vases_cpu.toml").read_text() + "\n[extra]\nx = 1\n")
    with pytest.raises(ConfigError, match="unknown key"):
        load_run_config(bad)
    bad.write_text((PIPELINES / "cpu" / "syn_vases_cpu.toml").read_text().replace("sad_patch = 16", "sad_patch = 12"))
    with pytest.raises(ConfigError, match="sad_patch"):
        load_run_config(bad)
