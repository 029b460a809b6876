"""Closed-form surface points, normals and view directions on a regular (height x angle) grid of the SoR.

This is the geometry of the unwrapped texture space: row i <-> v_i = -1 + (2i+1)/rows (top to bottom),
column j <-> angle phi_j = (-1 + (2j+1)/cols) * span, with span = pi/3 for the frontal third, pi for 360 deg.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch

from radar_cli.config import CameraConfig
from radar_cli.sor.pose import directions_to_camera, object_to_camera
from radar_cli.sor.profile import radius_at, slope_at
from radar_cli.sor.solid import Solid

FRONT_SPAN = math.pi / 3.0  # the frontal third: phi in [-60, 60] deg around the direction facing the camera
FULL_SPAN = math.pi


@dataclass(frozen=True)
class SurfaceGrid:
    """Surface samples on a rows x cols grid, camera space.

    Attributes:
        points: B x rows x cols x 3 positions.
        normals: B x rows x cols x 3 unit outward normals.
        view: B x rows x cols x 3 unit directions from the surface towards the camera.
    """

    points: torch.Tensor
    normals: torch.Tensor
    view: torch.Tensor


def grid_centres(n: int, device=None, dtype=torch.float32) -> torch.Tensor:
    """n cell centres in [-1, 1] (grid_sample's align_corners=False convention)."""
    return (torch.arange(n, device=device, dtype=dtype) * 2.0 + 1.0) / n - 1.0


def surface_grid(
    solid: Solid,
    rows: int,
    cols: int,
    camera: CameraConfig = CameraConfig(),
    span: float = FRONT_SPAN,
) -> SurfaceGrid:
    """Sample the surface of revolution on a regular grid.

    Args:
        solid: B solids (radius B x L in fractions of r_max, height B, pose B x 4).
        rows, cols: grid size. span: half-width of the angular range in radians.

    Returns:
        SurfaceGrid of B x rows x cols x 3 tensors.
    """
    radius, height, pose = solid.radius, solid.height, solid.pose
    n_batch, dev, dt = radius.shape[0], radius.device, radius.dtype
    v = grid_centres(rows, dev, dt).expand(n_batch, rows)  # B x rows
    phi = grid_centres(cols, dev, dt) * span  # cols
    r = radius_at(radius, v) * camera.r_max  # B x rows
    y = -v * height[:, None] * camera.r_max  # B x rows
    sin, cos = torch.sin(phi), torch.cos(phi)
    pts = torch.stack(
        [r[..., None] * sin, y[..., None].expand(-1, -1, cols), -r[..., None] * cos], dim=-1
    )  # B x rows x cols x 3
    slope = slope_at(radius, height, v)[..., None].expand(-1, -1, cols)  # B x rows x cols
    nrm = torch.stack([sin.expand_as(slope), -slope, -cos.expand_as(slope)], dim=-1)
    nrm = nrm / nrm.norm(dim=-1, keepdim=True)
    pts_cam = object_to_camera(pts, pose, camera)
    nrm_cam = directions_to_camera(nrm, pose)
    view = -pts_cam / pts_cam.norm(dim=-1, keepdim=True)
    return SurfaceGrid(pts_cam, nrm_cam, view)
