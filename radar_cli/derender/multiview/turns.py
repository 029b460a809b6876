"""The turn of each view about the axis relative to the first, found from the photographs: the views' textures
unwrapped over 360 deg (multiview.fuse.unwrap_view) are compared where two views see the same surface, by
normalised cross-correlation of their detail along the angle (each row's slow changes, the shading the fit did not
explain and the painted horizontal bands, taken out), at every turn between them. The turns that agree best over
all pairs are chosen, near a prior of equal steps (a museum's A, A/B, B, B/A views: 90 deg) that only ranks
near-ties: a view whose texture overlaps none of the others' keeps its step. Where the locator split handles off
the silhouettes, they place the views too: a view with a handle standing out on each side looks at the vessel
between its handles, a view with one in front of the middle along them, so two views of the first kind are turned
by a multiple of 180 deg from each other and by 90 or 270 from one of the second kind (`handle_phase`); the
steps are assigned only as that allows."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import cv2
import numpy as np
import torch
import torch.nn.functional as F

from radar_cli.derender.multiview.fuse import ViewTexture

SPREAD_TIE_BREAK = 1e-6  # per degree of the smallest gap between views: decides only between equal scores
HANDLE_SIDE = 0.75  # an appendage centred beyond this share of the half-width from the axis stands out at a side
HANDLE_MIDDLE = 0.35  # ... one centred within this share stands in front of (or behind) the middle
HANDLE_MIN_SHARE = 0.003  # appendage pieces under this share of the core's area are left out (specks, a label)
MAX_ASSIGNMENTS = 1024  # assignments of views to the prior's steps polished one by one; where there are more, ...
BEAM = 64  # ... the views are assigned one at a time, keeping this many of the best partial assignments


@dataclass(frozen=True)
class TurnConfig:
    """How the turns are registered.

    Attributes:
        step_deg: the prior's step between views (each view starts at a distinct multiple of it).
        reach_deg: each turn is searched within this of its step.
        prior_weight: the score lost by a turn reach_deg away from its step (the correlations are 0..1 per pair).
        rows: rows of the low-resolution maps compared (their columns are whole degrees, 360).
        detail_sigma_deg, fine_sigma_deg: the detail compared is the texture blurred along the angle by a Gaussian
            of the fine width less its blur by the other (a band: the shading and the bands are slower, a painted
            frieze's repeats are finer and would match at every repeat).
        seen: texels a view sees at a cosine below this are left out of the comparison.
        full_overlap: overlaps of at least this many texels count fully; smaller ones in proportion.
        rounds: rounds of coordinate ascent over the views' turns.
    """

    step_deg: float = 90.0
    reach_deg: float = 30.0
    prior_weight: float = 0.05
    rows: int = 64
    detail_sigma_deg: float = 12.0
    fine_sigma_deg: float = 2.0
    seen: float = 0.3
    full_overlap: int = 3000
    rounds: int = 3


@dataclass(frozen=True)
class Turns:
    """The registered turns.

    Attributes:
        degrees: per view, its turn relative to the first (0 for the first), in [0, 360).
        registered: per view, whether its turn came from the textures (False: the prior's step kept: its texture
            overlapped no other view's, or agreed best only at the edge of the reach).
        agreement: per view, the mean correlation with the views it overlaps at the chosen turns (NaN: none).
    """

    degrees: tuple[float, ...]
    registered: tuple[bool, ...]
    agreement: tuple[float, ...]


def _circular_blur(x: np.ndarray, sigma: float) -> np.ndarray:
    """R x 360 blurred along the angle (wrapping round) by a Gaussian of sigma columns."""
    radius = int(math.ceil(3 * sigma))
    taps = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    taps /= taps.sum()
    padded = np.concatenate([x[:, -radius:], x, x[:, :radius]], axis=1)
    return np.stack([np.convolve(row, taps, mode="valid") for row in padded])


def detail_map(view: ViewTexture, config: TurnConfig) -> tuple[np.ndarray, np.ndarray]:
    """(R x 360 detail, R x 360 bool seen) of a view's texture: the grey albedo at whole degrees less its blur along
    the angle (a weighted blur over the seen texels only)."""
    grey = view.albedo.mean(1, keepdim=True) ** (1 / 2.2)
    small = F.interpolate(torch.cat([grey, view.weight], 1), size=(config.rows, 360), mode="area")[0].double().numpy()
    seen = small[1] > config.seen
    value = np.where(seen, small[0], 0.0)
    mask = seen.astype(np.float64)
    fine, coarse = (_blurred(value, mask, sigma) for sigma in (config.fine_sigma_deg, config.detail_sigma_deg))
    return np.where(seen, fine - coarse, 0.0), seen


def _blurred(value: np.ndarray, mask: np.ndarray, sigma: float) -> np.ndarray:
    """The masked values' normalised blur along the angle (the value itself where sigma is 0)."""
    if sigma <= 0:
        return value
    return _circular_blur(value * mask, sigma) / np.maximum(_circular_blur(mask, sigma), 1e-6)


def correlation(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray],
                config: TurnConfig) -> tuple[np.ndarray, np.ndarray]:
    """(360 correlations, 360 overlap weights in [0, 1]) of view a's detail with view b's turned by d degrees
    (b's column c moved to c + d), for d = 0..359: a sees at its angle phi what b sees at phi - d, i.e. b's turn
    is a's plus d."""
    (da, sa), (db, sb) = a, b
    ncc, weight = np.zeros(360), np.zeros(360)
    for d in range(360):
        both = sa & np.roll(sb, d, axis=1)
        n = int(both.sum())
        if n < 20:
            continue
        x, y = da[both], np.roll(db, d, axis=1)[both]
        x, y = x - x.mean(), y - y.mean()
        ncc[d] = float((x * y).sum() / max(math.sqrt(float((x * x).sum() * (y * y).sum())), 1e-12))
        weight[d] = min(1.0, n / config.full_overlap)
    return ncc, weight


def _score_at(k: int, theta: np.ndarray, curves: dict, count: int) -> np.ndarray:
    """360 scores of view k's turn at each whole degree, the others' held: its pairs' weighted correlations."""
    total = np.zeros(360)
    for j in range(count):
        if j == k:
            continue
        ncc, weight = curves[(j, k)]  # indexed by theta_k - theta_j
        shift = int(round(theta[j])) % 360
        total += np.roll(ncc * weight, shift)
    return total


def _prior(slot: float, config: TurnConfig) -> np.ndarray:
    """360 prior penalties of a view's turn near `slot` (inf beyond reach_deg)."""
    off = (np.arange(360) - slot + 180) % 360 - 180
    return np.where(np.abs(off) <= config.reach_deg, config.prior_weight * (off / config.reach_deg) ** 2, np.inf)


def _ascend(slots: tuple[float, ...], curves: dict, config: TurnConfig) -> tuple[np.ndarray, float]:
    """Coordinate ascent from the slots: (the turns, their total score)."""
    count = len(slots)
    theta = np.array(slots, np.float64)
    for _ in range(config.rounds):
        for k in range(1, count):
            theta[k] = float(np.argmax(_score_at(k, theta, curves, count) - _prior(slots[k], config)))
    total = sum(_score_at(k, theta, curves, count)[int(theta[k]) % 360] - _prior(slots[k], config)[int(theta[k])]
                for k in range(1, count))
    for k in range(1, count):  # sub-degree: a parabola through the peak and its neighbours
        s = _score_at(k, theta, curves, count)
        c = int(theta[k]) % 360
        left, mid, right = s[c - 1], s[c], s[(c + 1) % 360]
        bend = left - 2 * mid + right
        if bend < 0:
            theta[k] = (theta[k] + float(np.clip(0.5 * (left - right) / bend, -0.5, 0.5))) % 360
    return theta, float(total)


def _smallest_gap(slots: tuple[float, ...]) -> float:
    """The smallest angle between two of the slots round the circle (degrees)."""
    ordered = sorted(s % 360 for s in slots)
    return min((b - a) % 360 or 360.0 for a, b in zip(ordered, ordered[1:] + ordered[:1]))


def handle_phase(core: np.ndarray, appendages: np.ndarray | None) -> float | None:
    """Where a view's handles stand about the axis, modulo 180 deg from the direction it looks at: 90 where pieces
    of the appendages stand out on both sides of the silhouette (a two-handled vessel seen between its handles),
    0 where they stand only in front of the middle (seen along its handles), None otherwise (none, one side only,
    both kinds).

    Args:
        core: N x N bool silhouette's symmetric core; appendages: N x N bool pixels split off it (None: none).
    """
    if appendages is None or not appendages.any() or not core.any():
        return None
    cols = np.nonzero(core.any(0))[0]
    axis, half = (cols[0] + cols[-1]) / 2.0, max((cols[-1] - cols[0]) / 2.0, 1.0)
    n, _, stats, centres = cv2.connectedComponentsWithStats(appendages.astype(np.uint8), connectivity=8)
    big = [i for i in range(1, n) if stats[i, cv2.CC_STAT_AREA] >= HANDLE_MIN_SHARE * core.sum()]
    offsets = [(centres[i][0] - axis) / half for i in big]
    left, right = any(o <= -HANDLE_SIDE for o in offsets), any(o >= HANDLE_SIDE for o in offsets)
    middle = any(abs(o) <= HANDLE_MIDDLE for o in offsets)
    if left and right and not middle:
        return 90.0
    if middle and not (left or right):
        return 0.0
    return None


def _allowed(slots: tuple[float, ...], phases: list[float | None]) -> bool:
    """Whether turns at these slots agree with the views' handle phases (handle_phase): a handle at object angle
    h is seen by view k at h - turn_k, so turn_k - turn_j = phase_j - phase_k modulo 180."""
    known = [(s, p) for s, p in zip(slots, phases) if p is not None]
    return all(round((sk - sj - (pj - pk)) % 180.0) % 180 == 0
               for (sj, pj), (sk, pk) in itertools.combinations(known, 2))


def _assignments(count: int, curves: dict, config: TurnConfig,
                 phases: list[float | None] | None) -> list[tuple[float, ...]]:
    """The assignments of the views to the prior's steps (degrees per view, the first at 0) worth polishing: views
    on distinct steps, or steps reused where there are more views than steps; only those the handle phases allow
    where any is. All of them up to MAX_ASSIGNMENTS; beyond, the BEAM best of a beam search (`_beam`)."""
    steps = max(1, int(round(360 / config.step_deg)))
    distinct = count - 1 <= steps - 1
    if (math.perm(steps - 1, count - 1) if distinct else steps ** (count - 1)) <= MAX_ASSIGNMENTS:
        choices = (itertools.permutations(range(1, steps), count - 1) if distinct
                   else itertools.product(range(steps), repeat=count - 1))
        candidates = [(0.0, *(c * config.step_deg for c in choice)) for choice in choices]
    else:
        candidates = _beam(count, steps, curves, config, phases)
    if phases is not None and any(_allowed(s, phases) for s in candidates):
        candidates = [s for s in candidates if _allowed(s, phases)]
    return candidates


def _beam(count: int, steps: int, curves: dict, config: TurnConfig,
          phases: list[float | None] | None) -> list[tuple[float, ...]]:
    """The BEAM best assignments of `count` views to `steps` steps (reused), the views placed one at a time: each
    partial assignment scored by its pairs' best agreement within reach of their steps' difference, those the
    handle phases allow ranked first (ties by the steps, so the same views give the same turns)."""
    reach = np.arange(-int(config.reach_deg), int(config.reach_deg) + 1)
    best_near: dict[tuple[int, int, int], float] = {}

    def agreement(j: int, k: int, delta: int) -> float:
        """Views j and k's best weighted correlation within reach of a turn `delta` (degrees) between them."""
        if (j, k, delta) not in best_near:
            ncc, weight = curves[(j, k)]
            best_near[(j, k, delta)] = float((ncc * weight)[(delta + reach) % 360].max())
        return best_near[(j, k, delta)]

    def degrees(chosen: tuple[int, ...]) -> tuple[float, ...]:
        return tuple(c * config.step_deg for c in chosen)

    beam: list[tuple[float, tuple[int, ...]]] = [(0.0, (0,))]
    for k in range(1, count):
        grown = [(score + sum(agreement(j, k, round((s - chosen[j]) * config.step_deg) % 360) for j in range(k)),
                  (*chosen, s)) for score, chosen in beam for s in range(steps)]
        grown.sort(key=lambda t: (phases is not None and not _allowed(degrees(t[1]), phases), -t[0], t[1]))
        beam = grown[:BEAM]
    return [degrees(chosen) for _, chosen in beam]


def register_turns(views: list[ViewTexture], config: TurnConfig = TurnConfig(),
                   phases: list[float | None] | None = None) -> Turns:
    """The turns of V views (each ViewTexture in its own frame) relative to the first: every assignment of the
    views to distinct steps of the prior (or steps reused, with more views than steps) that the views' handle
    phases allow (`phases`, handle_phase per view; all assignments where none does; `_assignments`) is polished by
    coordinate ascent and the best total agreement kept. A turn that ends at the edge of its reach found no peak
    there and keeps its step (not registered)."""
    count = len(views)
    details = [detail_map(v, config) for v in views]
    curves = {}
    for i, j in itertools.combinations(range(count), 2):
        ncc, weight = correlation(details[i], details[j], config)
        curves[(i, j)] = (ncc, weight)
        curves[(j, i)] = (np.roll(ncc[::-1], 1), np.roll(weight[::-1], 1))  # d -> -d
    candidates = _assignments(count, curves, config, phases)
    best: tuple[np.ndarray, float, tuple[float, ...]] = (np.zeros(count), -np.inf, candidates[0])
    for slots in candidates:
        theta, total = _ascend(slots, curves, config)
        total += SPREAD_TIE_BREAK * _smallest_gap(slots)  # on a tie (no overlaps) the views spread round evenly
        if total > best[1]:
            best = (theta, total, slots)
    theta, _, slots = best
    registered, agreement = [True], [float("nan")]
    for k in range(1, count):
        off = (theta[k] - slots[k] + 180.0) % 360.0 - 180.0
        edge = abs(off) >= config.reach_deg - 1.0  # no peak within reach: the agreement only rose towards its edge
        if edge:
            theta[k] = slots[k]
        pairs = [(curves[(j, k)][0][int(round(theta[k] - theta[j])) % 360],
                  curves[(j, k)][1][int(round(theta[k] - theta[j])) % 360]) for j in range(count) if j != k]
        used = [c for c, w in pairs if w > 0]
        registered.append(bool(used) and not edge)
        agreement.append(float(np.mean(used)) if used else float("nan"))
    return Turns(tuple(float(t % 360) for t in theta), tuple(registered), tuple(agreement))
