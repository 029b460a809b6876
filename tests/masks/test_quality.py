"""The whole-object scores of masks.quality: how far a solid's outline is off a silhouette, how round a
silhouette is."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.quality import outline_residual, roundness


def _box(shift: int = 0) -> np.ndarray:
    mask = np.zeros((200, 200), bool)
    mask[40:160, 60 + shift:140 + shift] = True
    return mask


def test_outline_residual_is_the_ends_distance_over_the_height() -> None:
    assert outline_residual(_box(), _box()) == 0.0
    # shifted 6 px sideways: rows' ends off by 6, columns' ends (top and bottom) off only where one mask lacks them
    assert abs(outline_residual(_box(), _box(6)) - 6 * 240 / (240 + 2 * 74) / 120) < 0.02
    assert outline_residual(np.zeros((10, 10), bool), _box()) is None


def test_a_disc_is_round_and_a_vase_outline_is_not() -> None:
    disc = np.zeros((200, 200), np.uint8)
    cv2.ellipse(disc, (100, 100), (70, 55), 10, 0, 360, 1, -1)
    assert roundness(disc > 0) > 0.97
    assert roundness(_box()) < 0.85  # straight rim and foot: a side view
