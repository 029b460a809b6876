"""The L x K vertex grid of a solid of revolution and its triangulation, for export (paper Sec. 3.1)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch

from radar_cli.config import CameraConfig
from radar_cli.sor.profile import check_sor


@dataclass(frozen=True)
class SorMesh:
    """One triangulated SoR in the canonical object frame (axis = y, the side facing the camera at -z).

    Attributes:
        vertices: V x 3 float positions, object-space units (r_max = CameraConfig.r_max).
        faces: F x 3 int vertex indices, counter-clockwise seen from outside.
        uv: V x 2 texture coordinates in [0, 1] of the 360 deg map (u = 0 at the back, -180 deg, growing with
            the angle; v = 1 at the top), the glTF/OBJ convention with the image's first row at v = 1.
    """

    vertices: torch.Tensor
    faces: torch.Tensor
    uv: torch.Tensor


def vertex_grid(radius: torch.Tensor, height: torch.Tensor, n_cols: int = 96,
                camera: CameraConfig = CameraConfig()) -> torch.Tensor:
    """The vertex map V (paper Sec. 3.1): L rows along the axis x K evenly spaced angles in [0, 360).

    Args:
        radius: B x L radius column (fractions of r_max), row 0 at the top.
        height: B half-heights (fractions of r_max).
        n_cols: K, angles around the axis; angle 0 faces the camera.

    Returns:
        B x L x K x 3 canonical positions.
    """
    check_sor(radius, height, torch.zeros(radius.shape[0], 4, dtype=radius.dtype, device=radius.device))
    n_rows = radius.shape[1]
    theta = torch.arange(n_cols, dtype=radius.dtype, device=radius.device) * (2 * math.pi / n_cols)
    y = torch.linspace(1.0, -1.0, n_rows, dtype=radius.dtype, device=radius.device)  # L, top to bottom
    r = radius[:, :, None] * camera.r_max  # B x L x 1
    ys = (y[None, :, None] * height[:, None, None] * camera.r_max).expand(-1, -1, n_cols)
    return torch.stack([r * torch.sin(theta), ys, -r * torch.cos(theta)], dim=-1)  # B x L x K x 3


def triangulate(radius: torch.Tensor, height: torch.Tensor, n_cols: int = 96, closed_bottom: bool = True,
                camera: CameraConfig = CameraConfig()) -> SorMesh:
    """Triangulate one SoR (B = 1) as an open-topped vessel with a closed base, with a texture seam.

    The seam column is duplicated (K + 1 columns) so u runs continuously 0..1 around the object.

    Args:
        radius: 1 x L; height: 1; n_cols: K.
        closed_bottom: add a fan closing the base.

    Returns:
        SorMesh.
    """
    if radius.shape[0] != 1:
        raise ValueError(f"triangulate takes one shape (1 x L), got {tuple(radius.shape)}")
    n_rows = radius.shape[1]
    grid = vertex_grid(radius, height, n_cols, camera)[0]  # L x K x 3
    # start the columns at the back (-180 deg) so the 360 deg map's middle column faces the camera
    grid = torch.roll(grid, shifts=n_cols // 2, dims=1)
    grid = torch.cat([grid, grid[:, :1]], dim=1)  # L x (K+1) x 3, seam duplicated
    k1 = n_cols + 1
    verts = grid.reshape(-1, 3)
    u = torch.arange(k1, dtype=radius.dtype) / n_cols
    v = torch.linspace(1.0, 0.0, n_rows, dtype=radius.dtype)
    uv = torch.stack(torch.meshgrid(v, u, indexing="ij")[::-1], dim=-1).reshape(-1, 2)
    idx = torch.arange(n_rows * k1).view(n_rows, k1)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = torch.cat([torch.stack([a, b, c], -1).reshape(-1, 3), torch.stack([b, d, c], -1).reshape(-1, 3)])
    if closed_bottom:
        centre = torch.tensor([[0.0, float(grid[-1, 0, 1]), 0.0]], dtype=verts.dtype)
        ci = verts.shape[0]
        ring = idx[-1, :-1]
        fan = torch.stack([ring, torch.roll(ring, -1), torch.full_like(ring, ci)], -1)
        verts = torch.cat([verts, centre])
        uv = torch.cat([uv, torch.tensor([[0.5, 0.0]], dtype=uv.dtype)])
        faces = torch.cat([faces, fan])
    return SorMesh(verts, faces.long(), uv)
