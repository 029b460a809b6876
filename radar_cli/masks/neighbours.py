"""Part a located vessel from a neighbour that the cut merged into it (a second vessel standing behind or
beside it): the columns' extent over the lower part of the object rises a second time beyond the main vessel's
flank; the object is cut at the valley between the two humps and the main (larger) one is kept.

Handles and rims reach out above the body, not down to the floor: only the lower rows are read. Where no
valley parts them (a vessel behind overlapping the main one by much of its width), what lies off the main
vessel's symmetric core in the lowest rows (`base_off_axis`) says a neighbour was probably kept with it.
"""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.refine import main_component

LOWER = 0.55  # the column profile counts object pixels in this lower share of the object's rows
SECOND_PEAK = 0.3  # a second hump at least this fraction of the main one's height is a neighbour ...
VALLEY = 0.6  # ... when the profile between them drops below this fraction of the second hump
MIN_PART = 0.05  # ... and the part beyond the valley holds at least this share of the object
BASE = 0.4  # `base_off_axis` reads this lowest share of the object's rows


def _valley(profile: np.ndarray, start: int, step: int) -> int | None:
    """The column of the valley before a second hump, walking from the main peak at `start` by `step`."""
    peak = profile[start]
    low, low_at, i = peak, start, start + step
    while 0 <= i < len(profile):
        if profile[i] < low:
            low, low_at = profile[i], i
        elif profile[i] >= SECOND_PEAK * peak and low <= VALLEY * profile[i] and low_at != start:
            return low_at
        i += step
    return None


def split_neighbour(mask: np.ndarray) -> tuple[np.ndarray, bool]:
    """The main vessel of a located n x n bool mask with a merged neighbour cut off at the valley between them.

    Returns:
        (mask, whether a neighbour was cut off).
    """
    rows = np.nonzero(mask.any(1))[0]
    if len(rows) < 10:
        return mask, False
    lower = mask.copy()
    lower[: rows.min() + int((1 - LOWER) * (rows.max() - rows.min() + 1))] = False
    profile = cv2.GaussianBlur(lower.sum(0).astype(np.float32)[None], (0, 0), max(1.0, mask.shape[1] / 100))[0]
    start = int(np.argmax(profile))
    out, cut = mask.copy(), False
    for step in (-1, 1):
        at = _valley(profile, start, step)
        if at is None:
            continue
        beyond = np.zeros_like(mask)
        if step < 0:
            beyond[:, : at + 1] = True
        else:
            beyond[:, at:] = True
        if (mask & beyond).sum() >= MIN_PART * mask.sum():
            out &= ~beyond
            cut = True
    return (main_component(out), True) if cut else (mask, False)


def base_off_axis(whole: np.ndarray, core: np.ndarray) -> float:
    """Share of the located object's lowest BASE rows that lies off its symmetric core: near 0 for a vessel
    (its foot and body are symmetric, handles sit higher), large where a neighbour standing beside or behind
    it (or a card in front of its foot) was kept with it.

    Args:
        whole: n x n bool located object (core and appendages). core: n x n bool, its symmetric core.
    """
    rows = np.nonzero(whole.any(1))[0]
    if len(rows) < 2:
        return 0.0
    low = whole.copy()
    low[: rows.max() + 1 - int(BASE * (rows.max() - rows.min() + 1))] = False
    return float((low & ~core).sum() / max(int(low.sum()), 1))
