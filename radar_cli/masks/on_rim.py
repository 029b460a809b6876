"""Cut off what stands on a located vessel's rim over its mouth: flowers and their stems, a bunch of twigs.

The vessel's central run (the row's object pixels joined to the axis column) widens and narrows smoothly down
the neck, shoulder and body; at the rim's top it ends. Stems rising from the mouth continue it with a run far
narrower than the rim (the stems themselves, or the backdrop between them that the cut filled in). From the
widest central run in the object's upper half, walking up, the first row whose run above is under RIM_STEP of
the widest of the few rows up to it is the rim's top; the parts above it that come over the middle of the mouth
(within half the rim's half-width of the axis) are cut off where they are sparse (stems and blossoms, under
SPARSE of their bounding box: a lid's knob or a head is compact), rise at least MIN_RISE of the object's height,
are not symmetric about the axis, and the vessel left is more of a solid of revolution (`neighbours.CUT_GAIN`).
A compact part (its largest piece fills COMPACT of its convex hull: a lid's head with a beak or a nose turned
aside, lopsided but smooth-edged) stays, whatever its symmetry: `appendages.above_rim` measures it.
Volutes and handles rising above the rim stand at its ends, not over the mouth, and stay.

A narrow neck under a wide lip, found in part (a glass neck as grey as the backdrop), ends its shoulder as a rim
would and is sparse in its box too, but it is its own mirror image about the axis (IoU 0.59-0.75 on the small
crops where it was cut), where stems and blossoms are not (at most 0.49): a part of SYMMETRIC or more stays. On
a colour photo a denser part (up to DENSE of its box: a bunch whose blossoms and leaves the cut filled in between)
is cut too where it is far from its own mirror image (under ASYMMETRIC; a lid's head or knob is its own mirror
image). On a greyscale photo the vessel's own rim, where parts of it are as grey as the backdrop, can come out
dense and lopsided above the rim's top found there, so only sparse parts are cut."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.neighbours import rounder
from radar_cli.masks.quality import mirror_iou, solidity
from radar_cli.masks.refine import main_component, row_extents

RIM_STEP = 0.5  # the run above the rim's top row is under this share of the rim's run ...
RIM_WINDOW = 0.01  # ... the widest run of this share of the object's height of rows up to it (at least one row)
SPARSE = 0.5  # what stands on the rim fills under this share of its bounding box (stems, not a knob)
MIN_RISE = 0.05  # ... and rises at least this share of the object's height above the rim
SYMMETRIC = 0.55  # ... and its IoU with its mirror image about the axis is under this (a neck and lip are over it)
DENSE = 0.75  # on a colour photo a denser part, up to this share of its box, is cut too ...
ASYMMETRIC = 0.3  # ... where its IoU with its mirror image is under this
COMPACT = 0.83  # a part whose largest piece fills this share of its convex hull or more is a lid's head or knob


def central_runs(mask: np.ndarray, axis: int) -> np.ndarray:
    """n: per row of an n x n bool mask, the length of its run of object pixels through column `axis` (0 where
    that pixel is backdrop)."""
    left = np.cumprod(mask[:, axis::-1], axis=1).sum(1)
    right = np.cumprod(mask[:, axis:], axis=1).sum(1)
    return np.where(mask[:, axis], left + right - 1, 0)


def rim_top(rows: np.ndarray, runs: np.ndarray) -> int | None:
    """The row of the rim's top where something continues the central run above it (None if nothing does): from
    the widest central run in the object's upper half, up to the first row whose run above is under RIM_STEP
    of the widest of the RIM_WINDOW of rows up to it (a rim's top edge may slope over a few rows into a bunch of
    stems as wide as half the mouth: compared with the row below alone, no step halves).

    Args:
        rows: the object's rows (sorted); runs: n central run lengths (`central_runs`).
    """
    top, bottom = int(rows[0]), int(rows[-1])
    upper = rows[rows <= top + 0.5 * (bottom - top)]
    start = int(upper[np.argmax(runs[upper])])
    window = max(1, round(RIM_WINDOW * (bottom - top)))
    for y in range(start, top, -1):
        if runs[y] == 0:
            return None
        if runs[y - 1] < RIM_STEP * runs[y : y + window].max():
            return y
    return None


def cut_on_rim(mask: np.ndarray, greyscale: bool = False) -> tuple[np.ndarray, bool]:
    """The located vessel (n x n bool) without what stands on its rim over the mouth (see the module); on a
    greyscale photo (`greyscale`) only sparse parts are cut.

    Returns:
        (mask, whether anything was cut off).
    """
    rows = np.nonzero(mask.any(1))[0]
    if len(rows) < 20:
        return mask, False
    top, bottom = int(rows[0]), int(rows[-1])
    cols = np.arange(mask.shape[1])
    left, right = row_extents(mask, rows[rows >= top + 0.5 * (bottom - top)])
    axis = float(np.median((left + right) / 2))  # the body's and foot's midpoints: what stands on top moves none
    runs = central_runs(mask, int(round(axis)))
    rim = rim_top(rows, runs)  # below the object's top row, so something stands above it
    if rim is None:
        return mask, False
    above = mask.copy()
    above[rim:] = False
    count, labels = cv2.connectedComponents(above.astype(np.uint8), connectivity=8)
    middle = np.abs(cols - axis) < 0.25 * runs[rim]  # over the middle of the mouth
    over = [i for i in range(1, count) if (labels[:, middle] == i).any()]
    if not over:
        return mask, False
    part = np.isin(labels, over)
    ys, xs = np.nonzero(part)
    fill = part.sum() / ((ys.max() - ys.min() + 1) * (xs.max() - xs.min() + 1))
    symmetry = mirror_iou(part, axis)
    sparse = fill < SPARSE or (not greyscale and fill < DENSE and symmetry < ASYMMETRIC)
    if not sparse or rim - ys.min() < MIN_RISE * (bottom - top + 1) or symmetry >= SYMMETRIC:
        return mask, False
    if solidity(main_component(part)) >= COMPACT:  # a head turned aside (a beak, a nose): lopsided, no bunch
        return mask, False
    cut = main_component(mask & ~part)
    return (cut, True) if rounder(cut, mask) else (mask, False)
