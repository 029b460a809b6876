"""Spherical-Gaussian environment lighting (supplementary, "Lighting"), baked into the renderer's env map.

L(eta) = sum_k sqrt(lambda_k) F_k exp(-lambda_k (1 - eta . xi_k)), 3 lobes, xi_k uniform on the upper-front
quarter of the sphere (y >= 0 up, z <= 0 towards the camera), lambda ~ U(10, 30), F ~ U(0.1, 0.3). The map uses
the direction convention of radar_cli.render.lighting.env_directions (azimuth 0 = towards the camera, elevation
+ = up); each texel holds the solid-angle-weighted mean of L over the texel (supersampled), so narrow lobes keep
their energy on the coarse 16 x 48 grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from radar_cli.render.lighting import env_directions

N_LOBES = 3
SUPERSAMPLE = 4  # sub-samples per texel side when baking


@dataclass(frozen=True)
class Lobe:
    """One spherical Gaussian: unit direction xi (camera frame), sharpness lambda, intensity F."""

    direction: tuple[float, float, float]
    sharpness: float
    intensity: float

    def as_dict(self) -> dict[str, object]:
        return {"direction": list(self.direction), "lambda": self.sharpness, "F": self.intensity}


def sample_lobes(rng: np.random.Generator, n: int = N_LOBES) -> list[Lobe]:
    """`n` lobes from the upper-front quarter of the sphere."""
    lobes = []
    for _ in range(n):
        d = rng.normal(size=3)
        d /= max(float(np.linalg.norm(d)), 1e-12)
        d[1], d[2] = abs(d[1]), -abs(d[2])  # up, towards the camera
        lobes.append(Lobe((float(d[0]), float(d[1]), float(d[2])), float(rng.uniform(10.0, 30.0)),
                          float(rng.uniform(0.1, 0.3))))
    return lobes


def sg_radiance(lobes: list[Lobe], dirs: np.ndarray) -> np.ndarray:
    """L(eta) at unit directions dirs (N x 3) -> N."""
    out = np.zeros(dirs.shape[0], dtype=np.float64)
    for lobe in lobes:
        cos = dirs @ np.asarray(lobe.direction, dtype=np.float64)
        out += np.sqrt(lobe.sharpness) * lobe.intensity * np.exp(-lobe.sharpness * (1.0 - cos))
    return out


def bake_env(lobes: list[Lobe], height: int = 16, width: int = 48, supersample: int = SUPERSAMPLE) -> np.ndarray:
    """Bake lobes into an environment map.

    Returns:
        height x width float32 map (camera frame, linear, >= 0).
    """
    s = supersample
    dirs, solid = env_directions(height * s, width * s, dtype=torch.float64)
    radiance = sg_radiance(lobes, dirs.numpy()) * solid.numpy()  # energy per sub-texel
    energy = radiance.reshape(height, s, width, s).sum(axis=(1, 3))
    area = solid.numpy().reshape(height, s, width, s).sum(axis=(1, 3))
    return (energy / area).astype(np.float32)
