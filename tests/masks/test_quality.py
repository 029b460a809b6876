"""The whole-object scores of masks.quality: how far a solid's outline is off a silhouette, how round a
silhouette is, how uneven its lower outline is."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.quality import foot_asymmetry, outline_residual, roundness


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


def _vase(foot: int = 30) -> np.ndarray:
    """A vessel's outline: a bellied body on a foot whose lower edge is a level ellipse arc (seen a little from
    above), `foot` px in half-width."""
    mask = np.zeros((200, 200), np.uint8)
    for y in range(30, 170):
        half = int(30 + 35 * np.sin(np.pi * (y - 30) / 150))
        mask[y, 100 - half:100 + half + 1] = 1
    cv2.rectangle(mask, (100 - foot, 160), (100 + foot, 170), 1, -1)
    cv2.ellipse(mask, (100, 170), (foot, 6), 0, 0, 180, 1, -1)
    return mask > 0


def test_a_foot_is_symmetric_even_where_the_solid_misses_it() -> None:
    assert foot_asymmetry(_vase(), _vase()) == 0.0
    assert foot_asymmetry(_vase(36), _vase(26)) < 0.005  # a solid drawing the foot too narrow, on both sides
    assert foot_asymmetry(np.zeros((10, 10), bool), _vase()) is None


def _broken(line: np.ndarray) -> float | None:
    """foot_asymmetry of the vessel's upper part above a break along `line` (a row per column), the solid
    following the unbroken part, cut level at the break's highest point."""
    rows = np.arange(200)[:, None]
    return foot_asymmetry(_vase() & (rows <= line[None]), _vase() & (rows <= line[30:170].min()))


def test_a_broken_lower_edge_is_not_a_foot() -> None:
    """A straight slanted break (a sherd's edge) and jagged ones (a random walk of 12 px, as
    experiments.status_cases draws them): a jagged break is caught where it is uneven enough, which a random walk
    is not always (0.023-0.054 on the five below: two stay under the limit of 0.03)."""
    cols = np.arange(200)
    assert _broken(100 + 0.3 * (cols - 100)) > 0.1
    jagged = []
    for seed in range(5):
        walk = np.cumsum(np.random.default_rng(seed).normal(0, 1, 200))
        walk -= np.interp(cols, [0, 199], [walk[0], walk[-1]])
        jagged.append(_broken(110 + 12 * walk / np.abs(walk).max()))
    assert min(jagged) > 0.02 and sum(v > 0.03 for v in jagged) >= 3, jagged
