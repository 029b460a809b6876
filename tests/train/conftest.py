"""Fixtures for training tests: a few vases rendered with the project's renderer into the dataset layout, and a
tiny RunConfig (32 px) so a training step takes a fraction of a second."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest
import torch

from radar_cli.config import GeometryConfig, RenderConfig
from radar_cli.dataset import sample_ref, write_sample
from radar_cli.model.config import LossConfig, ModelConfig, RunConfig, TrainConfig
from radar_cli.render.material import Material
from radar_cli.render.raycast import cast_rays
from radar_cli.render.scene import render_view
from radar_cli.sor.solid import Solid
from radar_cli.threads import torch_threads


def render_vases(root: Path, n: int, size: int, seed: int = 0) -> Path:
    """Write n rendered vases (two-sine profiles, banded albedo, one key light) to root/train/."""
    g = torch.Generator().manual_seed(seed)

    def u(*shape: int) -> torch.Tensor:
        return torch.rand(*shape, generator=g)

    rows = torch.arange(32, dtype=torch.float32)
    for k in range(n):
        t, a1, p1, q1 = 0.15 + 0.15 * u(1), 0.25 * u(1), -math.pi * u(1), math.pi / 2 + 1.5 * math.pi * u(1)
        radius = (t + a1 * (1 + torch.sin((32 - rows) / 32 * p1 + rows / 32 * q1)))[None].clamp(0.05, 0.9)
        height = 0.6 + 0.3 * u(1)
        pose = torch.tensor([[20 * float(u(1)), 0.0, 0.0, 0.0]])
        albedo = (0.3 + 0.6 * u(1, 3, 1, 1)).expand(1, 3, 16, 48).clone()
        albedo[:, :, ::4] *= 0.5
        env = torch.full((1, 8, 24), 0.3)
        env[0, 2, 10] = 3.0
        solid = Solid(radius, height, pose)
        image, _ = render_view(solid, Material(albedo, env, torch.tensor([20.0]), torch.tensor([0.5])), size,
                               background=1.0)
        hits = cast_rays(solid, size)
        write_sample(sample_ref(root, "train", f"v{k:03d}"), image[0].permute(1, 2, 0).clamp(0, 1).numpy(),
                     hits.mask[0].numpy())
    return root


@pytest.fixture(scope="session")
def vases32(tmp_path_factory) -> Path:
    """8 rendered 32 px vases."""
    return render_vases(tmp_path_factory.mktemp("vases32"), 8, 32)


@pytest.fixture(scope="session")
def vases64(tmp_path_factory) -> Path:
    """4 rendered 64 px vases (the CPU preset's size)."""
    return render_vases(tmp_path_factory.mktemp("vases64"), 4, 64, seed=1)


def tiny_config(lr: float = 2e-4, **train) -> RunConfig:
    """The paper's structure at toy sizes: 32 px images and textures, narrow networks."""
    render = RenderConfig(image_size=32, tex_height=32, tex_width=32, env_height=4, env_width=12,
                          shading_height=8, shading_width=8)
    model = ModelConfig(render=render, geometry=GeometryConfig(n_rows=16), shape_width=8, light_width=8,
                        albedo_width=8, disc_width=8, max_channels=32, latent=16, albedo_depth=3)
    t = TrainConfig(lr=lr, batch_size=4, iterations=4, checkpoint_every=2, keep_checkpoints=2, image_every=2,
                    log_every=1, device="cpu")
    return RunConfig(name="tiny", model=model, loss=LossConfig(sad_patch=8),
                     train=dataclasses.replace(t, **train)).validate()


@pytest.fixture(autouse=True)
def one_thread():
    """One torch thread: on a shared 2-core machine two OpenMP threads oversubscribe (docs/performance.md, Threads)."""
    with torch_threads(1):
        yield
