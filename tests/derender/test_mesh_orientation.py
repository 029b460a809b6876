"""Exported meshes face the viewer: the photographed side at +z (glTF's front), normals outward."""

import numpy as np
import torch

from radar_cli.config import CameraConfig, RenderConfig
from radar_cli.derender.export.mesh import build_mesh
from radar_cli.derender.run.state import ObjectState
from radar_cli.render.material import Material
from radar_cli.sor.solid import Solid


def _state() -> ObjectState:
    albedo = torch.zeros(1, 3, 8, 24)
    albedo[..., 8:16] = 1.0  # the frontal third (middle of the 360 deg map) is white, the rest black
    solid = Solid(torch.full((1, 32), 0.5), torch.tensor([0.8]), torch.zeros(1, 4))
    material = Material(albedo, torch.ones(1, 16, 48), torch.tensor([20.0]), torch.tensor([0.5]))
    return ObjectState(solid, material, RenderConfig(), CameraConfig())


def test_front_of_the_texture_faces_plus_z_and_normals_point_out():
    mesh = build_mesh(_state(), n_cols=48)
    uv = mesh.visual.uv
    side = np.arange(len(uv)) < len(uv) - 1  # all but the base centre
    front = side & (np.abs(uv[:, 0] - 0.5) < 1 / 6)  # middle third of the map = the photographed side
    assert mesh.vertices[front, 2].min() > 0 and mesh.vertices[side & ~front, 2].min() < 0
    centres, normals = mesh.triangles_center, mesh.face_normals
    lateral = np.abs(normals[:, 1]) < 0.5
    radial = centres[lateral] * np.array([1.0, 0.0, 1.0])
    assert ((normals[lateral] * radial).sum(1) > 0).mean() > 0.99
