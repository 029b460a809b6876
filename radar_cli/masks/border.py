"""Which parts of a photo's border show the backdrop, for the backdrop model of `masks.detect`.

The border band is read along the ring it makes around the photo. An object that runs into the frame crosses
the band with its outline: a sharp colour step along the ring. Shading of the backdrop (a sweep, a vignette,
a light pool) changes its colour slowly, however much in all. The ring is cut at the sharp steps into runs (and,
along the top and bottom edges, which an upright vessel's rim and foot cross, at soft ones: a blurred,
low-contrast plate); with none, or only one, the whole band is backdrop. Otherwise the backdrop is the set of
runs, each at least half explained by one linear colour gradient across the frame (a flat backdrop or a sweep),
that holds the most explained pixels; of two neighbouring runs of clearly different colours at most one is in it
(the step between them is the object's outline). It is grown by long runs (against all the backdrop runs
together) of a somewhat different colour (a whole side of the frame lit differently) and by the runs that
continue a backdrop run's colour across a short interruption (a label, a chart, a scale bar).

A flat frame round the picture (a black or white border that squared the photo up) is neither backdrop nor
object (`frame_padding`).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

BORDER_FRAC = 0.04  # width of the border band the backdrop is fitted to, as a fraction of the long edge
STEP_SPAN = 2  # a step is the colour change over 2 x this many pixels along the ring ...
STEP_EDGE = 20.0  # ... and an outline crossing the band where it exceeds this (RGB levels, Euclidean)
SOFT_SPAN = 6  # a soft outline (a blurred, low-contrast scan) is a change over 2 x this many pixels ...
SOFT_EDGE = 30.0  # ... over this (a backdrop's shading changes a few levels over such a span)
RING_PIECES = 32  # runs are judged in pieces of at most 1 / this of the ring (a long run spans a gradient) ...
RUN_TOLERANCE = 14.0  # ... pieces whose median colours a gradient explains this closely (levels) show it
GRADIENT_TRIES = 400  # random triples of pieces a gradient is fitted through
END_SPAN = 6  # a run's end colour is read over this many pixels along the ring
BRIDGE = 0.2  # a run continues a chosen one across interruptions of at most this share of the ring
OUTLINE_STEP = 40.0  # two neighbouring runs this far apart in median colour (levels) are object and backdrop
LONG_SHARE = 0.5  # a run at least this share as long as the longest backdrop run ...
LONG_TOLERANCE = 65.0  # ... is backdrop as well if its median colour is this close (levels) to a backdrop run's
PAD_MAX = 0.02  # a flat frame round the picture is at most this share of its long side deep ...
PAD_SPREAD = 8.0  # ... its pixels this close (levels) to its colour ...
PAD_SHARE = 0.6  # ... on at least this share of each of its lines ...
PAD_STEP = 25.0  # ... and the picture inside it this far from its colour
PAD_SMEAR = 2  # the frame's edge blurred into this many pixels by resampling goes with it


def border_band(shape: tuple[int, int], frac: float = BORDER_FRAC) -> np.ndarray:
    """H x W bool, True in a band along the image border `frac` of the long edge wide (at least 2 px)."""
    h, w = shape
    k = max(2, round(frac * max(h, w)))
    band = np.zeros((h, w), bool)
    band[:k], band[-k:], band[:, :k], band[:, -k:] = True, True, True, True
    return band


def _ring(shape: tuple[int, int], band: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[int], int]:
    """The band's pixels (flat indices) and each one's position along the ring (clockwise from the top-left,
    on the path through the band's middle at inset c); the path's side lengths; c."""
    h, w = shape
    c = max(2, round(BORDER_FRAC * max(h, w))) // 2
    ys, xs = np.nonzero(band)
    side = np.argmin(np.stack([ys, w - 1 - xs, h - 1 - ys, xs]), axis=0)  # the nearest edge: top, right, ...
    lengths = [max(1, w - 2 * c), max(1, h - 2 * c)] * 2
    along = np.select([side == 0, side == 1, side == 2], [xs - c, ys - c, w - 1 - c - xs], h - 1 - c - ys)
    start = np.cumsum([0, *lengths[:-1]])
    position = start[side] + np.clip(along, 0, np.array(lengths)[side] - 1)
    return ys * w + xs, position.astype(int), lengths, c


def _profile(image: np.ndarray, c: int, lengths: list[int]) -> np.ndarray:
    """L x 3 colour along the ring's path (slightly blurred), L = sum(lengths)."""
    h, w = image.shape[:2]
    blur = cv2.GaussianBlur(image, (0, 0), 1.0).astype(np.float32)
    top, right = blur[c, c : c + lengths[0]], blur[c : c + lengths[1], w - 1 - c]
    bottom, left = blur[h - 1 - c, w - c - lengths[2] : w - c][::-1], blur[h - c - lengths[3] : h - c, c][::-1]
    return np.concatenate([top, right, bottom, left])


@dataclass(frozen=True)
class Run:
    """A stretch of the ring between two sharp steps: its band pixels (flat indices) and their positions along
    it (order), its length along the ring and the colours at its two ends (first, last; 3-vectors) and over all
    of it (median)."""

    pixels: np.ndarray
    order: np.ndarray
    length: int
    first: np.ndarray
    last: np.ndarray
    median: np.ndarray


def _ends(profile: np.ndarray, start: int, stop: int) -> tuple[np.ndarray, np.ndarray]:
    """Median colours just inside the two ends of the ring positions [start, stop) (stop may pass the end)."""
    n = len(profile)
    inner = min(END_SPAN, max(1, (stop - start) // 3))
    at = np.arange(start, stop) % n
    skip = min(2, max(0, len(at) - inner))  # the blurred step itself is not the run's colour
    head, tail = at[skip : skip + inner], at[::-1][skip : skip + inner]
    return np.median(profile[head], axis=0), np.median(profile[tail], axis=0)


def _steps(profile: np.ndarray, span: int, edge: float) -> np.ndarray:
    """Ring positions (int) where the colour changes by over `edge` across 2 x `span` pixels, most there."""
    step = np.linalg.norm(np.roll(profile, -span, 0) - np.roll(profile, span, 0), axis=1)
    return np.nonzero((step > edge) & (step >= np.roll(step, 1)) & (step >= np.roll(step, -1)))[0]


def ring_runs(image: np.ndarray, band: np.ndarray) -> list[Run]:
    """The band cut at the colour steps along the ring, in ring order (one run if the ring has fewer than two):
    sharp ones (STEP_EDGE over 2 x STEP_SPAN pixels) and, along the top and bottom edges, soft ones (SOFT_EDGE
    over 2 x SOFT_SPAN) with no sharp one near."""
    flat, position, lengths, c = _ring(band.shape, band)
    profile = _profile(image, c, lengths)
    n = len(profile)
    values = image.reshape(-1, 3).astype(np.float32)
    whole = Run(flat, position, n, *_ends(profile, 0, n), np.median(values[flat], axis=0))
    if n < 4 * STEP_SPAN + 2:
        return [whole]
    cuts = _steps(profile, STEP_SPAN, STEP_EDGE)
    soft = _steps(profile, SOFT_SPAN, SOFT_EDGE)  # where no sharp step is near: a soft outline; only along the
    # top and bottom edges, which an upright vessel's rim and foot cross (a sweep's horizon, a table's edge and
    # the shading between wall and floor cross the sides)
    top, bottom = (soft < lengths[0]), (soft >= lengths[0] + lengths[1]) & (soft < n - lengths[3])
    soft = soft[top | bottom]
    if len(soft):
        gap = np.full(len(soft), n)  # along the ring to the nearest sharp step
        if len(cuts):
            gap = np.abs((soft[:, None] - cuts[None] + n // 2) % n - n // 2).min(1)
        cuts = np.sort(np.concatenate([cuts, soft[gap > SOFT_SPAN]]))
    if len(cuts) < 2:
        return [whole]
    run = np.searchsorted(cuts, position, side="right") % len(cuts)  # past the last cut: back to the first run
    out = []
    for r in range(len(cuts)):
        start, stop = cuts[r - 1], cuts[r] + (n if r == 0 else 0)
        if (run == r).any():
            out.append(Run(flat[run == r], (position[run == r] - start) % n, stop - start,
                           *_ends(profile, start, stop), np.median(values[flat[run == r]], axis=0)))
    return out


def _bridged(runs: list[Run], chosen: np.ndarray) -> np.ndarray:
    """`chosen` grown by the runs that continue a chosen run's colour across a short interruption (a label, a
    chart or a scale bar standing in the band): the ends that face each other agree."""
    total = sum(r.length for r in runs)
    chosen = chosen.copy()
    grown = True
    while grown:
        grown = False
        for k in np.nonzero(~chosen)[0]:
            for way in (-1, 1):
                j, gap = (k + way) % len(runs), 0
                while not chosen[j] and j != k:
                    gap += runs[j].length
                    j = (j + way) % len(runs)
                if j == k or gap > BRIDGE * total:
                    continue
                mine, theirs = (runs[k].first, runs[j].last) if way < 0 else (runs[k].last, runs[j].first)
                if np.linalg.norm(mine - theirs) < RUN_TOLERANCE:
                    chosen[k] = grown = True
                    break
    return chosen


def _chunks(runs: list[Run], piece: float) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """The runs cut into pieces of about `piece` pixels of ring (a long run spans a shading gradient): per piece
    its run's index, its pixel count and (in the list) its pixels."""
    owner, pixels = [], []
    for i, r in enumerate(runs):
        count = max(1, round(r.length / piece))
        for part in np.array_split(r.pixels[np.argsort(r.order, kind="stable")], count):
            if len(part):
                owner.append(i)
                pixels.append(part)
    return np.array(owner), np.array([len(p) for p in pixels], np.float64), pixels


def _backdrop_runs(runs: list[Run], colours: np.ndarray, centres: np.ndarray, size: np.ndarray,
                   owner: np.ndarray) -> np.ndarray:
    """R bool: the runs that one linear colour gradient across the frame (a flat backdrop or a sweep) explains,
    each at least half of its pixels within RUN_TOLERANCE. Of two neighbouring runs of clearly different colours
    (OUTLINE_STEP: the sharp step between them is an outline crossing the band) at most one is backdrop: the one
    it explains more of. The gradient is the one whose runs hold the most explained pixels, from GRADIENT_TRIES
    random triples of pieces and single pieces (flat), then refitted to those pixels. Counting whole runs, not
    pieces, keeps a steep gradient through a dark rim cut by the top edge and the light floor under the foot from
    outweighing one long run that changes slowly: the backdrop round three sides.

    Args:
        colours, centres, size, owner: per piece of the runs (`_chunks`): its median colour (P x 3), its centre
            in the frame (P x 2, fractions of width and height), its pixels and its run.
    """
    design = np.column_stack([np.ones(len(colours)), centres])  # P x 3
    rng = np.random.default_rng(0)
    triples = rng.integers(0, len(colours), (GRADIENT_TRIES, 3))
    coefs = np.linalg.pinv(design[triples]) @ colours[triples]  # T x 3 x 3
    flat = np.zeros((len(colours), 3, 3))
    flat[:, 0] = colours  # each piece's colour everywhere
    coefs = np.concatenate([coefs, flat])
    inliers = np.linalg.norm(colours[None] - design[None] @ coefs, axis=2) < RUN_TOLERANCE  # T x P
    member = np.eye(len(runs))[owner]  # P x R
    run_size = size @ member  # R
    stepped = [r for r in range(len(runs))
               if np.linalg.norm(runs[r].median - runs[(r + 1) % len(runs)].median) >= OUTLINE_STEP]

    def held(inl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(... x P bool inliers) -> (... x R bool runs held, ... explained pixels in them)."""
        inside = (inl * size) @ member  # ... x R
        keep = inside >= 0.5 * run_size
        for r in stepped:  # neighbours across an outline: the one less explained is let go
            q = (r + 1) % len(runs)
            both = keep[..., r] & keep[..., q]
            first_less = inside[..., r] < inside[..., q]
            keep[..., r] &= ~(both & first_less)
            keep[..., q] &= ~(both & ~first_less)
        return keep, (inside * keep).sum(-1)

    keep, score = held(inliers)
    best = int(np.argmax(score))
    runs_kept, best_score, best_inl = keep[best], score[best], inliers[best]
    root = np.sqrt(size)[:, None]
    for _ in range(2 if runs_kept.any() else 0):
        use = best_inl & runs_kept[owner]
        coef, *_ = np.linalg.lstsq(design[use] * root[use], colours[use] * root[use], rcond=None)
        refit = np.linalg.norm(colours - design @ coef, axis=1) < RUN_TOLERANCE
        refit_kept, refit_score = held(refit)
        if refit_score < best_score:
            break
        runs_kept, best_score, best_inl = refit_kept, refit_score, refit
    return runs_kept


def backdrop_band(image: np.ndarray) -> np.ndarray:
    """H x W bool: the pixels of the border band that show backdrop (see the module's note).

    Args:
        image: H x W x 3 uint8 RGB.
    """
    band = border_band(image.shape[:2])
    runs = ring_runs(image, band)
    if len(runs) < 2:
        return band
    h, w = band.shape
    flat = image.reshape(-1, 3).astype(np.float32)
    owner, size, pieces = _chunks(runs, sum(r.length for r in runs) / RING_PIECES)
    colours = np.array([np.median(flat[p], axis=0) for p in pieces])  # P x 3
    centres = np.array([[(p % w).mean() / w, (p // w).mean() / h] for p in pieces])  # P x 2
    chosen = _backdrop_runs(runs, colours, centres, size, owner)
    if not chosen.any():
        return band
    weight = np.array([len(r.pixels) for r in runs], np.float64)
    colours = np.array([r.median for r in runs])  # R x 3
    # whole sides of the frame, lit differently, if near the colour of a main backdrop run (not of a fragment
    # between two steps that the gradient happens to explain); long as against all the backdrop seen, so that
    # a backdrop cut in two by a foot on the bottom edge does not make a rim cut by the top edge long
    main = chosen & (weight >= LONG_SHARE * weight[chosen].max())
    near = (np.linalg.norm(colours[:, None] - colours[main][None], axis=2) < LONG_TOLERANCE).any(1)
    long = weight >= LONG_SHARE * weight[chosen].sum()
    chosen = _bridged(runs, chosen | (long & near))
    out = np.zeros(h * w, bool)
    for r, keep in zip(runs, chosen):
        out[r.pixels] = keep
    return out.reshape(h, w)


def _padded_lines(lines: np.ndarray, colour: np.ndarray, share: float) -> int:
    """How many of the first L x N x 3 `lines` (outermost first) are a frame of the flat `colour` (on at least
    `share` of each line: an object may stand on it) that the line inside them breaks from."""
    flat = np.linalg.norm(lines - colour, axis=2) < PAD_SPREAD  # L x N
    count = 0
    while count < len(lines) - 1 and flat[count].mean() >= share:
        count += 1
    if count == 0 or np.median(np.linalg.norm(lines[count] - colour, axis=1)) < PAD_STEP:
        return 0  # no frame, or a plain backdrop that just goes on
    return count


def _frame(image: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, int]]:
    """Per side (top, bottom, left, right): its outermost lines (L x N x 3 float, outermost first), the frame's
    colour and how many of the lines are frame (0: none)."""
    h, w = image.shape[:2]
    depth = max(1, round(PAD_MAX * max(h, w))) + 1
    sides = [image[:depth], image[::-1][:depth], image[:, :depth].transpose(1, 0, 2),
             image[:, ::-1][:, :depth].transpose(1, 0, 2)]
    sides = [lines.astype(np.float32) for lines in sides]
    own = [np.median(lines[0], axis=0) for lines in sides]
    counts = [_padded_lines(lines, colour, PAD_SHARE) for lines, colour in zip(sides, own)]
    framed = [colour for colour, count in zip(own, counts) if count]
    out = []
    for lines, colour, count in zip(sides, own, counts):
        if framed and not count:  # the frame's colour from the other sides, on half the share of the line
            colour = framed[0]
            count = _padded_lines(lines, colour, PAD_SHARE / 2)
        out.append((lines, colour, count))
    return out


def frame_inset(image: np.ndarray) -> tuple[int, int, int, int]:
    """(top, bottom, left, right): how many rows and columns a flat frame round the picture (a black or white
    border that squared it up) takes on each side, its edge smeared by resampling included; zeros without one.

    Args:
        image: H x W x 3 uint8 RGB.
    """
    counts = [count + PAD_SMEAR if count else 0 for _, _, count in _frame(image)]
    return counts[0], counts[1], counts[2], counts[3]


def frame_padding(image: np.ndarray) -> np.ndarray:
    """H x W bool: the pixels of a flat frame round the picture (`frame_inset`), which is neither backdrop nor
    object; only its flat pixels (an object crossing it keeps its own). A side mostly covered by an object (a
    stand on the bottom edge) is found from the colour the other sides show.

    Args:
        image: H x W x 3 uint8 RGB.
    """
    h, w = image.shape[:2]
    out = np.zeros((h, w), bool)
    views = [out, out[::-1], out.T, out[:, ::-1].T]
    for view, (lines, colour, count) in zip(views, _frame(image)):
        if count:
            view[:count] |= np.linalg.norm(lines[:count] - colour, axis=2) < PAD_SPREAD
            view[count : count + PAD_SMEAR] |= view[count - 1]  # the frame's edge, smeared by resampling
    return out
