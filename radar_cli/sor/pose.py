"""Object pose v = (pitch, roll, tx, ty): rotation and translation from the canonical object frame to the camera.

world = Rz(roll) Rx(-pitch) p + (tx * r_max, ty * r_max, distance). Positive pitch tips the vase's top towards
the camera, i.e. a camera looking down on the mouth (the paper's elevation, 0..20 deg).
"""

from __future__ import annotations

import math

import torch

from radar_cli.config import CameraConfig


def rotation_matrix(pose: torch.Tensor) -> torch.Tensor:
    """B x 4 pose -> B x 3 x 3 rotation taking canonical object coordinates to camera coordinates."""
    pitch = -pose[:, 0] * (math.pi / 180.0)
    roll = pose[:, 1] * (math.pi / 180.0)
    cp, sp, cr, sr = torch.cos(pitch), torch.sin(pitch), torch.cos(roll), torch.sin(roll)
    one, zero = torch.ones_like(cp), torch.zeros_like(cp)
    rx = torch.stack([one, zero, zero, zero, cp, -sp, zero, sp, cp], dim=-1).view(-1, 3, 3)
    rz = torch.stack([cr, -sr, zero, sr, cr, zero, zero, zero, one], dim=-1).view(-1, 3, 3)
    return rz @ rx


def translation(pose: torch.Tensor, camera: CameraConfig) -> torch.Tensor:
    """B x 4 pose -> B x 3 position of the object's centre in camera coordinates."""
    tz = torch.full_like(pose[:, 2], camera.distance)
    return torch.stack([pose[:, 2] * camera.r_max, pose[:, 3] * camera.r_max, tz], dim=-1)


def object_to_camera(points: torch.Tensor, pose: torch.Tensor, camera: CameraConfig) -> torch.Tensor:
    """Canonical points (B x ... x 3) -> camera coordinates (B x ... x 3)."""
    rot = rotation_matrix(pose)
    shape = points.shape
    flat = points.reshape(shape[0], -1, 3)  # B x N x 3
    out = flat @ rot.transpose(1, 2) + translation(pose, camera)[:, None, :]
    return out.reshape(shape)


def directions_to_camera(vectors: torch.Tensor, pose: torch.Tensor) -> torch.Tensor:
    """Canonical direction vectors (B x ... x 3) -> camera coordinates (rotation only)."""
    rot = rotation_matrix(pose)
    shape = vectors.shape
    return (vectors.reshape(shape[0], -1, 3) @ rot.transpose(1, 2)).reshape(shape)
