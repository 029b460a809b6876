"""Measurements of a vessel's profile (radius against height) as a catalogue gives them: the body, rim and foot
diameters over the height, and the landmarks a profile drawing is compared at (neck, shoulder, foot).

A profile here is a pair of arrays: heights t in [0, 1] from the foot's underside (0) to the rim's top (1), and
radii in any unit, the same for both profiles being compared once they are scaled by their height.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

RIM_SHARE = 0.05  # the rim is the widest point of the top 5% of the height
FOOT_SHARE = 0.08  # the foot is the widest point of the bottom 8%
BODY_SPAN = (0.12, 0.88)  # the body is the widest point between these heights (rim and foot left out)
NECK_SPAN = (0.55, 0.95)  # the neck is the narrowest point above the body's widest, within these heights
LANDMARK_HALF = 0.01  # a landmark's error is the mean over +- this share of the height round it


@dataclass(frozen=True)
class Ratios:
    """Diameters over the height, as the catalogue's columns give them."""

    body_height: float
    rim_body: float
    foot_body: float

    def as_tuple(self) -> tuple[float, float, float]:
        return self.body_height, self.rim_body, self.foot_body


def profile_from_material(radius: list[float], half_height: float) -> tuple[np.ndarray, np.ndarray]:
    """(t, radius) of a fitted solid: material.json's radius column (top to bottom, fractions of r_max) and
    half-height (r_max units); radii in half-height units' r_max, t from the bottom row (0) to the top (1)."""
    r = np.asarray(radius, np.float64)[::-1]
    if r.ndim != 1 or len(r) < 2 or not np.isfinite(r).all() or not half_height > 0:
        raise ValueError("radius must be a column of at least 2 finite values and height positive")
    return np.linspace(0.0, 1.0, len(r)), r / (2.0 * half_height)  # radius over the full height


def _widest(t: np.ndarray, r: np.ndarray, lo: float, hi: float) -> float:
    inside = (t >= lo) & (t <= hi)
    return float(r[inside].max()) if inside.any() else float(np.interp((lo + hi) / 2, t, r))


def ratios(t: np.ndarray, r: np.ndarray) -> Ratios:
    """The catalogue's ratios of a profile whose radii are in units of its height."""
    body = _widest(t, r, *BODY_SPAN)
    rim = _widest(t, r, 1.0 - RIM_SHARE, 1.0)
    foot = _widest(t, r, 0.0, FOOT_SHARE)
    return Ratios(2.0 * body, rim / body, foot / body)


def landmarks(t: np.ndarray, r: np.ndarray) -> dict[str, float]:
    """Heights (t) of a profile's neck (narrowest point above the body's widest, within NECK_SPAN), shoulder
    (half-way between the body's widest and the neck) and foot (widest point of the bottom FOOT_SHARE)."""
    body_t = t[(t >= BODY_SPAN[0]) & (t <= BODY_SPAN[1])]
    body_r = r[(t >= BODY_SPAN[0]) & (t <= BODY_SPAN[1])]
    widest = float(body_t[int(np.argmax(body_r))])
    upper = (t >= max(widest, NECK_SPAN[0])) & (t <= NECK_SPAN[1])
    neck = float(t[upper][int(np.argmin(r[upper]))]) if upper.any() else NECK_SPAN[1]
    low = t <= FOOT_SHARE
    foot = float(t[low][int(np.argmax(r[low]))])
    return {"neck": neck, "shoulder": (neck + widest) / 2.0, "foot": foot}


def profile_error(fitted: tuple[np.ndarray, np.ndarray], drawn: tuple[np.ndarray, np.ndarray]) -> dict[str, float]:
    """Radius error of a fitted profile against a drawn one, both in units of their own height, in % of the
    height: the mean and the worst over the drawing's heights, and the mean at its landmarks (+- LANDMARK_HALF).

    Args:
        fitted, drawn: (t, r) each, t increasing in [0, 1].

    Returns:
        {"mean", "worst", "neck", "shoulder", "foot"} in %.
    """
    t, r = drawn
    error = np.abs(np.interp(t, *fitted) - r) * 100.0
    out = {"mean": float(error.mean()), "worst": float(error.max())}
    for name, at in landmarks(t, r).items():
        near = np.abs(t - at) <= LANDMARK_HALF
        out[name] = float(error[near].mean()) if near.any() else float(np.interp(at, t, error))
    return out


def read_drawn_profile(text: str) -> tuple[np.ndarray, np.ndarray]:
    """(t, radius over height) of a digitised profile's CSV text (`height_cm,radius_cm`, a header line, height
    from the foot's underside up).

    Raises:
        ValueError: not two numeric columns, fewer than 10 rows, or heights not increasing.
    """
    lines = [line for line in text.strip().splitlines()[1:] if line.strip()]
    try:
        values = np.array([[float(v) for v in line.split(",")] for line in lines], np.float64)
    except ValueError as e:
        raise ValueError(f"not numbers ({e})") from None
    if values.ndim != 2 or values.shape[1] != 2 or len(values) < 10:
        raise ValueError("expected at least 10 rows of height_cm,radius_cm")
    h, r = values[:, 0], values[:, 1]
    if not (np.diff(h) > 0).all() or not np.isfinite(values).all():
        raise ValueError("heights must be finite and increasing")
    height = h[-1] - h[0]
    return (h - h[0]) / height, r / height
