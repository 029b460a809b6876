"""Bad input: wrong shapes, NaN and out-of-range parameters raise InputError naming the argument."""

from __future__ import annotations

import pytest
import torch

from radar_cli.errors import InputError
from radar_cli.render.lighting import shading_factors
from radar_cli.render.material import Material
from radar_cli.render.raycast import cast_rays
from radar_cli.render.scene import render_view, shade
from radar_cli.render.texture import render_texture, unwrap
from radar_cli.sor.solid import Solid


def good(n: int = 2):
    return torch.full((n, 32), 0.4), torch.full((n,), 0.8), torch.zeros(n, 4)


@pytest.mark.parametrize(
    "change, name",
    [
        (lambda r, h, p: (r[:, :, None], h, p), "radius"),
        (lambda r, h, p: (r, h[:1], p), "height"),
        (lambda r, h, p: (r, h, p[:, :3]), "pose"),
        (lambda r, h, p: (r[:, :1], h, p), "radius"),
        (lambda r, h, p: (r.long(), h, p), "radius"),
        (lambda r, h, p: (r.index_fill(1, torch.tensor([3]), float("nan")), h, p), "radius"),
        (lambda r, h, p: (r, torch.full_like(h, float("nan")), p), "height"),
        (lambda r, h, p: (r, h, p.index_fill(1, torch.tensor([0]), float("inf"))), "pose"),
        (lambda r, h, p: (-r, h, p), "radius"),
        (lambda r, h, p: (r, h * 10, p), "height"),
        (lambda r, h, p: (r, h, p.index_fill(1, torch.tensor([0]), 120.0)), "pose"),
        (lambda r, h, p: (r, h, p.index_fill(1, torch.tensor([2]), 3.0)), "pose"),
    ],
)
def test_cast_rays_rejects_bad_parameters(change, name):
    with pytest.raises(InputError, match=name):
        cast_rays(Solid(*change(*good())), 16)


@pytest.mark.parametrize("size, sigma", [(0, 1.0), (16, 0.0), (16, float("nan"))])
def test_cast_rays_rejects_bad_size_or_sigma(size, sigma):
    with pytest.raises(InputError, match="size|sigma"):
        cast_rays(Solid(*good()), size, sigma_px=sigma)


def test_texture_ops_reject_bad_shapes():
    r, h, p = good()
    hits = cast_rays(Solid(r, h, p), 16)
    with pytest.raises(InputError, match="texture"):
        render_texture(hits, torch.rand(3, 3, 8, 8))
    with pytest.raises(InputError, match="texture"):
        render_texture(hits, torch.rand(2, 8, 8))
    with pytest.raises(InputError, match="image"):
        unwrap(Solid(r, h, p), torch.rand(2, 16, 16), (8, 8))
    with pytest.raises(InputError, match="image"):
        unwrap(Solid(r, h, p), torch.rand(2, 3, 16, 16).index_fill(2, torch.tensor([1]), float("nan")), (8, 8))


def test_shading_rejects_bad_inputs():
    r, h, p = good()
    albedo, env = torch.rand(2, 3, 8, 8), torch.rand(2, 16, 48)
    alpha, rho = torch.tensor([5.0, 5.0]), torch.tensor([0.5, 0.5])
    with pytest.raises(InputError, match="env"):
        shade(Solid(r, h, p), Material(albedo, env[:, None], alpha, rho))
    with pytest.raises(InputError, match="env"):
        shade(Solid(r, h, p), Material(albedo, -env, alpha, rho))
    with pytest.raises(InputError, match="alpha"):
        shade(Solid(r, h, p), Material(albedo, env, torch.tensor([float("nan"), 1.0]), rho))
    with pytest.raises(InputError, match="rho"):
        shade(Solid(r, h, p), Material(albedo, env, alpha, -rho))
    with pytest.raises(InputError, match="albedo"):
        shade(Solid(r, h, p), Material(albedo[:, :2], env, alpha, rho))
    with pytest.raises(InputError, match="radius"):
        shade(Solid(r[:, :, None], h, p), Material(albedo, env, alpha, rho))
    with pytest.raises(InputError, match="normals"):
        shading_factors(torch.rand(2, 4, 4, 2), torch.rand(2, 4, 4, 3), env, alpha)
    with pytest.raises(InputError, match="albedo_full"):
        render_view(Solid(r, h, p), Material(torch.rand(2, 3, 8), env, alpha, rho), 16)
