"""The exported vertex grid and triangulation: outward normals, uv in [0, 1], sizes."""

from __future__ import annotations

import pytest
import torch

from radar_cli.config import CameraConfig
from radar_cli.errors import InputError
from radar_cli.sor.mesh import triangulate, vertex_grid


def vase():
    y = torch.linspace(0, 1, 32)
    return (0.3 + 0.2 * torch.sin(3 * y))[None], torch.tensor([0.8])


def test_vertex_grid_lies_on_the_profile():
    radius, height = vase()
    grid = vertex_grid(radius, height, n_cols=24)
    r_max = CameraConfig().r_max
    assert grid.shape == (1, 32, 24, 3)
    rho = torch.sqrt(grid[..., 0] ** 2 + grid[..., 2] ** 2)
    assert torch.allclose(rho, radius[0, :, None].expand(-1, 24) * r_max, atol=1e-5)
    assert torch.allclose(grid[0, 0, :, 1], torch.full((24,), 0.8 * r_max))  # row 0 at the top
    assert torch.allclose(grid[0, -1, :, 1], torch.full((24,), -0.8 * r_max))
    assert torch.allclose(grid[0, :, 0, 0], torch.zeros(32), atol=1e-6) and (grid[0, :, 0, 2] < 0).all()  # faces camera


def test_triangulation_normals_point_outward_and_uv_in_unit_square():
    radius, height = vase()
    mesh = triangulate(radius, height, n_cols=48)
    v, f = mesh.vertices, mesh.faces
    assert v.shape == (32 * 49 + 1, 3) and mesh.uv.shape == (v.shape[0], 2)
    assert mesh.uv.min() >= 0 and mesh.uv.max() <= 1
    assert f.min() >= 0 and f.max() < v.shape[0]
    tri = v[f]  # F x 3 x 3
    normal = torch.linalg.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = normal.norm(dim=-1)
    centre = tri.mean(1)
    side = area > 1e-9
    n_side = f.shape[0] - 48
    outward = centre.clone()
    outward[:, 1] = 0
    dots = (normal * outward).sum(-1)
    assert (dots[:n_side][side[:n_side]] > 0).all()
    assert (normal[n_side:, 1] < 0).all()  # the closed base faces down


def test_triangulate_rejects_batches_and_bad_values():
    radius, height = vase()
    with pytest.raises((InputError, ValueError), match="1 x L|radius"):
        triangulate(radius.expand(2, -1), height.expand(2))
    with pytest.raises(InputError, match="radius"):
        triangulate(radius * float("nan"), height)
