"""Profile rows the photograph does not show, drawn smooth (derender.refine.fit_shape; docs/refinement.md).

Seen from above, a vase's neck lies behind its rim and shoulder: no row or column of the silhouette ends on the
neck's discs, so the outline neither pulls nor holds those rows of the profile. The row-by-row width correction
and the polish, whose bending term charges a corner only once, leave them rippled, and the ripples show as rings
in the normals and every relit view; rows the outline holds only by a pixel of a limb ripple the same way. Here
each interior run of such rows is replaced by the least-bending curve through the rows around it, and kept only
if the outline stays as good.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.sor.outline import Outline, outline
from radar_cli.sor.solid import Solid

HELD_WEAKLY = (1e-2, 1e-9)
"""Rows whose outline gradient is at most this share of the profile's largest, loosest first: rows the outline
holds only weakly (a ring of the shoulder seen from above, its limb one pixel of the outline) and rows it does not
hold at all. The loosest set whose smoothing keeps the outline is used."""


def row_hold(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, size: int,
             camera: CameraConfig) -> np.ndarray:
    """L shares: how strongly the S x S outline's ends depend on each row of a 1 x L profile, against the row
    they depend on most (one backward pass of the ends weighted at random: a row some end depends on gets a
    non-zero gradient almost surely; 0: no end depends on it)."""
    r = radius.detach().clone().requires_grad_(True)
    drawn = outline(Solid(r, height, pose), size, camera)
    generator = torch.Generator().manual_seed(0)
    total = torch.stack([(torch.nan_to_num(t) * torch.randn(t.shape, generator=generator, dtype=t.dtype)).sum()
                         for t in (drawn.left, drawn.right, drawn.top, drawn.bottom)]).sum()
    (grad,) = torch.autograd.grad(total, r)
    return (grad[0].abs() / (float(grad.abs().max()) or 1.0)).numpy()


def hidden_rows(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, size: int,
                camera: CameraConfig) -> np.ndarray:
    """L bools: the rows of a 1 x L profile that no end of its S x S outline depends on."""
    return row_hold(radius, height, pose, size, camera) <= HELD_WEAKLY[-1]


def least_bending(profile: np.ndarray, free: np.ndarray) -> np.ndarray:
    """L radii: `profile` with its `free` rows (L bools) replaced by the values that minimise the sum of squared
    second differences, the other rows held."""
    rows = len(profile)
    bend = np.zeros((rows - 2, rows))
    idx = np.arange(rows - 2)
    bend[idx, idx], bend[idx, idx + 1], bend[idx, idx + 2] = 1.0, -2.0, 1.0
    held = ~free
    solved, *_ = np.linalg.lstsq(bend[:, free], -bend[:, held] @ profile[held], rcond=None)
    out = profile.copy()
    out[free] = solved
    return out


def interior(mask: np.ndarray) -> np.ndarray:
    """The True runs of an L bool mask that neither the first nor the last row belongs to."""
    out = mask.copy()
    for run in (range(len(mask)), range(len(mask) - 1, -1, -1)):
        for i in run:
            if not mask[i]:
                break
            out[i] = False
    return out


def smooth_hidden(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, target: Outline, size: int,
                  camera: CameraConfig, score: Callable[[Outline, Outline], torch.Tensor],
                  tolerance: float = 0.01) -> torch.Tensor:
    """The 1 x L profile with its interior weakly held or hidden rows (HELD_WEAKLY, loosest first) drawn with the
    least bending, the first such profile that keeps score(drawn outline, target) (a callable giving B scores,
    lower better) within `tolerance` of the profile's own (a smoothed row can come into view); else the profile."""
    hold = row_hold(radius, height, pose, size, camera)
    profile = radius[0].detach().numpy()
    frees: list[np.ndarray] = []
    for share in HELD_WEAKLY:
        free = interior(hold <= share)
        if free.any() and not any(np.array_equal(free, f) for f in frees):
            frees.append(free)
    smooth = [torch.from_numpy(least_bending(profile, free)).clamp(0.02, 1.0) for free in frees]
    if not smooth:
        return radius
    both = torch.cat([radius.detach(), torch.stack(smooth).to(radius.dtype)])  # (1 + C) x L
    drawn = outline(Solid(both, height.expand(len(both)), pose.expand(len(both), -1)), size, camera)
    scores = score(drawn, target)
    for k in range(1, len(both)):
        if float(scores[k]) <= float(scores[0]) + tolerance:
            return both[k : k + 1]
    return radius
