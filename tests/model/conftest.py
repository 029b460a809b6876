"""Fixtures for model tests: a tiny RunConfig (32 px images, 32 x 32 textures) so every network runs in ms."""

from __future__ import annotations

import pytest
import torch

from radar_cli.config import GeometryConfig, RenderConfig
from radar_cli.model.config import LossConfig, ModelConfig, RunConfig, TrainConfig
from radar_cli.model.losses import distance_transform
from radar_cli.threads import torch_threads
from radar_cli.train.step import Batch


def tiny_config(**loss) -> RunConfig:
    """A RunConfig with the paper's structure at toy sizes."""
    render = RenderConfig(image_size=32, tex_height=32, tex_width=32, env_height=4, env_width=12,
                          shading_height=8, shading_width=8)
    model = ModelConfig(render=render, geometry=GeometryConfig(n_rows=16), shape_width=8, light_width=8,
                        albedo_width=8, disc_width=8, max_channels=32, latent=16, albedo_depth=3)
    train = TrainConfig(batch_size=4, iterations=4, checkpoint_every=2, keep_checkpoints=2, image_every=2,
                        log_every=1, device="cpu")
    return RunConfig(name="tiny", model=model, loss=LossConfig(sad_patch=8, **loss), train=train).validate()


def box_batch(n: int, rows: slice = slice(6, 26), cols: slice = slice(10, 22)) -> Batch:
    """n random 32 px images whose target silhouette is one box (the current torch RNG draws the images)."""
    image = torch.rand(n, 3, 32, 32)
    mask = torch.zeros(n, 32, 32)
    mask[:, rows, cols] = 1
    dts = torch.stack([torch.from_numpy(distance_transform(m.numpy() > 0)) for m in mask])
    return Batch(image, mask, dts)


@pytest.fixture
def tiny() -> RunConfig:
    return tiny_config()


@pytest.fixture(autouse=True)
def one_thread():
    """One torch thread: on a shared 2-core machine two OpenMP threads oversubscribe (docs/performance.md, Threads)."""
    with torch_threads(1):
        yield
