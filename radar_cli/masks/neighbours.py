"""Part a located vessel from a neighbour that the cut merged into it (a second vessel standing behind or
beside it).

Behind it (`cut_behind`, tried first): the vessel in front hides part of the one behind, which stands higher;
the neighbour widens one side of the object over a span of rows with the vessel's own outline above and below
(its neck or rim, its foot), and that side is cut back to the mirror of the other. Beside it
(`split_neighbour`): the columns' extent over the lower part of the object rises a second time beyond the main
vessel's flank; the object is cut at the valley between the two humps and the main (larger) one is kept, if it
is the more symmetric for it. Cut by the photo's side edge (`cut_at_frame`): a neighbour that reaches the frame
joins the vessel down to the floor with no valley; the part past the mirror image of the other side that meets
the frame in a straight line is cut off. Every cut must make the vessel left more of a solid of revolution.

Handles and rims reach out above the body, not down to the floor: only the lower rows are read. Where no
valley parts them (a vessel behind overlapping the main one by much of its width), what lies off the main
vessel's symmetric core in the lowest rows (`base_off_axis`) says a neighbour was probably kept with it."""

from __future__ import annotations

from typing import NamedTuple

import cv2
import numpy as np

from radar_cli.masks.quality import sor_score
from radar_cli.masks.refine import main_component, row_extents

LOWER = 0.55  # the column profile counts object pixels in this lower share of the object's rows
SECOND_PEAK = 0.3  # a second hump at least this fraction of the main one's height is a neighbour ...
VALLEY = 0.6  # ... when the profile between them drops below this fraction of the second hump
MIN_PART = 0.05  # ... and the part beyond the valley holds at least this share of the object
CUT_GAIN = 0.02  # every cut here must raise the solid-of-revolution score (`quality.sor_score`) by this much
BASE = 0.4  # `base_off_axis` reads this lowest share of the object's rows
BASE_MERGED = 0.1  # more of those rows than this off the symmetric core: something probably merged at the base
BASE_CUT_MAX = 0.25  # `cut_base` cuts at most this share of the object
BASE_PART_TOP = 0.5  # `cut_base` cuts only parts starting this share of the object's height below its top, or lower


def rounder(cut: np.ndarray, whole: np.ndarray) -> bool:
    """Whether cutting `whole` (n x n bool) down to `cut` leaves more of a solid of revolution (CUT_GAIN)."""
    return sor_score(cut) >= sor_score(whole) + CUT_GAIN


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
    """The main vessel of a located n x n bool mask with a merged neighbour cut off at the valley between them
    (of the parts between and beyond the valleys, the one with the most pixels is kept), if the vessel kept is the
    more symmetric for it (a light figure painted on a low-contrast body can carve a valley into the vessel itself;
    its half alone is far less a solid of revolution than the whole).

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
    middle, parts = mask.copy(), []
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
            middle &= ~beyond
            parts.append(mask & beyond)
    if not parts:
        return mask, False
    # the hump the profile peaks in may be a taller but narrower neighbour (an albarello beside a krater)
    kept = main_component(max([middle, *parts], key=lambda part: int(part.sum())))
    return (kept, True) if rounder(kept, mask) else (mask, False)


def _base_start(whole: np.ndarray) -> int | None:
    """The first of the object's lowest BASE rows (None for an object under two rows tall)."""
    rows = np.nonzero(whole.any(1))[0]
    return None if len(rows) < 2 else int(rows.max() + 1 - int(BASE * (rows.max() - rows.min() + 1)))


def base_off_axis(whole: np.ndarray, core: np.ndarray) -> float:
    """Share of the located object's lowest BASE rows that lies off its symmetric core: near 0 for a vessel
    (its foot and body are symmetric, handles sit higher), large where a neighbour standing beside or behind
    it (or a card in front of its foot) was kept with it.

    Args:
        whole: n x n bool located object (core and appendages). core: n x n bool, its symmetric core.
    """
    start = _base_start(whole)
    if start is None:
        return 0.0
    low = whole.copy()
    low[:start] = False
    return float((low & ~core).sum() / max(int(low.sum()), 1))


def cut_base(whole: np.ndarray, core: np.ndarray) -> tuple[np.ndarray, bool]:
    """The located object with what stands in front of or beside its foot cut off: where more of its lowest rows
    than BASE_MERGED lie off its symmetric core (`base_off_axis`), the connected parts off the core that reach
    into those rows (a card or label in front of the foot, a neighbour beside it) are cut, if they are a small
    part of the object (BASE_CUT_MAX) and the vessel left is more of a solid of revolution (CUT_GAIN). A
    vessel's own foot is symmetric and its handles sit higher. A part that rises into the object's upper half
    (BASE_PART_TOP) stays: what stands before the foot rises from the floor, while a strip down the vessel's
    own flank is off the core where the core came out narrow (a flank or handle lost on the other side, on a
    low-contrast greyscale plate) or the outline is uneven.

    Args:
        whole: n x n bool located object; core: n x n bool, its symmetric core (inside `whole`).
    Returns:
        (object, whether anything was cut off).
    """
    start = _base_start(whole)
    if start is None or base_off_axis(whole, core) <= BASE_MERGED:
        return whole, False
    _, labels, stats, _ = cv2.connectedComponentsWithStats((whole & ~core).astype(np.uint8), connectivity=8)
    rows = np.nonzero(whole.any(1))[0]
    highest = rows[0] + BASE_PART_TOP * (rows[-1] - rows[0] + 1)  # the highest row a part cut may start at
    low = np.unique(labels[start:])
    parts = np.isin(labels, low[(low > 0) & (stats[low, cv2.CC_STAT_TOP] >= highest)])
    cut = whole & ~parts
    if not parts.any() or parts.sum() > BASE_CUT_MAX * whole.sum() or not rounder(cut, whole):
        return whole, False
    return cut, True


BEHIND_TOLERANCE = 0.03  # a row's midpoint within this fraction of the object's width of the axis is clean
BEHIND_VIOLATE = 0.05  # the clean side may stick out past the mirrored other side on this share of the rows
BEHIND_SPAN = 0.2  # a neighbour behind spans at least this share of the object's rows ...
BEHIND_LOW = 0.6  # ... reaching below this share of the height from the top ...
BEHIND_WIDE = 0.12  # ... sticks out past the mirror of the other side by this fraction of the width (median)
BEHIND_END = 0.015  # ... with at least this share of the rows clean above it and below it (at least 3 rows) ...
BEHIND_CLEAN = (0.3, 0.4)  # ... and at least these shares of the rows above it and below it clean ...
BEHIND_FILL = 0.75  # ... and fills this share of its rows' span (a handle's loop does not) ...
BEHIND_MAX = 0.4  # ... but holds at most this share of the object (the vessel in front hides much of it)


def _behind_axis(mid: np.ndarray, side: int, tol: float) -> float:
    """The axis x under the hypothesis that a neighbour widens only `side` (+1 right, -1 left): the rows'
    midpoints lie on the axis or beyond it on that side, so the axis is at most (at least) their low (high)
    quantile; among those, the x holding the most midpoints within `tol`."""
    bound = np.quantile(side * mid, BEHIND_VIOLATE) + tol
    candidates = np.unique(np.round(side * mid[side * mid <= bound] * 2) / 2)
    counts = [int((np.abs(side * mid - c) <= tol).sum()) for c in candidates]
    return float(side * candidates[int(np.argmax(counts))])


class _Rows(NamedTuple):
    """The object's rows and, per row, its outermost columns (R = the rows holding object pixels)."""

    rows: np.ndarray  # R
    left: np.ndarray  # R, float64
    right: np.ndarray  # R, float64
    tol: float  # BEHIND_TOLERANCE of the object's width, in pixels (at least 1.5)


def _rows(mask: np.ndarray) -> _Rows:
    """The rows and outermost columns of an n x n bool mask with object pixels."""
    rows = np.nonzero(mask.any(1))[0]
    left, right = (e.astype(np.float64) for e in row_extents(mask, rows))
    return _Rows(rows, left, right, max(1.5, BEHIND_TOLERANCE * (right.max() - left.min() + 1)))


def _past_mirror(mask: np.ndarray, r: _Rows, side: int) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """The largest n x n bool part of `mask` past the mirror image of the other side (None if none) under the
    hypothesis that only `side` (+1 right, -1 left) is widened, the R bool rows whose midpoint lies on the axis
    (clean) and the R mirror columns (with the tolerance)."""
    mid = (r.left + r.right) / 2
    axis = _behind_axis(mid, side, r.tol)
    other = r.left if side > 0 else r.right
    clip = 2 * axis - other + side * r.tol  # per row: the mirror of the other side, with the tolerance
    clean = np.abs(mid - axis) <= r.tol
    cols = np.arange(mask.shape[1])
    beyond = np.zeros_like(mask)
    beyond[r.rows] = mask[r.rows] & (side * (cols[None, :] - clip[:, None]) > 0)
    k = np.ones((2 * int(r.tol) + 1,) * 2, np.uint8)  # thin parts (a rim's or handle's end) are the vessel's own
    beyond = cv2.morphologyEx(beyond.astype(np.uint8), cv2.MORPH_OPEN, k) > 0
    count, labels, stats, _ = cv2.connectedComponentsWithStats(beyond.astype(np.uint8), connectivity=8)
    if count <= 1:
        return None, clean, clip
    return labels == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA])), clean, clip


def _behind_part(mask: np.ndarray, r: _Rows, side: int) -> np.ndarray | None:
    """The n x n bool part of `mask` that a neighbour behind it on `side` adds, or None if none does (see
    `cut_behind`)."""
    part, clean, clip = _past_mirror(mask, r, side)
    if part is None:
        return None
    height, width = len(r.rows), r.right.max() - r.left.min() + 1
    outer = r.right if side > 0 else r.left
    held = np.nonzero(part[r.rows].any(1))[0]
    top, bottom = int(held.min()), int(held.max())
    end = max(3, int(round(BEHIND_END * height)))
    spans = side * (outer[top : bottom + 1] - clip[top : bottom + 1])
    if (bottom - top + 1 < BEHIND_SPAN * height or bottom < BEHIND_LOW * height
            or clean[:top].sum() < max(end, BEHIND_CLEAN[0] * top)
            or clean[bottom + 1 :].sum() < max(end, BEHIND_CLEAN[1] * (height - bottom - 1))
            or np.median(spans) < BEHIND_WIDE * width
            or not MIN_PART * mask.sum() <= part.sum() <= BEHIND_MAX * mask.sum()
            or part.sum() < BEHIND_FILL * np.maximum(spans, 0).sum()):
        return None
    return part


def cut_behind(mask: np.ndarray) -> tuple[np.ndarray, bool]:
    """The main vessel of a located n x n bool mask with a neighbour standing behind it cut off.

    A neighbour behind the vessel is partly hidden by it and stands higher: it widens one side of the object
    over a span of rows with the vessel's own outline above and below it (its foot; its neck or rim). Per side,
    the vessel's axis is where those clean rows' midpoints gather (the other rows' lie beyond it on that side);
    the neighbour is the largest part of the object past the mirror of the other side, and it is cut off where
    it spans many rows down into the lower part, is solid and sticks out well, and the vessel left is more of a
    solid of revolution than before (`CUT_GAIN`; a tilted vessel's flank passes the rest).

    Returns:
        (mask, whether a neighbour was cut off).
    """
    if mask.any(1).sum() < 20:
        return mask, False
    r = _rows(mask)
    parts = [p for p in (_behind_part(mask, r, side) for side in (1, -1)) if p is not None]
    if not parts:
        return mask, False
    cut = main_component(mask & ~max(parts, key=lambda p: int(p.sum())))
    if not rounder(cut, mask):  # a tilted vessel's own flank, not a neighbour's
        return mask, False
    return cut, True


FRAME_SPAN = 0.15  # a neighbour cut by the photo's side edge meets that edge on this share of the object's rows ...
FRAME_CLEAN = 0.1  # ... and on at least this share of the rows it does not reach the vessel is clean
FRAME_BOTH = 0.2  # ... unless the other side meets the other edge on more than this share of those rows


def _meets_frame(part: np.ndarray, outside: np.ndarray, side: int) -> np.ndarray:
    """n bool: the rows where `part` (n x n bool) reaches the photo's edge on `side` (the window's border or the
    padding beyond the photo, `outside`)."""
    edge = np.zeros_like(part)
    if side > 0:
        edge[:, -1] = True
        edge[:, :-1] |= outside[:, 1:]
    else:
        edge[:, 0] = True
        edge[:, 1:] |= outside[:, :-1]
    return (part & edge).any(1)


def cut_at_frame(mask: np.ndarray, outside: np.ndarray) -> tuple[np.ndarray, bool]:
    """The main vessel of a located n x n bool mask with a neighbour that the photo's side edge cuts off removed.

    A vessel beside or behind the main one, cut by the frame, ends at the photo's edge in a straight line and
    leaves no valley to part them (`split_neighbour`) nor, when it reaches the floor, the vessel's foot clean
    below it (`cut_behind`). Per side, the largest part of the object past the mirror image of the other side
    (about the axis the clean rows give) is cut off where it meets the photo's edge on FRAME_SPAN of the
    object's rows, holds MIN_PART-BEHIND_MAX of it, leaves FRAME_CLEAN of the rows clean, and the vessel left is
    more of a solid of revolution (`CUT_GAIN`). A vessel that the frame cuts is narrower on that side than its
    mirror image, not wider; where the object's other side meets the other edge on more than FRAME_BOTH of the
    rows the part meets its edge on, the frame cuts the vessel itself at both sides (a tight crop of a wide jar,
    its flank ragged where it meets the edge): neither side's outline is seen there, so no mirror image tells a
    neighbour from the vessel's flank.

    Args:
        mask: n x n bool located object. outside: n x n bool, the window's padding beyond the photo.
    Returns:
        (mask, whether a neighbour was cut off).
    """
    if mask.any(1).sum() < 20:
        return mask, False
    r = _rows(mask)
    height, area, best = len(r.rows), int(mask.sum()), None
    for side in (1, -1):
        part, clean, _ = _past_mirror(mask, r, side)
        if part is None:
            continue
        held = part[r.rows].any(1)
        meets = _meets_frame(part, outside, side)
        if (meets.sum() >= FRAME_SPAN * height
                and _meets_frame(mask, outside, -side)[meets].mean() <= FRAME_BOTH
                and MIN_PART * area <= part.sum() <= BEHIND_MAX * area
                and clean[~held].sum() >= FRAME_CLEAN * height
                and (best is None or part.sum() > best.sum())):
            best = part
    if best is None:
        return mask, False
    cut = main_component(mask & ~best)
    return (cut, True) if rounder(cut, mask) else (mask, False)
