"""Soft coverage of a vase's open mouth in the image: where the camera looks into the vessel.

A pixel looks through the mouth when its ray crosses the rim's plane y = +h (canonical frame) inside the rim,
rho < r_top, before anything else (the camera sits above the plane for pitch >= 0, so nothing can come first).
The coverage sigmoid((r_top - rho) / sigma) is smooth in the radius column, the height and the pose, so the
mouth's projected ellipse, whose depth is r_top sin(pitch), can be fitted to an image where the inside is
darker than the outside: a pitch cue that the outline alone barely carries at low resolution (docs/training.md).
"""

from __future__ import annotations

import math

import torch

from radar_cli.config import CameraConfig
from radar_cli.render.raycast import object_rays
from radar_cli.sor.camera import pixel_size
from radar_cli.sor.profile import check_sor


def mouth_margin(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, size: int,
                 camera: CameraConfig = CameraConfig()) -> torch.Tensor:
    """How far inside the rim each pixel's ray crosses the rim's plane, in pixels at the object's distance.

    Args:
        radius: B x L radius column (fractions of r_max, row 0 = top); height: B half-heights; pose: B x 4.
        size: image side in pixels.

    Returns:
        B x size x size: r_top - rho (> 0 inside the mouth), -inf for rays that never cross the plane going
        down; differentiable in radius[:, 0], height and pose.
    """
    check_sor(radius, height, pose)
    _, origin, _, d_obj = object_rays(pose, size, camera)  # B x 3, B x P x 3
    h = height * camera.r_max  # B
    dy = d_obj[..., 1]
    safe_dy = torch.where(dy.abs() < 1e-9, torch.full_like(dy, -1e-9), dy)
    s = (h[:, None] - origin[:, None, 1]) / safe_dy  # B x P: where each ray meets the plane y = h
    p = origin[:, None, :] + s[..., None] * d_obj
    rho = torch.sqrt(p[..., 0] ** 2 + p[..., 2] ** 2 + 1e-20)
    margin = (radius[:, :1] * camera.r_max - rho) / pixel_size(size, camera)
    crosses = (s > 0) & (dy < 0)  # met in front of the camera, going down into the vessel
    return torch.where(crosses, margin, torch.full_like(margin, -math.inf)).view(-1, size, size)


def coverage(margin: torch.Tensor, sigma_px: float = 1.0) -> torch.Tensor:
    """Soft mouth mask from mouth_margin: sigmoid(margin / sigma), in [0, 1] (0 where the ray misses)."""
    return torch.sigmoid(margin / sigma_px)


def coverage_above(margin: torch.Tensor, sigma_px: float, level: float) -> torch.Tensor:
    """coverage(margin, sigma_px) > level, as a bool mask, without evaluating the sigmoid."""
    return margin > sigma_px * math.log(level / (1.0 - level))


def mouth_coverage(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, size: int,
                   camera: CameraConfig = CameraConfig(), sigma_px: float = 1.0) -> torch.Tensor:
    """Soft mask of the open mouth as seen from the camera: B x size x size in [0, 1], differentiable in
    radius[:, 0], height and pose (sigma_px: softness of the rim's edge in pixels)."""
    return coverage(mouth_margin(radius, height, pose, size, camera), sigma_px)
