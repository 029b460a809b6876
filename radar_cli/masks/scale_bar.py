"""A black-and-white scale bar laid in front of or under a vessel's foot, found so that it is not taken for part
of the vessel.

Documentation photographs often show a scale: a bar of equal black and white segments (centimetres) on the floor
in front of the object. Apart from the object it is a neighbour like any other; touching or overlapping the foot,
its black segments join the located object, draw a band under the foot and pull the axis off (22 photographs of
../shared/data/cva10 and the Met with a bar over the foot: a level jug read at 13 deg and `ok`, right views sent to
`review`; docs/real-photos.md). A bar is found row by row in the lowest part of the object: at least
MIN_SEGMENTS alternating near-black and near-white segments of even length, on at least MIN_ROWS rows that share
their ends, with no more of the object below them than the bar's own height (its blurred lower edge). Painted
bands do not pass: their light parts are clay, slip or glaze, coloured or grey, and a black-and-white one on a
white ground has the vessel's foot below it (unless the foot is thinner than the band: then it is cut as a bar).
"""

from __future__ import annotations

import cv2
import numpy as np

DARK = 0.3
"""A black segment's luminance (0..1) is at most this ..."""
LIGHT = 0.75
"""... and a white one's at least this, ..."""
NEUTRAL = 40
"""... with its largest and smallest channel at most this many levels apart (white, not a light paint)."""
MIN_SEGMENTS = 6
"""A bar shows at least this many segments in a row (three black, three white) ..."""
MIN_SEGMENT_PX = 3
"""... each at least this long ..."""
EVEN = 0.25
"""... and all but the two end ones (a frame or the object may cut them) within this share of their median length
(or 1.5 px) of it."""
MIN_ROWS = 3
"""A bar spans at least this many rows whose runs share their ends (within OVERLAP of their length)."""
OVERLAP = 0.8
LOWEST = 0.3
"""Only a bar whose top lies in the object's lowest share of rows, or below it, counts."""
MARGIN = 0.3
"""The bar is cut off with this share of its height around it (its outline, anti-aliased edges), at least 2 px."""


def _runs(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run-length encoding of a 1-D label array: (starts, lengths, values)."""
    change = np.flatnonzero(np.diff(labels)) + 1
    starts = np.concatenate([[0], change])
    lengths = np.diff(np.concatenate([starts, [len(labels)]]))
    return starts, lengths, labels[starts]


def _row_bar(labels: np.ndarray) -> tuple[int, int] | None:
    """(first, last) column of the longest stretch of alternating black (1) and white (2) segments in one row of
    labels (0: neither), anti-aliased steps of one or two pixels between them allowed; None if none qualifies."""
    starts, lengths, values = _runs(labels)
    best: tuple[int, int] | None = None
    i, n = 0, len(values)
    while i < n:
        if values[i] == 0 or lengths[i] < MIN_SEGMENT_PX:
            i += 1
            continue
        chain = [i]
        j = i + 1
        while j < n:
            k = j + 1 if values[j] == 0 and lengths[j] <= 2 and j + 1 < n else j
            if values[k] in (1, 2) and values[k] != values[chain[-1]] and lengths[k] >= MIN_SEGMENT_PX:
                chain.append(k)
                j = k + 1
            else:
                break
        if len(chain) >= MIN_SEGMENTS:
            inner = lengths[chain[1:-1]].astype(np.float64)
            median = float(np.median(inner))
            if np.all(np.abs(inner - median) <= max(1.5, EVEN * median)):
                first, last = int(starts[chain[0]]), int(starts[chain[-1]] + lengths[chain[-1]] - 1)
                if best is None or last - first > best[1] - best[0]:
                    best = (first, last)
        i = chain[-1] + 1 if len(chain) > 1 else i + 1
    return best


def find_scale_bar(image: np.ndarray, mask: np.ndarray) -> np.ndarray | None:
    """The pixels of a black-and-white scale bar that the located object touches and ends with (its lowest rows).

    Args:
        image: n x n x 3 uint8, the window the object was located in. mask: n x n bool, the located object.

    Returns:
        n x n bool, the bar's rectangle with a margin (None: no bar found).
    """
    rows = np.flatnonzero(mask.any(1))
    if len(rows) < 10:
        return None
    top = int(rows[0] + (1.0 - LOWEST) * (rows[-1] - rows[0] + 1))
    pixels = image[top:].astype(np.int16)
    luma = cv2.cvtColor(np.ascontiguousarray(image[top:]), cv2.COLOR_RGB2GRAY) / 255.0
    white = (luma >= LIGHT) & (pixels.max(2) - pixels.min(2) <= NEUTRAL)
    labels = np.where(luma <= DARK, 1, np.where(white, 2, 0)).astype(np.int8)
    enough = MIN_SEGMENTS // 2 * MIN_SEGMENT_PX
    candidates = np.flatnonzero(((labels == 1).sum(1) >= enough) & ((labels == 2).sum(1) >= enough)
                                & ((np.diff(labels, axis=1) != 0).sum(1) >= MIN_SEGMENTS - 1))
    found = [(int(y), span) for y in candidates if (span := _row_bar(labels[y])) is not None]
    if len(found) < MIN_ROWS:
        return None
    groups: list[list[tuple[int, tuple[int, int]]]] = []
    for y, span in found:
        last = groups[-1][-1] if groups else None
        if last is not None and y - last[0] <= 2 and _overlap(span, last[1]) >= OVERLAP:
            groups[-1].append((y, span))
        else:
            groups.append([(y, span)])
    bars = [g for g in groups if len(g) >= MIN_ROWS]
    for group in sorted(bars, key=len, reverse=True):
        y0, y1 = top + group[0][0], top + group[-1][0]
        x0, x1 = int(np.median([s[0] for _, s in group])), int(np.median([s[1] for _, s in group]))
        pad = max(2, round(MARGIN * (y1 - y0 + 1)))
        bar = np.zeros(mask.shape, bool)
        bar[max(0, y0 - pad) : y1 + pad + 1, max(0, x0 - pad) : x1 + pad + 1] = True
        below = rows[-1] - y1  # the object's rows under the bar's: its own blurred edge, or a vessel's foot
        if (bar & mask).any() and below <= max(3, y1 - y0 + 1):
            return bar
    return None


def _overlap(a: tuple[int, int], b: tuple[int, int]) -> float:
    """The shared length of two column spans over the shorter one's."""
    shared = min(a[1], b[1]) - max(a[0], b[0]) + 1
    return max(0, shared) / max(1, min(a[1] - a[0], b[1] - b[0]) + 1)
