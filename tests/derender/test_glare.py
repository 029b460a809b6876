"""The specular albedo lowered where the fitted highlights outshine the photo (derender.refine.glare): a vase in
black glaze photographed without highlights, drawn with its true lights and a specular albedo of 0.5, is lowered
until no white spot is left; the same vase photographed with those highlights keeps its specular albedo."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.glare import GlareConfig, _surface, dim
from radar_cli.sor.solid import Solid
from radar_cli.synth.generator import SynthConfig, make_sample
from radar_cli.synth.layout import ALBEDO_FILE
from radar_cli.synth.render import render_sample

SIZE = 256
RHO = 0.5


def _photo(index: int, rho: float):
    """A synthetic vase in black glaze (its albedo x 0.15) under its true lights with specular albedo `rho`:
    (crop, silhouette, solid, true map, shininess)."""
    files, params = make_sample(SynthConfig(size=SIZE, seed=3), "test", index, None)
    photo = render_sample(np.asarray(params["radius"]), params["height"], tuple(params["pose"]),
                          files[ALBEDO_FILE] * 0.15, files["env_map.npy"], params["alpha"], rho, SIZE,
                          SynthConfig(size=SIZE).render_config())
    image = (np.clip(photo.image, 0, 1) * 255 + 0.5).astype(np.uint8)
    solid = Solid(torch.tensor([params["radius"]], dtype=torch.float32), torch.tensor([params["height"]]),
                  torch.tensor([params["pose"]], dtype=torch.float32))
    return image, files["mask.png"] > 0.5, solid, torch.from_numpy(files["env_map.npy"]), params["alpha"]


@pytest.mark.parametrize("index", [0, 2])
def test_highlights_the_photo_does_not_have_are_dimmed(index):
    image, mask, solid, env, alpha = _photo(index, 0.0)
    config = GlareConfig()
    surface = _surface(image, mask, solid, tuple(env.shape), alpha, CameraConfig(), config)
    assert surface is not None
    assert surface.glare(env, RHO, config.glaring) > config.trigger  # white spots at the held specular albedo
    factor = dim(image, mask, solid, env, alpha, RHO, CameraConfig(), config)
    assert factor < 1.0
    assert surface.glare(env, RHO * factor, config.glaring) <= config.target
    # the largest factor of the ladder that does so
    assert surface.glare(env, RHO * factor / config.step, config.glaring) > config.target


@pytest.mark.parametrize("index", [0, 2])
def test_highlights_the_photo_has_are_kept(index):
    image, mask, solid, env, alpha = _photo(index, RHO)
    assert dim(image, mask, solid, env, alpha, RHO, CameraConfig()) == 1.0


def test_nothing_to_read_keeps_the_specular_albedo():
    image, mask, solid, env, alpha = _photo(0, 0.0)
    assert dim(image, np.zeros_like(mask), solid, env, alpha, RHO, CameraConfig()) == 1.0
