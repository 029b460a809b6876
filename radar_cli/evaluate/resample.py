"""A result's image-space maps brought to its ground truth's size, so results and truth of different resolutions
(a 512 px de-rendering of a 128 px synthetic image, a 64 px one of a 256 px image) are scored on the truth's grid.

The maps are resampled within the predicted frontal mask (normalised: sum(map * mask) / sum(mask) over each
target pixel's footprint), so the black drawn off the object never bleeds into the scored pixels; the mask itself
by its coverage, cut at one half. Area averaging shrinks, bilinear interpolation enlarges."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from radar_cli.errors import InputError
from radar_cli.evaluate.loading import Prediction

MAX_ASPECT_MISMATCH = 0.02  # both are square crops of the same window: a larger difference means misaligned maps


def _resize(x: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """H x W (x C) float -> h x w (x C), area down, bilinear up (per axis the larger factor decides)."""
    h, w = size
    shrink = x.shape[0] > h or x.shape[1] > w
    out = cv2.resize(x.astype(np.float64), (w, h), interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR)
    return out.reshape(h, w, *x.shape[2:])


def _masked_resize(x: np.ndarray, weight: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """H x W x C values averaged within H x W weights onto h x w (0 where no weight reaches)."""
    num = _resize(x * weight[..., None], size)
    den = _resize(weight, size)[..., None]
    return np.where(den > 1e-6, num / np.maximum(den, 1e-6), 0.0)


def resample_prediction(pred: Prediction, size: tuple[int, int], name: str = "result") -> Prediction:
    """The prediction's image-space maps at `size` (h, w); unchanged if they have it already.

    Args:
        pred: maps H x W (mask_front bool, albedo_rendered H x W x 3 in [0, 1], normal H x W x 3 in [-1, 1]).
        size: the ground truth's (h, w).
        name: the object, for messages.

    Returns:
        The Prediction on the h x w grid (normals renormalised to unit length where the mask reaches).

    Raises:
        InputError: the maps' aspect ratio differs from the truth's (not the same window).
    """
    if pred.mask_front.shape == tuple(size):
        return pred
    (ph, pw), (h, w) = pred.mask_front.shape, size
    if abs(ph / pw - h / w) > MAX_ASPECT_MISMATCH * (h / w):
        raise InputError(f"{name}: result maps are {ph} x {pw}, ground truth {h} x {w}: not the same window")
    weight = pred.mask_front.astype(np.float64)
    normal = _masked_resize(pred.normal, weight, size)
    length = np.linalg.norm(normal, axis=-1, keepdims=True)
    return dataclasses.replace(
        pred,
        mask_front=_resize(weight, size) > 0.5,
        albedo_rendered=np.clip(_masked_resize(pred.albedo_rendered, weight, size), 0.0, 1.0),
        normal=np.where(length > 1e-6, normal / np.maximum(length, 1e-6), 0.0),
    )
