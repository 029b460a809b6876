"""mesh.obj written by radar's own formatter: the bytes trimesh's OBJ exporter writes, loaded back by trimesh."""

from __future__ import annotations

import io

import numpy as np
import torch
import trimesh
from PIL import Image

from radar_cli.derender.export.mesh import OBJ_MTL, TO_VIEWER_FRONT, obj_text
from radar_cli.sor.mesh import triangulate


def _mesh() -> trimesh.Trimesh:
    radius = (0.2 + 0.7 * torch.rand(1, 40, generator=torch.Generator().manual_seed(0)))
    sor = triangulate(radius, torch.tensor([0.9]), 24, closed_bottom=True)
    vertices = sor.vertices.numpy().astype(np.float64) * TO_VIEWER_FRONT
    vertices[0, 0], vertices[1, 0] = -0.0, -1e-12  # signed zeros print as trimesh prints them
    material = trimesh.visual.material.SimpleMaterial(name="albedo", image=Image.new("RGB", (6, 2)))
    return trimesh.Trimesh(vertices, sor.faces.numpy(), visual=trimesh.visual.TextureVisuals(uv=sor.uv.numpy(),
                                                                                          material=material),
                           process=False)


def test_obj_text_is_trimesh_s_bytes() -> None:
    mesh = _mesh()
    text, _ = trimesh.exchange.obj.export_obj(mesh, include_texture=True, return_texture=True, mtl_name=OBJ_MTL)
    assert obj_text(mesh.vertices, mesh.visual.uv, mesh.faces, "albedo") == text.encode("utf-8")


def test_obj_text_loads_back() -> None:
    mesh = _mesh()
    loaded = trimesh.load(io.BytesIO(obj_text(mesh.vertices, mesh.visual.uv, mesh.faces, "albedo")),
                          file_type="obj", process=False, force="mesh")
    assert loaded.vertices.shape == mesh.vertices.shape and np.array_equal(loaded.faces, mesh.faces)
    assert np.allclose(loaded.vertices, mesh.vertices, atol=1e-8)
