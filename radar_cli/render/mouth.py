"""Soft coverage of a vase's open mouth in the image: where the camera looks into the vessel.

A pixel looks through the mouth when its ray crosses the rim's plane y = +h (canonical frame) inside the rim,
rho < r_top, before anything else (the camera sits above the plane for pitch >= 0, so nothing can come first).
The coverage sigmoid((r_top - rho) / sigma) is smooth in the radius column, the height and the pose, so the
mouth's projected ellipse, whose depth is r_top sin(pitch), can be fitted to an image where the inside is
darker than the outside: a pitch cue that the outline alone barely carries at low resolution (README, Training).
"""

from __future__ import annotations

import torch

from radar_cli.config import CameraConfig
from radar_cli.sor.camera import pixel_rays, pixel_size
from radar_cli.sor.pose import rotation_matrix, translation
from radar_cli.sor.profile import check_sor


def mouth_coverage(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, size: int,
                   camera: CameraConfig = CameraConfig(), sigma_px: float = 1.0) -> torch.Tensor:
    """Soft mask of the open mouth as seen from the camera.

    Args:
        radius: B x L radius column (fractions of r_max, row 0 = top); height: B half-heights; pose: B x 4.
        size: image side in pixels. sigma_px: softness of the rim's edge in pixels (at the object's distance).

    Returns:
        B x size x size coverage in [0, 1], differentiable in radius[:, 0], height and pose.
    """
    check_sor(radius, height, pose)
    rot = rotation_matrix(pose)  # B x 3 x 3
    origin = -(rot.transpose(1, 2) @ translation(pose, camera)[..., None])[..., 0]  # B x 3, canonical frame
    dirs = pixel_rays(size, camera, radius.device, radius.dtype).reshape(-1, 3)
    d_obj = (dirs / dirs.norm(dim=-1, keepdim=True)) @ rot  # B x P x 3
    h = height * camera.r_max  # B
    dy = d_obj[..., 1]
    safe_dy = torch.where(dy.abs() < 1e-9, torch.full_like(dy, -1e-9), dy)
    s = (h[:, None] - origin[:, None, 1]) / safe_dy  # B x P: where each ray meets the plane y = h
    p = origin[:, None, :] + s[..., None] * d_obj
    rho = torch.sqrt(p[..., 0] ** 2 + p[..., 2] ** 2 + 1e-20)
    sigma = sigma_px * pixel_size(size, camera)
    cover = torch.sigmoid((radius[:, :1] * camera.r_max - rho) / sigma)
    crosses = (s > 0) & (dy < 0)  # met in front of the camera, going down into the vessel
    return torch.where(crosses, cover, torch.zeros_like(cover)).view(-1, size, size)
