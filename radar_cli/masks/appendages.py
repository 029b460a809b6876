"""The symmetric core of a vessel's silhouette: the part a profile about its axis explains. Handles, spouts,
knobs and other appendages are what is left over.

Each row of a solid of revolution seen from the side is one interval centred on the projected axis. Per row,
the core keeps the run of object pixels that holds the axis (the loop of a handle, seen beside the body, is
another run), clipped to the shorter of its two half-widths (a spout sticks out on one side only) and to the
row's radius after a vertical opening of the radius profile (a handle's attachment widens a few rows on both
sides; the body's own curve is smooth over that span). A narrow part standing on the rim (a volute or a
handle's top seen face on, above the mouth) is an appendage too, though it reaches the top. So are handle
plates: where a handle rises on each side, apart from the body, into the top rows (a column-krater seen from
the front), those rows are bounded by the handles' outer edges just under them; the plates beyond are the
handles' own. Handles that go on above the rim on both sides (a volute-krater's) pass outside it: the top rows
are bounded by their inner edges.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from radar_cli.masks.quality import SCORE_SIDE, TILTS_DEG, mirror_agreement, sor_score
from radar_cli.masks.refine import main_component, row_extents

SIDE_TOLERANCE = 0.03  # a half-width may exceed the other by this fraction of the object's width (perspective)
BUMP_SPAN = 0.1  # bumps of the radius profile shorter than this fraction of the height are appendages
NEAR_AXIS = 0.05  # a row whose runs all miss the axis keeps the nearest one within this fraction of the width
END_ROWS = 0.04  # ... unless they reach this close (fraction of the height) to the top or bottom: a rim, a foot
MIN_APPENDAGE = 0.004  # appendage parts smaller than this fraction of the silhouette are outline noise
SPIKE_WIDTH = 0.6  # rows above the rim narrower than this fraction of the rim's radius stand on it (a handle)
SPIKE_SPAN = 0.2  # ... where the rim is the widest row within this fraction of the height from the top
SHELF = 0.25  # ... and the rim widens from them in one row by at least this fraction of its radius
PLATE_BELOW = (0.02, 0.06)  # a handle's outer edge is read this far under its top (fractions of the height)
FINE_SIDE = 256  # the axis' tilt is refined on the mask at this side ...
FINE_STEPS = ((1.0, 3), (0.25, 3))  # ... in these steps (deg), this many each side of the best so far


@dataclass(frozen=True)
class Core:
    """A silhouette split into its symmetric core and its appendages.

    Attributes:
        core: H x W bool, the solid of revolution's silhouette.
        appendages: H x W bool, the rest of the silhouette (handles, spouts, knobs).
        tilt: the axis' tilt from vertical in degrees (positive: counter-clockwise in the image).
        axis: the axis' x in the upright (untilted) frame, in pixels.
        symmetry: solid-of-revolution score of the core (`quality.sor_score`), in [0, 1].
    """

    core: np.ndarray
    appendages: np.ndarray
    tilt: float
    axis: float
    symmetry: float

    @property
    def appendage_fraction(self) -> float:
        """Share of the whole silhouette that is appendage."""
        total = int(self.core.sum()) + int(self.appendages.sum())
        return float(self.appendages.sum() / total) if total else 0.0


def upright_rotation(mask: np.ndarray, deg: float) -> np.ndarray:
    """2 x 3 affine rotating a mask by `deg` about its centroid."""
    ys, xs = np.nonzero(mask)
    return cv2.getRotationMatrix2D((float(xs.mean()), float(ys.mean())), deg, 1.0)


def turn_mask(mask: np.ndarray, affine: np.ndarray) -> np.ndarray:
    """A bool mask moved by a 2 x 3 affine (bilinear, thresholded at one half), its size kept."""
    h, w = mask.shape
    out = cv2.warpAffine(mask.astype(np.float32), affine, (w, h), flags=cv2.INTER_LINEAR)
    return out > 0.5


def find_axis(mask: np.ndarray) -> tuple[float, float]:
    """The tilt (deg, over `quality.TILTS_DEG`) and x (pixels, in the mask rotated upright by that tilt about
    its centroid) of the vertical mirror axis that best explains a bool mask."""
    small = _scaled(mask, SCORE_SIDE)
    best, best_tilt = -1.0, 0.0
    for deg in TILTS_DEG:
        score = _upright_agreement(small, deg)
        if score > best:
            best, best_tilt = score, deg
    upright = turn_mask(mask, upright_rotation(mask, best_tilt)) if best_tilt else mask
    _, axis = mirror_agreement(upright)
    return best_tilt, axis


def fine_tilt(mask: np.ndarray, around: float) -> tuple[float, float, float]:
    """The tilt (deg) of the vertical mirror axis that best explains a bool mask, refined from `around` (the
    coarse tilt of `find_axis`) to FINE_STEPS' last step; and the mask's mirror agreement (IoU with its mirror
    image, `quality.mirror_agreement`) turned upright by that tilt and as it stands."""
    small = _scaled(mask, FINE_SIDE)
    if not small.any():
        return around, 0.0, 0.0
    scores: dict[float, float] = {}
    best = around
    for step, count in FINE_STEPS:
        for deg in (round(best + i * step, 4) for i in range(-count, count + 1)):
            if deg not in scores:
                scores[deg] = _upright_agreement(small, deg)
        best = max(scores, key=lambda d: (scores[d], -abs(d)))
    return best, scores[best], scores[0.0] if 0.0 in scores else _upright_agreement(small, 0.0)


def _scaled(mask: np.ndarray, side: int) -> np.ndarray:
    """A bool mask resized (by area) so that its long side is `side`."""
    k = side / max(mask.shape)
    return cv2.resize(mask.astype(np.uint8), None, fx=k, fy=k, interpolation=cv2.INTER_AREA) > 0


def _upright_agreement(mask: np.ndarray, deg: float) -> float:
    """`quality.mirror_agreement` of a bool mask turned by `deg` about its centroid."""
    return mirror_agreement(turn_mask(mask, upright_rotation(mask, deg)) if deg else mask)[0]


def _axis_runs(mask: np.ndarray, axis: float) -> tuple[np.ndarray, np.ndarray]:
    """Per row, the half-widths (left, right; NaN where none) of the run of object pixels holding the axis, or
    of the nearest run within `NEAR_AXIS` of the object's width."""
    h, w = mask.shape
    cols = np.nonzero(mask.any(0))[0]
    near = NEAR_AXIS * (cols.max() - cols.min() + 1)
    left, right = np.full(h, np.nan), np.full(h, np.nan)
    padded = np.zeros((h, w + 2), np.int8)
    padded[:, 1:-1] = mask
    steps = np.diff(padded, axis=1)
    for y in np.nonzero(mask.any(1))[0]:
        starts, ends = np.nonzero(steps[y] == 1)[0], np.nonzero(steps[y] == -1)[0]  # run [start, end)
        centre = axis + 0.5
        gap = np.maximum(starts - centre, 0) + np.maximum(centre - ends, 0)
        i = int(np.argmin(gap))
        if gap[i] <= near:
            left[y], right[y] = centre - starts[i], ends[i] - centre
    return left, right


def _top_spike(radius: np.ndarray, rows: np.ndarray) -> int:
    """How many rows at the top stand on the rim: the rows above it narrower than SPIKE_WIDTH x its radius (the
    widest row within SPIKE_SPAN of the top), if they span at least END_ROWS of the height and the rim widens from
    them in one row by SHELF of its radius (module docstring); 0 if none."""
    height = rows.max() - rows.min() + 1
    top, span = int(rows.min()), max(1, int(round(SPIKE_SPAN * height)))
    window = np.nan_to_num(radius[top : top + span], nan=0.0)
    spike = int(np.argmax(window >= SPIKE_WIDTH * window.max()))
    # shorter: the rim's own rounded top; no shelf (the width grows gradually): a domed top, the solid's own
    if spike >= END_ROWS * height and window[spike] - window[spike - 1] >= SHELF * window.max():
        return spike
    return 0


def _outer_extents(mask: np.ndarray, axis: float) -> tuple[np.ndarray, np.ndarray]:
    """Per row, the distance from the axis to the outermost object pixel's far edge on the left and on the right
    (NaN where that side has none)."""
    h, w = mask.shape
    xs = np.arange(w) + 0.5 - (axis + 0.5)
    left = np.where(mask & (xs < 0), -xs + 0.5, -np.inf).max(1)
    right = np.where(mask & (xs >= 0), xs + 0.5, -np.inf).max(1)
    return np.where(np.isfinite(left), left, np.nan), np.where(np.isfinite(right), right, np.nan)


def runs_of(flags: np.ndarray, length: int) -> np.ndarray:
    """`flags` (bool, n) kept only in runs of at least `length` consecutive True."""
    padded = np.concatenate([[0], flags.astype(np.int8), [0]])
    starts, ends = np.nonzero(np.diff(padded) == 1)[0], np.nonzero(np.diff(padded) == -1)[0]
    out = np.zeros_like(flags, dtype=bool)
    for a, b in zip(starts, ends):
        out[a:b] = b - a >= length
    return out


def _handle_plates(mask: np.ndarray, axis: float, left: np.ndarray, right: np.ndarray, limit: np.ndarray,
                   rows: np.ndarray, tol: float) -> np.ndarray:
    """`limit` bounded, over the top rows that a handle on each side rises into from below, by the mean of the
    two handles' outer edges just under them (`PLATE_BELOW`): the plates the handles carry reach past the rim.
    Where the object stands above those rows on both sides (volutes), by the handles' inner edges instead.

    A side stands apart from the core where its outermost pixel lies past what the core keeps there by more than
    `tol` (two plates a little unequal are no handle). The rows down to the later of the two handles are the
    plates' on both sides, and both handles are read from there: a sliver of backdrop under one plate, which a
    rescaled or mirrored photo may show or not, moves where one handle starts by a few rows, and the handles'
    outer edges slope fast just under the plates.

    Args:
        mask: H x W bool upright silhouette. axis: its axis' x. left, right: H, the axis runs' half-widths
            (`_axis_runs`). limit: H, the per-row half-width bound. rows: the rows holding an axis run.
        tol: the half-widths' tolerance in pixels (`SIDE_TOLERANCE` of the object's width).
    """
    out = limit.copy()
    height = rows.max() - rows.min() + 1
    outer_l, outer_r = _outer_extents(mask, axis)
    window = np.arange(rows.min(), min(mask.shape[0], rows.min() + int(round(SPIKE_SPAN * height))))
    run = max(2, int(round(PLATE_BELOW[1] * height)))  # a handle: longer than a ragged or lopsided plate
    kept_l, kept_r = np.fmin(left, limit), np.fmin(right, limit)  # what the core keeps on each side so far
    apart = np.stack([runs_of(outer_l[window] > kept_l[window] + 1.0 + tol, run),
                      runs_of(outer_r[window] > kept_r[window] + 1.0 + tol, run)])  # 2 x n: beside a handle
    joined = np.nonzero(~apart.any(0))[0]  # neither: the plates, the rim
    if len(joined) == 0:
        return out
    start = joined[0]  # a volute beside the core's first rows stands apart above them
    below = [start + np.argmax(apart[s, start:]) if apart[s, start:].any() else -1 for s in (0, 1)]
    if min(below) <= start:
        return out
    under = max(below)  # the later handle's first row
    xs = np.arange(mask.shape[1]) + 0.5 - (axis + 0.5)  # pixel centres relative to the axis
    above = mask[: rows.min()]
    volutes = min(int((above & (xs < 0)).any(1).sum()), int((above & (xs > 0)).any(1).sum())) >= END_ROWS * height
    edges = []
    for s, outer, kept in ((0, outer_l, kept_l), (1, outer_r, kept_r)):
        a = window[under] + int(round(PLATE_BELOW[0] * height))
        b = window[under] + max(1, int(round(PLATE_BELOW[1] * height)))
        if volutes:  # the handle's first pixel past what the core keeps
            side = np.abs(xs) * (np.sign(xs) == (1 if s else -1))
            beyond = mask[a:b] & (side > kept[a:b, None] + 1.0)
            handle = np.where(beyond, side, np.inf).min(1) - 0.5
            handle = handle[np.isfinite(handle)]
        else:
            handle = outer[a:b][outer[a:b] > kept[a:b] + 1.0]
        if len(handle) == 0:
            return out
        edges.append(float(np.median(handle)))
    band = window[start:under]
    out[band] = np.fmin(out[band], float(np.mean(edges)))
    return out


def _opening(profile: np.ndarray, span: int) -> np.ndarray:
    """Grey opening of a 1-D profile (NaN = no object) with a window of `span` samples: peaks narrower than the
    window are cut down to their surroundings."""
    filled = np.where(np.isnan(profile), 0.0, profile).astype(np.float32)[:, None]
    kernel = np.ones((max(1, span), 1), np.uint8)
    eroded = cv2.erode(filled, kernel, borderType=cv2.BORDER_REPLICATE)
    return cv2.dilate(eroded, kernel, borderType=cv2.BORDER_REPLICATE)[:, 0]


def _keep_ends(radius: np.ndarray, opened: np.ndarray, tol: float, rows: np.ndarray, top: int) -> np.ndarray:
    """The opened profile, except over bumps that start or end within `END_ROWS` of the top (`top`: the first
    row of the solid, under what stands on its rim) or the last row: a rim or a foot is the solid's own, a handle's
    attachment lies between body rows."""
    out = opened.copy()
    bump = np.zeros(len(radius) + 2, np.int8)
    bump[1:-1] = np.nan_to_num(radius, nan=0.0) > opened + tol
    edges = np.diff(bump)
    near = END_ROWS * (rows.max() - rows.min() + 1)
    for start, end in zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]):
        if start <= top + near or end >= rows.max() - near:
            out[start:end] = radius[start:end]
    return out


def upright_core(mask: np.ndarray, axis: float) -> np.ndarray:
    """The symmetric core of an upright bool mask (axis vertical at x = `axis`)."""
    left, right = _axis_runs(mask, axis)
    rows = np.nonzero(~np.isnan(left))[0]
    if len(rows) == 0:
        return mask.copy()
    cols = np.nonzero(mask.any(0))[0]
    tol = SIDE_TOLERANCE * (cols.max() - cols.min() + 1)
    radius = np.fmin(left, right)
    opened = _opening(radius, int(round(BUMP_SPAN * (rows.max() - rows.min() + 1))))
    spike = _top_spike(radius, rows)  # what stands on the rim; the rim under it is the solid's top
    limit = np.fmin(radius, _keep_ends(radius, opened, tol, rows, int(rows.min()) + spike)) + tol
    limit[rows.min() : rows.min() + spike] = 0.0
    limit = _handle_plates(mask, axis, left, right, limit, rows, tol)
    xs = np.arange(mask.shape[1]) + 0.5 - (axis + 0.5)  # pixel centres relative to the axis
    core = np.zeros_like(mask)
    for y in rows[limit[rows] > 0]:
        core[y] = mask[y] & (xs >= -min(left[y], limit[y])) & (xs <= min(right[y], limit[y]))
    return main_component(core)


def symmetric_core(mask: np.ndarray) -> Core:
    """Split a bool silhouette into its symmetric core and appendages.

    Args:
        mask: H x W bool silhouette (one object).

    Returns:
        Core; for an empty mask, an empty core with symmetry 0.
    """
    if not mask.any():
        return Core(mask.copy(), np.zeros_like(mask), 0.0, 0.0, 0.0)
    tilt, axis = find_axis(mask)
    if tilt:
        rot = upright_rotation(mask, tilt)
        core = turn_mask(upright_core(turn_mask(mask, rot), axis), cv2.invertAffineTransform(rot)) & mask
    else:
        core = upright_core(mask, axis)
    rest = mask & ~core
    n, labels, stats, _ = cv2.connectedComponentsWithStats(rest.astype(np.uint8), connectivity=8)
    small = [i for i in range(1, n) if stats[i, cv2.CC_STAT_AREA] < MIN_APPENDAGE * mask.sum()]
    if small:
        core |= np.isin(labels, small)
        rest &= ~core
    return Core(core, rest, tilt, axis, sor_score(core))


def above_rim(whole: np.ndarray, core: np.ndarray, rim_rows: float = 0.02) -> tuple[float, float, float]:
    """What of the located object stands above the core's top over the mouth (within the columns of the core's
    top rows, its rim), left out of the core: (its area over the core's, its rise above the rim over the rim's
    width, the share of it whose mirror image about the core's axis stands there too). A lid's head, a stopper, a
    figure or flowers rise there and are bulky or tall; a volute or a handle's plate seen end-on rises there too
    but is thin and low (on the kraters measured at most 0.03 of the core, rising 0.19 of the rim's width), and
    stands as a pair at the rim's two ends or in the middle (mirrored: 0.57-0.98 on the vessels measured), where a
    head set on one side of the rim is not (0-0.26 on the generated lids). (0, 0, 1) where nothing stands above
    the rim.

    Args:
        whole: n x n bool located object (core and appendages). core: n x n bool, its symmetric core.
    """
    rows = np.nonzero(core.any(1))[0]
    if len(rows) < 2:
        return 0.0, 0.0, 1.0
    top = int(rows[0])
    cols = np.nonzero(core[top : top + max(2, int(rim_rows * (rows[-1] - top + 1)))].any(0))[0]
    over = whole[:top, cols[0] : cols[-1] + 1]
    standing = np.nonzero(over.any(1))[0]
    if not standing.size:
        return 0.0, 0.0, 1.0
    left, right = row_extents(core, rows)
    axis = float(np.median((left + right) / 2.0)) - cols[0]  # in `over`'s columns
    ys, xs = np.nonzero(over)
    mirrored = np.rint(2.0 * axis - xs).astype(int)
    inside = (mirrored >= 0) & (mirrored < over.shape[1])
    both = np.zeros(xs.size, bool)
    both[inside] = over[ys[inside], mirrored[inside]]
    return (float(over.sum() / max(int(core.sum()), 1)), float((top - standing[0]) / (cols[-1] - cols[0] + 1)),
            float(both.mean()))
