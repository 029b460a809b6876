"""The paper's error metrics on synthetic vases (Table 2), per sample, on numpy arrays.

Definitions follow the paper and its released scorer:
- pose: |pitch error| in degrees per sample (the per-sample RMSE of one number); mean +- std over samples;
- normal: mean angular deviation (deg) over the true mask AND the predicted frontal mask;
- albedo: scale-invariant MSE (Grosse et al. 2009) of image-space albedo over the same region: the one scalar
  a = <pred, gt> / <pred, pred> that best fits the prediction to the truth, then the MSE of a * pred - gt over
  the region's pixels and channels (values in [0, 1]); reported x 1e-2;
- shininess and specular albedo: |error| per sample;
- environment map: scale-invariant MSE over the front half (azimuth -90..90 deg: the middle half of the columns
  in radar's convention, see radar_cli.render.lighting.env_directions).
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from radar_cli.errors import InputError

EPS = 1e-12


def scale_invariant_mse(pred: np.ndarray, gt: np.ndarray, mask: np.ndarray | None = None) -> float:
    """min over a of the mean of (a * pred - gt)^2 over the masked pixels and all channels.

    Args:
        pred, gt: H x W (x C) arrays of the same shape.
        mask: H x W bool region, or None for every pixel.

    Returns:
        The error; a zero prediction gets a = 0, i.e. the mean of gt^2.
    """
    if pred.shape != gt.shape:
        raise InputError(f"prediction shape {pred.shape} does not match ground truth {gt.shape}")
    p, g = _region(pred, mask), _region(gt, mask)
    if p.size == 0:
        raise InputError("empty evaluation region")
    denom = float((p * p).sum())
    scale = float((p * g).sum()) / denom if denom > EPS else 0.0
    return float(((scale * p - g) ** 2).mean())


def angular_error_deg(pred: np.ndarray, gt: np.ndarray, mask: np.ndarray) -> float:
    """Mean angle (degrees) between normal maps (H x W x 3, any length; normalised here) over a mask."""
    if pred.shape != gt.shape:
        raise InputError(f"normal map shape {pred.shape} does not match ground truth {gt.shape}")
    p, g = _unit(_region(pred, mask)), _unit(_region(gt, mask))
    if p.shape[0] == 0:
        raise InputError("empty evaluation region")
    # atan2(|p x g|, p . g) is exact near 0 where arccos(p . g) loses half the digits
    angle = np.arctan2(np.linalg.norm(np.cross(p, g), axis=-1), (p * g).sum(-1))
    return float(np.degrees(angle).mean())


def abs_error(pred: float, gt: float) -> float:
    """|pred - gt|: the RMSE of a single number."""
    return abs(float(pred) - float(gt))


def front_half(env: np.ndarray) -> np.ndarray:
    """The columns of an He x We map with azimuth in [-90, 90] deg (towards the camera): the middle half."""
    width = env.shape[-1]
    return env[..., width // 4 : width - width // 4]


def env_error(pred: np.ndarray, gt: np.ndarray) -> float:
    """Scale-invariant MSE of the front halves; the prediction is resized (bilinear) to the truth's size first."""
    if pred.ndim != 2 or gt.ndim != 2:
        raise InputError(f"environment maps must be He x We, got {pred.shape} and {gt.shape}")
    if pred.shape != gt.shape:
        pred = cv2.resize(pred.astype(np.float32), (gt.shape[1], gt.shape[0]), interpolation=cv2.INTER_LINEAR)
    return scale_invariant_mse(front_half(pred).astype(np.float64), front_half(gt).astype(np.float64))


def decode_normals(image: np.ndarray) -> np.ndarray:
    """(n + 1) / 2 stored as uint8 RGB (H x W x 3) -> H x W x 3 float normals in [-1, 1] (not normalised)."""
    return image.astype(np.float64) / 255.0 * 2.0 - 1.0


def mean_std(values: list[float]) -> tuple[float, float]:
    """Mean and (population) standard deviation, as the paper reports them; NaN for no values."""
    if not values:
        return math.nan, math.nan
    arr = np.asarray(values, dtype=np.float64)
    return float(arr.mean()), float(arr.std())


def _region(x: np.ndarray, mask: np.ndarray | None) -> np.ndarray:
    """Pixels of x (H x W or H x W x C) inside mask, as N (x C) float64."""
    x = np.asarray(x, dtype=np.float64)
    if mask is None:
        return x.reshape(-1, *x.shape[2:]) if x.ndim > 2 else x.reshape(-1)
    if mask.shape != x.shape[:2]:
        raise InputError(f"mask shape {mask.shape} does not match map {x.shape[:2]}")
    return x[mask.astype(bool)]


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), EPS)
