"""Give back to a located vessel the light band its glaze shows along its flanks.

A glossy glaze seen at a grazing angle reflects what stands beside it: a black krater photographed on a light
sweep shows a grey band a few pixels wide along each flank, between the black body and the backdrop. On a darker
grey, close to that band's colour, both the backdrop model and GrabCut's colour models take the band for
backdrop, and the located outline runs along the black body's edge, inside the vessel's true outline (a tenth of
the IoU on a black krater on dark grey). Row by row, the pixels just outside the located outline that the
backdrop does not explain, up to where it explains them again, belong to the vessel when they hold a band
brighter than the backdrop, end within a short reach and do so over a run of rows. A shadow is darker than the
backdrop, a label or a neighbour does not end within the reach, noise does not run along the flank.
"""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.appendages import runs_of
from radar_cli.masks.detect import fit_backdrop
from radar_cli.masks.refine import row_extents

REACH = 0.1  # the band ends within this share of the object's width from its located outline ...
LIFT = 8.0  # ... in pixels brighter than the backdrop model by this many levels (grey mean, and 3 noise units)
EXPLAINED = 4.0  # pixels within this many levels (and 2 noise units) of the backdrop model are backdrop ...
CLEAR = 3  # ... and this many of them in a row end the band ...
ENDING = 3  # ... whose last this many pixels hold one LIFT over the backdrop and over those (a step, not a fade)
RUN = 0.05  # rows grown must run on for this share of the object's rows (a band along the flank)
RING = 0.04  # the backdrop is modelled on a ring this wide (share of the window) beyond the reach


def _reach(grey: np.ndarray, lift: np.ndarray, rows: np.ndarray, edge: np.ndarray, sign: int, reach: int,
           bright: float, explained: float) -> np.ndarray:
    """Per row, how many pixels outward (by `sign`) of its outline column `edge` the vessel goes on (0: none):
    the pixels the backdrop does not explain (`explained` levels) up to CLEAR it does, within `reach`, one of the
    last ENDING of them at least `bright` over the backdrop and over the CLEAR pixels after them.

    Args:
        grey: n x n float, the pixels' grey; lift: n x n float, their lift over the backdrop model.
        rows, edge: R int each.
    Returns:
        R int.
    """
    n = lift.shape[1]
    steps = np.arange(1, reach + CLEAR + 1)  # S
    cols = edge[:, None] + sign * steps[None, :]  # R x S
    inside = (cols >= 0) & (cols < n)
    values = lift[rows[:, None], cols.clip(0, n - 1)]
    seen = grey[rows[:, None], cols.clip(0, n - 1)]
    calm = (np.abs(values) <= explained) & inside  # R x S
    # the first step s that starts CLEAR calm pixels in a row: the band is steps 1 .. s - 1
    window = np.asarray(np.lib.stride_tricks.sliding_window_view(calm, CLEAR, axis=1).all(axis=2))  # R x (S-CLEAR+1)
    has_end = window.any(axis=1)
    end = np.where(has_end, window.argmax(axis=1), 0)  # band length in pixels
    # one of its last pixels bright, over the backdrop and in the photo: it ends in a step down to the backdrop, the
    # vessel's outline (a halo round an outline, or a backdrop lighter near the vessel, fades out instead; where the
    # model strays from a smooth backdrop, the photo shows no step)
    r = np.arange(len(rows))
    last = [(end - k).clip(0) for k in range(1, ENDING + 1)]
    lifted = np.max([values[r, i] for i in last], axis=0)
    after = np.mean([seen[r, (end + k).clip(0, len(steps) - 1)] for k in range(CLEAR)], axis=0)
    step = np.max([seen[r, i] for i in last], axis=0) - after
    return np.where(has_end & (end >= 1) & (end <= reach) & (lifted >= bright) & (step >= bright), end, 0)


def _steady(edge: np.ndarray, grow: np.ndarray, sign: int, run: int) -> np.ndarray:
    """R int growth kept only on runs of at least `run` grown rows, its new outline (R columns `edge` moved by
    `sign` x `grow`) then the running median over 5 rows, on those runs only (no staircase where neighbouring rows
    stop at different pixels)."""
    keep = runs_of(grow > 0, run)
    outline = (edge + sign * np.where(keep, grow, 0)).astype(np.float32).reshape(-1, 1)
    smooth = cv2.medianBlur(outline, 5).ravel()  # on one column: the median of 5 rows
    return np.where(keep, np.maximum(sign * (smooth - edge), 0), 0).astype(int)


def grow_sheen(mask: np.ndarray, image: np.ndarray, outside: np.ndarray | None = None) -> np.ndarray:
    """The located object with the light band along its flanks given back.

    Args:
        mask: n x n bool located object. image: n x n x 3 uint8, the pixels it was located in.
        outside: n x n bool, the padding beyond the photo's edge (never object), if any.

    Returns:
        n x n bool, `mask` grown row by row at its leftmost and rightmost columns.
    """
    rows = np.nonzero(mask.any(1))[0]
    cols = np.nonzero(mask.any(0))[0]
    if len(rows) < 10:
        return mask
    n = mask.shape[0]
    reach = max(3, int(round(REACH * (cols[-1] - cols[0] + 1))))
    square = np.ones((3, 3), np.uint8)
    near = cv2.dilate(mask.astype(np.uint8), square, iterations=reach) > 0
    far = cv2.dilate(mask.astype(np.uint8), square, iterations=reach + max(4, int(RING * n))) > 0
    ring = far & ~near if outside is None else far & ~near & ~outside
    if ring.sum() < 50:
        return mask
    pixels = image.astype(np.float32)
    model, noise = fit_backdrop(pixels, ring)
    grey = pixels.mean(2)
    lift = grey - model.mean(2)
    if outside is not None:
        lift[outside] = np.inf  # never calm, never a band's end: nothing grows into the padding
    spread = float(noise.mean())
    left, right = row_extents(mask, rows)
    run = max(3, int(round(RUN * len(rows))))
    grown = mask.copy()
    for edge, sign in ((right, 1), (left, -1)):
        grow = _steady(edge, _reach(grey, lift, rows, edge, sign, reach, max(LIFT, 3.0 * spread),
                                    max(EXPLAINED, 2.0 * spread)), sign, run)
        for y, x, g in zip(rows[grow > 0], edge[grow > 0], grow[grow > 0]):
            a, b = (x + 1, x + g + 1) if sign > 0 else (x - g, x)
            grown[y, a:b] = True
    return grown if outside is None else grown & ~outside
