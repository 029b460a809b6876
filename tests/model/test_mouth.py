"""The mouth term: its soft coverage is the set of rays that enter the vessel, and fitting the darker inside
pulls the pitch towards the truth from either side (radar's addition; docs/training.md)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from radar_cli.config import RenderConfig
from radar_cli.errors import ConfigError
from radar_cli.model import losses as L
from radar_cli.model.radar import RadarModel
from radar_cli.render.lighting import compose
from radar_cli.render.material import Material
from radar_cli.render.mouth import mouth_coverage
from radar_cli.render.raycast import cast_rays
from radar_cli.render.scene import render_front, render_view, shade
from radar_cli.sor.solid import Solid
from radar_cli.synth.shapes import sample_shape
from radar_cli.train.step import generator_losses

from .conftest import box_batch, tiny_config

RENDER = RenderConfig(image_size=64, tex_height=32, tex_width=32, env_height=8, env_width=24, shading_height=16,
                      shading_width=16)


def _vase(seed: int, pitch: float):
    shape = sample_shape(np.random.default_rng(seed))
    radius = torch.tensor(np.asarray(shape.radius), dtype=torch.float32)[None]
    return radius, torch.tensor([shape.height], dtype=torch.float32), torch.tensor([[pitch, 0.0, 0.0, 0.0]])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_coverage_is_the_rays_that_enter_the_mouth(seed):
    radius, height, pose = _vase(seed, 15.0)
    inner = cast_rays(Solid(radius, height, pose), 96).inner[0]
    cover = mouth_coverage(radius, height, pose, 96)[0]
    assert inner.sum() > 20
    assert ((cover > 0.5) == inner).float().mean() > 0.998
    assert mouth_coverage(radius, height, torch.zeros(1, 4), 96).max() < 1e-3  # side on: no mouth seen


def test_mouth_term_pulls_pitch_towards_the_truth_from_both_sides():
    radius, height, pose = _vase(4, 12.0)
    albedo = torch.full((1, 3, 32, 96), 0.5)
    env = torch.full((1, 8, 24), 0.3)
    alpha, rho = torch.tensor([20.0]), torch.tensor([0.2])
    with torch.no_grad():
        image, cover = render_view(Solid(radius, height, pose), Material(albedo, env, alpha, rho), 64, render=RENDER)
    mask = (cover > 0.5).float()
    for guess, sign in ((7.0, -1.0), (17.0, 1.0)):
        pitch = torch.tensor([guess], requires_grad=True)
        pred_pose = torch.cat([pitch[:, None], torch.zeros(1, 3)], dim=1)
        hits = cast_rays(Solid(radius, height, pred_pose), 64)
        shading = shade(Solid(radius, height, pred_pose), Material(albedo[..., 32:64], env, alpha, rho), RENDER)
        recon_mu, front = render_front(hits, compose(albedo[..., 32:64], shading.diffuse, shading.specular, rho))
        mouth = mouth_coverage(radius, height, pred_pose, 64)[:, None]
        region = mask * torch.maximum(front, hits.inner[:, None].float()).detach()
        L.mouth_l1(recon_mu, front, mouth, image, region, RENDER.inside_dim).backward()
        assert pitch.grad.item() * sign > 0, (guess, pitch.grad.item())  # descent moves towards 12


def test_mouth_term_in_the_training_losses():
    torch.manual_seed(0)
    config = tiny_config(mouth_weight=2.0)
    model = RadarModel(config.model)
    batch = box_batch(2, slice(4, 28), slice(8, 24))
    terms, _ = generator_losses(model(batch.image), batch, config, None)
    assert torch.isfinite(terms["mouth"]) and terms["mouth"].item() >= 0
    expected = (terms["sil"] + terms["im"] + terms["alb"] + 2.0 * terms["mouth"] + terms["diff"])
    assert torch.allclose(terms["total"], expected)
    assert "mouth" not in generator_losses(model(batch.image), batch, tiny_config(), None)[0]
    with pytest.raises(ConfigError, match="mouth"):
        tiny_config(mouth_weight=-1.0)
