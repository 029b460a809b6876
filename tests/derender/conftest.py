"""Fixtures for de-rendering tests: a small hand-built 'model' whose Decomposition depends on the image, so the
whole export path runs in milliseconds without trained weights."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from radar_cli.config import CameraConfig, GeometryConfig, RenderConfig
from radar_cli.derender.run.predictor import Predictor
from radar_cli.model.config import ModelConfig
from radar_cli.model.outputs import Decomposition
from radar_cli.render.lighting import GAMMA

SIZE = 64
SETUP = ModelConfig(render=RenderConfig(image_size=SIZE, tex_height=32, tex_width=32, env_height=8, env_width=24,
                                        shading_height=16, shading_width=16),
                    camera=CameraConfig(), geometry=GeometryConfig(n_rows=16, n_cols=24))


class FakeModel:
    """image B x 3 x S x S -> a plausible Decomposition (vase profile, albedo from the image, one key light)."""

    def __call__(self, image: torch.Tensor) -> Decomposition:
        b = image.shape[0]
        r = SETUP.render
        y = torch.linspace(1, -1, SETUP.geometry.n_rows)
        bright = image.mean(dim=(1, 2, 3))  # B
        radius = (0.35 + 0.2 * torch.sin(2.5 * y)[None] + 0.1 * bright[:, None]).clamp(0.1, 0.85)
        height = 0.6 + 0.2 * bright
        pose = torch.stack([10 * bright, torch.zeros(b), torch.zeros(b), torch.zeros(b)], 1)
        albedo = F.interpolate(image, size=(r.tex_height, r.tex_width), mode="area") ** GAMMA
        env = torch.full((b, r.env_height, r.env_width), 0.05)
        env[:, 2:4, 10:13] = 2.0
        return Decomposition(radius, height, pose, albedo, env, 20 + 40 * bright, 0.3 + 0 * bright)


@pytest.fixture
def predictor() -> Predictor:
    return Predictor(FakeModel(), SETUP, "fake-model", "cpu")


@pytest.fixture
def fake_checkpoint(monkeypatch, predictor: Predictor) -> None:
    """`radar derender` loads the tiny untrained `predictor` whatever --checkpoint says."""
    monkeypatch.setattr(Predictor, "from_checkpoint",
                        classmethod(lambda cls, path, device, albedo, pitch, refine="none", reader="bundled":
                                    predictor))


def vase_photo(seed: int, shape: tuple[int, int] = (SIZE, SIZE)) -> np.ndarray:
    """H x W x 3 uint8: a dark ellipse on a light backdrop (so radar masks' detector finds it)."""
    rng = np.random.default_rng(seed)
    h, w = shape
    yy, xx = np.mgrid[0:h, 0:w]
    inside = ((xx - w / 2) / (0.2 * min(h, w))) ** 2 + ((yy - h / 2) / (0.35 * min(h, w))) ** 2 < 1
    image = np.full((h, w, 3), 225, np.uint8)
    image[inside] = rng.integers(40, 140, 3)
    return image


def write_photo(path: Path, seed: int, shape: tuple[int, int] = (SIZE, SIZE)) -> Path:
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(vase_photo(seed, shape)).save(path)
    return path
