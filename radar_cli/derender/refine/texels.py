"""The photograph unwrapped at a fitted shape onto a grid of frontal texels: what the lighting fit
(derender.refine.fit_light) and its white-spot check (derender.refine.glare) read of the photo."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.render.texture import sample_surface
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import surface_grid

MIN_READ = 0.05
"""Fewer read texels than this share of the grid: nothing to read."""


@dataclass(frozen=True)
class FrontTexels:
    """The n texels read: shown 3 x n, the photo's display colour in [0, 1]; normals, view n x 3 (camera frame);
    facing n, the cosine between the two."""

    shown: torch.Tensor
    normals: torch.Tensor
    view: torch.Tensor
    facing: torch.Tensor


def read_front(crop: np.ndarray, silhouette: np.ndarray, geo: Solid, side: int, camera: CameraConfig,
               coverage: float, min_facing: float, dtype: torch.dtype) -> FrontTexels | None:
    """The crop unwrapped at the solid onto side x side frontal texels, those covered by the silhouette more than
    `coverage` and facing the camera more than `min_facing` (cosine) kept.

    Args:
        crop: N x N x 3 uint8; silhouette: N x N bool. geo: the solid (batch of one) in `dtype`.

    Returns:
        The texels read, or None where fewer than MIN_READ of the grid are.
    """
    image = torch.from_numpy(np.ascontiguousarray(crop)).permute(2, 0, 1)[None].to(dtype) / 255.0
    cover = torch.from_numpy(silhouette).to(dtype)[None, None]
    grid = surface_grid(geo, side, side, camera)
    texture = sample_surface(torch.cat([image, cover], 1), grid, camera)[0].reshape(4, -1)  # 4 x side^2
    normals, view = grid.normals[0].reshape(-1, 3), grid.view[0].reshape(-1, 3)
    facing = (normals * view).sum(-1)
    read = (texture[3] > coverage) & (facing > min_facing)
    if int(read.sum()) < MIN_READ * side * side:
        return None
    return FrontTexels(texture[:3, read], normals[read], view[read], facing[read])
