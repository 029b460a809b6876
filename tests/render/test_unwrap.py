"""Unwrapping a rendered textured vase gives back its frontal third (PSNR >= 30 dB, 128 px)."""

from __future__ import annotations

import torch
import torch.nn.functional as F

from radar_cli.config import CameraConfig
from radar_cli.render.raycast import cast_rays
from radar_cli.render.scene import render_front
from radar_cli.render.texture import front_third, full_from_front, unwrap
from radar_cli.sor.camera import project
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import surface_grid

SIZE = 128
TEX = (48, 48)


def smooth_texture(n: int, seed: int) -> torch.Tensor:
    g = torch.Generator().manual_seed(seed)
    coarse = torch.rand(n, 3, 6, 6, generator=g)
    return F.interpolate(coarse, size=TEX, mode="bicubic", align_corners=False).clamp(0, 1)


def psnr(a: torch.Tensor, b: torch.Tensor) -> float:
    return float(10 * torch.log10(1.0 / ((a - b) ** 2).mean()))


def test_unwrap_round_trip_over_the_visible_frontal_third(random_sor):
    camera = CameraConfig()
    radius, height, pose = random_sor(4, seed=21, dtype=torch.float32)
    texture = smooth_texture(4, seed=22)
    hits = cast_rays(Solid(radius, height, pose), SIZE, camera)
    image, mask = render_front(hits, texture)
    back = unwrap(Solid(radius, height, pose), image, TEX, camera)
    # texels whose projection lies inside the rendered frontal mask (all four bilinear taps): the visible part
    xy = project(surface_grid(Solid(radius, height, pose), *TEX, camera).points, camera)
    visible = F.grid_sample(mask, xy, mode="bilinear", align_corners=False) > 0.999  # B x 1 x Ht x Wt
    assert visible.float().mean() > 0.8
    sel = visible.expand_as(texture)
    assert psnr(back[sel], texture[sel]) >= 30.0


def test_front_third_and_full_from_front_are_consistent():
    front = smooth_texture(2, seed=1)
    full = full_from_front(front)
    assert full.shape == (2, 3, TEX[0], 3 * TEX[1])
    assert torch.equal(front_third(full), front)
    assert torch.equal(full[..., TEX[1] - 1], full[..., TEX[1]])  # seamless join: mirrored edge columns meet
