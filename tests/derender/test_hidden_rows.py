"""Profile rows that no end of the outline depends on (a neck behind the rim and shoulder of a vase seen from above)
are drawn with the least bending instead of the ripples the width correction leaves there."""

from __future__ import annotations

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.fit_shape import outline_score
from radar_cli.derender.refine.hidden_rows import (
    HELD_WEAKLY,
    hidden_rows,
    interior,
    least_bending,
    row_hold,
    smooth_hidden,
)
from radar_cli.sor.outline import outline
from radar_cli.sor.solid import Solid

CAMERA = CameraConfig()


def _necked_vase(pitch: float, ripple: float = 0.0) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """(radius 1 x 64, height 1, pose 1 x 4): a wide rim over a narrow neck over a wide shoulder (row 0 is the
    foot); `ripple` cuts rings of that depth into the neck (rows 46-52, behind the rim at 25 deg)."""
    t = np.linspace(0.0, 1.0, 64)  # foot to rim
    radius = 0.42 - 0.2 * np.exp(-0.5 * ((t - 0.78) / 0.07) ** 2) + 0.2 * np.exp(-0.5 * ((t - 0.45) / 0.2) ** 2)
    rows = np.arange(64)
    radius = radius - ripple * (rows % 2) * ((rows >= 46) & (rows <= 52))
    return (torch.from_numpy(radius)[None], torch.tensor([0.75], dtype=torch.float64),
            torch.tensor([[pitch, 0.0, 0.0, 0.0]], dtype=torch.float64))


def test_least_bending_puts_free_rows_back_on_the_line_through_the_held_ones():
    line = np.linspace(0.2, 0.6, 20)
    rippled = line + 0.03 * np.sin(np.arange(20) * 2.0) * (np.arange(20) % 3 != 0)
    free = np.arange(20) % 3 != 0
    assert np.allclose(least_bending(rippled, free), line)


def test_only_interior_runs_are_freed():
    mask = np.array([True, True, False, True, True, False, True])
    assert interior(mask).tolist() == [False, False, False, True, True, False, False]


def test_a_neck_seen_from_above_is_hidden_and_smoothed_without_moving_the_outline():
    level = hidden_rows(*_necked_vase(0.0), 256, CAMERA)
    steep = hidden_rows(*_necked_vase(25.0), 256, CAMERA)
    assert interior(steep)[45:54].sum() >= 8, np.nonzero(steep)[0]  # the neck lies behind rim and shoulder
    assert not level.any(), np.nonzero(level)[0]
    radius, height, pose = _necked_vase(25.0, ripple=0.02)
    target = outline(Solid(radius, height, pose), 256, CAMERA)
    smooth = smooth_hidden(radius, height, pose, target, 256, CAMERA, outline_score)
    bend = lambda r: float((r[0, 42:55].diff(n=2) ** 2).sum())  # noqa: E731
    assert bend(smooth) < 0.2 * bend(radius), (bend(smooth), bend(radius))
    drawn = outline(Solid(smooth, height, pose), 256, CAMERA)
    assert float(outline_score(drawn, target, absolute=True)) < 0.05  # the outline is the same


def test_the_loosest_smoothing_that_keeps_the_outline_is_the_one_used():
    """Weakly held rows are smoothed with the hidden ones where the outline stays; else the hidden ones alone;
    else nothing (a score callable standing in for the outline's says which candidates keep it)."""
    radius, height, pose = _necked_vase(25.0, ripple=0.02)
    hold = row_hold(radius, height, pose, 256, CAMERA)
    loose, strict = (interior(hold <= share) for share in HELD_WEAKLY)
    assert loose.sum() > strict.sum() > 0
    profile = radius[0].numpy()

    def pick(verdicts: list[float]) -> np.ndarray:
        keep = lambda drawn, target: torch.tensor(verdicts, dtype=torch.float64)  # noqa: E731
        return smooth_hidden(radius, height, pose, None, 256, CAMERA, keep)[0].numpy()

    assert np.allclose(pick([0.0, 0.0, 0.0]), least_bending(profile, loose).clip(0.02, 1.0))
    assert np.allclose(pick([0.0, 1.0, 0.0]), least_bending(profile, strict).clip(0.02, 1.0))
    assert np.allclose(pick([0.0, 1.0, 1.0]), profile)
