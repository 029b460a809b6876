"""The fixed pinhole camera: pixel rays and projection to grid_sample coordinates (square images, fov 10 deg)."""

from __future__ import annotations

import math

import torch

from radar_cli.config import CameraConfig


def pixel_rays(size: int, camera: CameraConfig, device=None, dtype=torch.float32) -> torch.Tensor:
    """Unnormalised ray directions through pixel centres, z = 1.

    Image x grows right (+x), image rows grow down (-y).

    Returns:
        size x size x 3 directions.
    """
    tan = math.tan(math.radians(camera.fov_deg) / 2.0)
    c = (torch.arange(size, device=device, dtype=dtype) + 0.5) * (2.0 / size) - 1.0  # pixel centres in [-1, 1]
    y, x = torch.meshgrid(-c * tan, c * tan, indexing="ij")
    return torch.stack([x, y, torch.ones_like(x)], dim=-1)


def project(points: torch.Tensor, camera: CameraConfig) -> torch.Tensor:
    """Camera-space points (B x ... x 3) -> image coordinates in [-1, 1] (B x ... x 2), grid_sample's convention
    with align_corners=False: (-1, -1) is the top-left corner of the top-left pixel."""
    tan = math.tan(math.radians(camera.fov_deg) / 2.0)
    z = points[..., 2:3].clamp_min(1e-6)
    xy = points[..., :2] / z / tan
    return torch.cat([xy[..., :1], -xy[..., 1:]], dim=-1)


def pixel_size(size: int, camera: CameraConfig) -> float:
    """Width of one pixel in object-space units at the object's distance."""
    return 2.0 * camera.r_max / size
