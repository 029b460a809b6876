"""Vase-like radius columns from two sine curves (supplementary, "SoR shapes"), heights and poses.

r_i = t + a1 (1 + sin((L - i)/L p1 + i/L q1)) + a2 (1 + sin(p2 + i/L q2)), i = 0..L-1, row 0 at the top,
with t ~ U(0.1, 0.3), a1 ~ U(0, 0.3), p1 ~ U(-pi, 0), q1 ~ U(pi/2, 2pi), a2 ~ U(0, 0.1), p2 ~ U(0, 2pi),
q2 ~ U(pi/2, 2pi). The formula reaches 1.1 while the model's radius range ends at 0.9, so a column whose maximum
exceeds the range is scaled down as a whole (its shape is kept), never clipped flat.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from radar_cli.config import CameraConfig, GeometryConfig

FRAME_FILL = 0.95  # the projected object spans at most this fraction of the half-view, so nothing is cut off


@dataclass(frozen=True)
class ShapeSample:
    """One sampled solid of revolution and its pose.

    Attributes:
        radius: L radius column, fractions of r_max, row 0 at the top.
        height: half-height, fraction of r_max.
        pose: (pitch deg, roll deg, tx, ty).
        curve: the sine-curve parameters t, a1, p1, q1, a2, p2, q2 and the applied scale.
    """

    radius: np.ndarray
    height: float
    pose: tuple[float, float, float, float]
    curve: dict[str, float]


def sine_radius(rng: np.random.Generator, n_rows: int = 32) -> tuple[np.ndarray, dict[str, float]]:
    """The supplementary's two-sine radius column (unscaled) and its parameters."""
    p = {
        "t": rng.uniform(0.1, 0.3),
        "a1": rng.uniform(0.0, 0.3), "p1": rng.uniform(-math.pi, 0.0), "q1": rng.uniform(math.pi / 2, 2 * math.pi),
        "a2": rng.uniform(0.0, 0.1), "p2": rng.uniform(0.0, 2 * math.pi), "q2": rng.uniform(math.pi / 2, 2 * math.pi),
    }
    i = np.arange(n_rows, dtype=np.float64)
    frac = i / n_rows
    f1 = p["a1"] * (1.0 + np.sin((1.0 - frac) * p["p1"] + frac * p["q1"]))
    f2 = p["a2"] * (1.0 + np.sin(p["p2"] + frac * p["q2"]))
    return p["t"] + f1 + f2, {k: float(v) for k, v in p.items()}


def fit_radius(radius: np.ndarray, lo: float, hi: float) -> tuple[np.ndarray, float]:
    """Scale a column down so that its maximum is at most `hi`, then clip to [lo, hi]; returns (column, scale)."""
    scale = min(1.0, hi / float(radius.max()))
    return np.clip(radius * scale, lo, hi), scale


def fit_frame(radius: np.ndarray, height: float, pitch_deg: float, camera: CameraConfig,
              min_height: float) -> tuple[np.ndarray, float, float]:
    """Shrink a tall, wide, tilted object uniformly until its projection fits the view with a margin.

    Bound on the projected half-extent (fractions of r_max): (h cos p + r_max sin p) magnified by perspective
    for the nearest point (distance - r_max_world).

    Returns:
        (radius, height, scale), scale <= 1.
    """
    p = math.radians(pitch_deg)
    r_big = float(radius.max())
    near = camera.distance / (camera.distance - r_big * camera.r_max)
    extent = max(height * math.cos(p) + r_big * math.sin(p), r_big) * near
    scale = min(1.0, FRAME_FILL / extent)
    scale = max(scale, min_height / height)  # keep the height in the model's range
    return radius * scale, height * scale, scale


def sample_shape(rng: np.random.Generator, geometry: GeometryConfig = GeometryConfig(),
                 camera: CameraConfig = CameraConfig(), random_roll: bool = False,
                 random_translation: bool = False) -> ShapeSample:
    """Sample radius column, height and pose: pitch ~ U(0, 20); roll, tx, ty 0 unless randomised in the
    geometry's ranges."""
    raw, curve = sine_radius(rng, geometry.n_rows)
    lo, hi = geometry.radius_range
    radius, curve["range_scale"] = fit_radius(raw, lo, hi)
    height = float(rng.uniform(*geometry.height_range))
    pitch = float(rng.uniform(0.0, 20.0))
    roll = float(rng.uniform(*geometry.roll_range)) if random_roll else 0.0
    tx, ty = (float(v) for v in rng.uniform(*geometry.trans_range, size=2)) if random_translation else (0.0, 0.0)
    radius, height, curve["frame_scale"] = fit_frame(radius, height, pitch, camera, geometry.height_range[0])
    radius = np.clip(radius, lo, hi)
    return ShapeSample(radius.astype(np.float32), float(height), (pitch, roll, tx, ty), curve)
