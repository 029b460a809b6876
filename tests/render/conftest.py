"""Shared fixtures for the renderer tests: random vase profiles (the paper's synthetic recipe) and poses."""

from __future__ import annotations

import math

import pytest
import torch

from radar_cli.config import GeometryConfig

L_ROWS = 32


def sine_profiles(n: int, generator: torch.Generator, dtype=torch.float64) -> torch.Tensor:
    """n x L radius columns from the supplementary's two-sine recipe, clamped to the radius range."""

    def u(lo: float, hi: float) -> torch.Tensor:
        return torch.rand(n, 1, generator=generator, dtype=dtype) * (hi - lo) + lo

    i = torch.arange(L_ROWS, dtype=dtype)[None]
    t, a1, p1, q1 = u(0.1, 0.3), u(0.0, 0.3), u(-math.pi, 0.0), u(math.pi / 2, 2 * math.pi)
    a2, p2, q2 = u(0.0, 0.1), u(0.0, 2 * math.pi), u(math.pi / 2, 2 * math.pi)
    r = (t + a1 * (1 + torch.sin((L_ROWS - i) / L_ROWS * p1 + i / L_ROWS * q1))
         + a2 * (1 + torch.sin(p2 + i / L_ROWS * q2)))
    lo, hi = GeometryConfig().radius_range
    return r.clamp(lo, hi)


def random_poses(n: int, generator: torch.Generator, dtype=torch.float64) -> torch.Tensor:
    """n x 4 poses (pitch, roll, tx, ty) uniformly in the paper's ranges."""
    geo = GeometryConfig()
    ranges = [geo.pitch_range, geo.roll_range, geo.trans_range, geo.trans_range]
    lo = torch.tensor([r[0] for r in ranges], dtype=dtype)
    hi = torch.tensor([r[1] for r in ranges], dtype=dtype)
    return lo + (hi - lo) * torch.rand(n, 4, generator=generator, dtype=dtype)


def random_heights(n: int, generator: torch.Generator, dtype=torch.float64) -> torch.Tensor:
    """n half-heights in the paper's range."""
    lo, hi = GeometryConfig().height_range
    return lo + (hi - lo) * torch.rand(n, generator=generator, dtype=dtype)


@pytest.fixture
def random_sor():
    """random_sor(n, seed, dtype) -> (radius n x L, height n, pose n x 4)."""

    def make(n: int, seed: int = 0, dtype=torch.float64):
        g = torch.Generator().manual_seed(seed)
        return sine_profiles(n, g, dtype), random_heights(n, g, dtype), random_poses(n, g, dtype)

    return make


@pytest.fixture(autouse=True)
def one_thread():
    """Run renderer tests on one intra-op thread: on a shared, busy CPU OpenMP's spinning threads cost more than
    they gain at these small sizes (docs/performance.md, Threads)."""
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)
