"""Spherical-Gaussian lobes: baked as radar synth bakes them, with an exact Jacobian; peaks found brightest first;
and a lobe fit that recovers the lights that drew a texture."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from radar_cli.derender.refine.light_lobes import LobeProblem, bake_lobes, direction, fit_lobes, peak_directions
from radar_cli.evaluate.metrics import env_error
from radar_cli.render.lighting import env_directions, phong_transport
from radar_cli.synth.lighting import Lobe, bake_env

SIZE = (16, 48)


def _theta(elevations, azimuths, sharpness, intensities) -> torch.Tensor:
    """theta (4k, float64) from degrees, sharpness and intensities."""
    return torch.tensor([*map(math.radians, elevations), *map(math.radians, azimuths),
                         *map(math.log, sharpness), *map(math.log, intensities)], dtype=torch.float64)


def _lobes(theta: torch.Tensor) -> list[Lobe]:
    k = theta.numel() // 4
    xi = direction(theta[:k], theta[k:2 * k])
    return [Lobe(tuple(map(float, xi[i])), float(theta[2 * k + i].exp()), float(theta[3 * k + i].exp()))
            for i in range(k)]


def test_bake_matches_the_synthetic_lighting():
    theta = _theta([20, 50, 5], [-40, 10, 70], [12, 28, 45], [0.2, 0.15, 0.3])
    env, _ = bake_lobes(theta, SIZE, jacobian=False)
    same = bake_env(_lobes(theta), *SIZE, supersample=2).reshape(-1)
    finer = bake_env(_lobes(theta), *SIZE).reshape(-1)  # the synthetic maps' 4 x 4 points per texel
    assert np.allclose(env.numpy(), same, rtol=1e-5, atol=1e-6)
    assert np.abs(env.numpy() - finer).max() < 0.02 * finer.max()


def test_jacobian_matches_autograd():
    theta = _theta([20, 60], [-30, 45], [8, 30], [0.2, 0.1])
    _, jac = bake_lobes(theta, SIZE)
    numeric = torch.autograd.functional.jacobian(lambda t: bake_lobes(t, SIZE, jacobian=False)[0], theta)
    assert jac.shape == (SIZE[0] * SIZE[1], 8)
    assert torch.allclose(jac, numeric, rtol=1e-9, atol=1e-12)


def test_peaks_brightest_first_above_the_floor():
    theta = _theta([30, 10, -40], [-45, 60, 0], [20, 20, 20], [0.1, 0.3, 0.5])
    env = bake_lobes(theta, SIZE, jacobian=False)[0].reshape(SIZE)
    el, az = peak_directions(env, 3, min_elevation=0.0)
    assert az[0] == pytest.approx(math.radians(60), abs=math.radians(8))  # the brighter of the two above
    assert az[1] == pytest.approx(math.radians(-45), abs=math.radians(8))
    assert el[0] == pytest.approx(math.radians(10), abs=math.radians(7))
    assert el[2] == pytest.approx(math.radians(30))  # the lobe below the horizon is not a start: filled in
    assert bool((el >= 0).all())


def _problem(theta: torch.Tensor, rho: float, alpha: float):
    """A hemisphere of texels facing the camera, two paints, drawn by the lobes of theta."""
    gen = torch.Generator().manual_seed(0)
    normals = torch.randn(600, 3, generator=gen, dtype=torch.float64)
    normals[:, 2] = -normals[:, 2].abs() - 0.3  # towards the camera (-z)
    normals = normals / normals.norm(dim=1, keepdim=True)
    view = torch.tensor([0.0, 0.0, -1.0], dtype=torch.float64).expand(600, 3)
    kd, ks = phong_transport(normals, view, *env_directions(*SIZE, dtype=torch.float64), alpha)
    paint = (torch.arange(600) % 2)
    colours = torch.tensor([[0.6, 0.3], [0.5, 0.3], [0.4, 0.2]], dtype=torch.float64)  # 3 x 2 paints
    env = bake_lobes(theta, SIZE, jacobian=False)[0]
    linear = colours[:, paint] * (kd @ env) + rho * (ks @ env)

    def paints(e: torch.Tensor) -> torch.Tensor:
        d, s = kd @ e, ks @ e
        num = torch.zeros(3, 2, dtype=d.dtype).index_add_(1, paint, d * (linear - rho * s))
        den = torch.zeros(2, dtype=d.dtype).index_add_(0, paint, d * d)
        return (num / den)[:, paint]

    problem = LobeProblem(torch.cat([kd, ks]).T.float().contiguous(), linear, rho, SIZE)
    return problem, paints, env


def test_fit_recovers_the_lobes_that_drew_the_texture():
    truth = _theta([25, 45], [-35, 30], [15, 25], [0.25, 0.2])
    problem, paints, env = _problem(truth, rho=0.3, alpha=40.0)
    start = bake_lobes(_theta([10, 20], [-60, 60], [6, 6], [0.2, 0.2]), SIZE, jacobian=False)[0]
    fitted = fit_lobes(problem, start.reshape(SIZE), 2, paints, rounds=4, steps=30, tolerance=1e-6,
                       sharpness=(4.0, 60.0), start_sharpness=15.0, min_elevation=0.0)
    true_map, start_map = env.reshape(SIZE).numpy(), start.reshape(SIZE).numpy()
    before = env_error(start_map, true_map)
    after = env_error(fitted.reshape(SIZE).numpy(), true_map)
    assert after < 0.05 * before, (before, after)
