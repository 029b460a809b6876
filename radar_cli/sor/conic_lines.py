"""Where horizontal lines cross ellipses given by their point conics, and which of many ellipses or segments
holds each line's left and right ends (sor.outline's rows and columns). No gradients flow through the choice of
winners; sor.outline evaluates each line's winner again with them.
"""

from __future__ import annotations

import math

import torch


def roots(qa: torch.Tensor, qb: torch.Tensor, qc: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The smaller and larger real root of qa t^2 + 2 qb t + qc = 0 (NaN where there is none)."""
    disc = qb * qb - qa * qc
    real = (disc > 0) & (qa.abs() > 0)
    root = torch.sqrt(torch.where(real, disc, torch.ones_like(disc)))
    inv = 1.0 / torch.where(real, qa, torch.ones_like(qa))
    t1, t2 = (-qb - root) * inv, (-qb + root) * inv
    nan = torch.full_like(t1, math.nan)
    return torch.where(real, torch.minimum(t1, t2), nan), torch.where(real, torch.maximum(t1, t2), nan)


def crossings(conic: tuple[torch.Tensor, ...], y: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The smaller and larger x where the lines at heights y cross ellipses (q00, q01, q02, q11, q12, q22, each
    broadcasting with y), NaN where they miss."""
    q00, q01, q02, q11, q12, q22 = conic
    return roots(q00, q01 * y + q02, q11 * y * y + 2 * q12 * y + q22)


def line_spans(low: torch.Tensor, high: torch.Tensor, lines: tuple[float, float, int]) -> tuple[torch.Tensor,
                                                                                         torch.Tensor]:
    """The first and last of the N lines each of B x K height ranges [low, high] spans, one spare either side
    (B x K long each; last < first where the range spans none, or is NaN). No gradients."""
    y0, dy, n = lines
    a, b = (low - y0) / dy, (high - y0) / dy
    first = (torch.fmin(a, b).floor() - 1).clamp(0, n)
    last = (torch.fmax(a, b).ceil() + 1).clamp(-1, n - 1)
    spans = ~(first.isnan() | last.isnan()) & (last >= first)
    first = torch.where(spans, first, torch.zeros_like(first)).long()
    return first, torch.where(spans, last, torch.full_like(last, -1.0)).long()


def band(first: torch.Tensor, last: torch.Tensor, lines: tuple[float, float, int]) -> tuple[torch.Tensor,
                                                                                           torch.Tensor]:
    """The lines first .. last (B x K, line_spans) as indices B x K x W into the N lines (N where a range needs
    fewer than W: a line past the last, whose values winner drops) and their heights B x K x W."""
    y0, dy, n = lines
    width = max(int((last - first).max()) + 1, 1) if last.numel() else 1
    index = first[..., None] + torch.arange(width, device=first.device)  # B x K x W
    index = torch.where(index <= last[..., None], index, torch.full_like(index, n))
    return index, y0 + index.to(torch.float64) * dy


def flat_lines(index: torch.Tensor, n: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """B x K x W line indices (band) as winner takes them: flat b (N + 1) + line, on a line, part k."""
    rows = torch.arange(index.shape[0], device=index.device)[:, None, None] * (n + 1)
    parts = torch.arange(index.shape[1], device=index.device)[None, :, None].expand_as(index)
    return (index + rows).flatten(), (index < n).flatten(), parts.flatten()


BAND_GROUPS = 4
"""The discs' crossings are evaluated in this many groups of similar band widths, each padded to its widest
(one padding for all would evaluate the widest band's lines on every disc): the same values, fewer of them."""
SAMPLE_STEP = 8
"""Every SAMPLE_STEP-th disc (and the last) is evaluated first; its ends bound which other discs can win."""
SAMPLE_MIN = 100_000
"""Discs x lines below which all are evaluated at once (the grouping and the sample cost more than they save)."""
PRUNE_MARGIN = 1e-4
"""A disc is left out of a run of lines only when its nearest point there is this far (normalised units, 1/40 px
at 512 px) beyond the sampled discs' end on every line of the run: far more than the crossings' rounding (~1e-8
at a tangent)."""
RUN_LINES = 8
"""The lines a disc spans are tested for pruning in runs of this many: a wide ellipse (a disc seen from above, in
the columns' pass) holds the ends only near its own extremes, and is left out of the runs between them."""


def disc_winners(conic: tuple[torch.Tensor, ...], low: torch.Tensor, high: torch.Tensor,
                 extremes: tuple[tuple[torch.Tensor, torch.Tensor], tuple[torch.Tensor, torch.Tensor]],
                 lines: tuple[float, float, int]) -> tuple[torch.Tensor, torch.Tensor]:
    """Per line, the disc whose ellipse crosses it furthest left and furthest right (conic: the six B x K
    coefficients as crossings takes them; low, high: B x K the ellipses' tangent heights; extremes: their
    leftmost and rightmost points, (x, y) B x K each): (left, right) B x N disc indices, K where no ellipse
    crosses the line.

    Each ellipse is evaluated only on the lines it spans, and only where it can win: a sample of the discs is
    evaluated first, and on each run of RUN_LINES lines a disc whose leftmost point there lies beyond the
    sample's left end on every line of the run (and whose rightmost point short of the right end) cannot hold an
    end there, nor tie one. An ellipse's left edge is convex in the line's height and its right edge concave, so
    a run's leftmost point is the ellipse's own where that lies in the run's heights, else at one of the run's
    ends: the bound is exact, and the winners are those of every disc on every line. No gradients."""
    y0, dy, n = lines
    batch, k = low.shape
    first, last = line_spans(low, high, lines)
    spans = last >= first
    if not first.numel() or first.numel() * (int((last - first).max()) + 1) < SAMPLE_MIN:
        index, y = band(first, last, lines)
        lo, hi = crossings(tuple(c[..., None] for c in conic), y)
        flat = flat_lines(index, n)
        return (winner(lo.flatten(), *flat, batch, n, "amin", k), winner(hi.flatten(), *flat, batch, n, "amax", k))
    sample = torch.zeros(k, dtype=torch.bool, device=low.device)
    sample[::SAMPLE_STEP] = True
    sample[-1] = True
    sample = spans & sample
    done = _evaluate(conic, first, last, sample.flatten(), lines)
    left = _line_best(done[0], done[2], done[3], batch, n, "amin")  # B x N, inf where no sampled disc crosses
    right = _line_best(done[1], done[2], done[3], batch, n, "amax")
    runs = max(-(-int((last - first).max() + 1) // RUN_LINES), 1)
    run_first = first[..., None] + RUN_LINES * torch.arange(runs, device=first.device)  # B x K x P
    run_last = torch.minimum(run_first + RUN_LINES - 1, last[..., None])
    nearest = _run_extremes(conic, low, high, extremes, run_first, run_last, lines)
    flat_first, flat_last = run_first.flatten(1), run_last.flatten(1)  # B x KP
    beyond = (nearest[0].flatten(1) > _range_reduce(left, flat_first, flat_last, torch.maximum) + PRUNE_MARGIN) & (
        nearest[1].flatten(1) < _range_reduce(right, flat_first, flat_last, torch.minimum) - PRUNE_MARGIN)
    chosen = ((spans & ~sample)[..., None] & (run_first <= run_last)).flatten(1) & ~beyond
    more = _evaluate(conic, flat_first, flat_last, chosen.flatten(), lines, runs)
    lo, hi, target, inside, disc = (torch.cat([a, b]) for a, b in zip(done, more))
    return (winner(lo, target, inside, disc, batch, n, "amin", k),
            winner(hi, target, inside, disc, batch, n, "amax", k))


def _run_extremes(conic: tuple[torch.Tensor, ...], low: torch.Tensor, high: torch.Tensor,
                  extremes: tuple[tuple[torch.Tensor, torch.Tensor], tuple[torch.Tensor, torch.Tensor]],
                  run_first: torch.Tensor, run_last: torch.Tensor,
                  lines: tuple[float, float, int]) -> tuple[torch.Tensor, torch.Tensor]:
    """The leftmost and rightmost x of each ellipse (B x K, as disc_winners) over the heights of each run of lines
    (B x K x P, first .. last) clamped to its span [low, high]; -inf and inf (never pruned) for conics that are no
    ellipse. B x K x P each."""
    y0, dy, _ = lines
    ends = [y0 + i.to(low.dtype) * dy for i in (run_first, run_last)]
    bottom = torch.maximum(torch.minimum(*ends), low[..., None]).clamp(max=high[..., None])
    top = torch.minimum(torch.maximum(*ends), high[..., None]).clamp(min=low[..., None])
    q00, q01, q02, q11, q12, q22 = (c[..., None] for c in conic)
    edges = []
    for h in (bottom, top):  # both edges at the run's ends: the crossings, the discriminant clamped at a tangent
        qb = q01 * h + q02
        root = torch.sqrt((qb * qb - q00 * (q11 * h * h + 2 * q12 * h + q22)).clamp_min(0.0))
        t1, t2 = (-qb - root) / q00, (-qb + root) / q00
        edges.append((torch.minimum(t1, t2), torch.maximum(t1, t2)))
    ellipse = q00 * q11 - q01 * q01 > 0
    bounds = []
    for i, ((x, y), reduce, far) in enumerate(zip(extremes, (torch.minimum, torch.maximum), (-math.inf, math.inf))):
        x, y = x[..., None], y[..., None]
        inside = (y >= bottom) & (y <= top)
        bound = torch.where(inside, x, reduce(edges[0][i], edges[1][i]))
        known = ellipse & x.isfinite() & y.isfinite() & bound.isfinite()
        bounds.append(torch.where(known, bound, torch.full_like(bound, far)))
    return bounds[0], bounds[1]


def _evaluate(conic: tuple[torch.Tensor, ...], first: torch.Tensor, last: torch.Tensor, chosen: torch.Tensor,
              lines: tuple[float, float, int], per_disc: int = 1) -> tuple[torch.Tensor, ...]:
    """The crossings of the chosen discs' runs of lines (flat B x KP bool; P = `per_disc` runs per disc,
    first .. last each, B x KP), in BAND_GROUPS groups of similar widths: flat (lo, hi, b (N + 1) + line, on a
    line, disc index)."""
    y0, dy, n = lines
    runs = first.shape[1]
    first, last = first.flatten(), last.flatten()
    count = last - first + 1
    order = torch.nonzero(chosen).flatten()
    order = order[torch.argsort(count[order], stable=True)]
    coefficients = tuple(c.flatten() for c in conic)
    out: list[list[torch.Tensor]] = [[], [], [], [], []]
    for group in torch.tensor_split(order, BAND_GROUPS) if len(order) else ():
        if not len(group):
            continue
        index = first[group, None] + torch.arange(int(count[group].max()), device=first.device)  # G x W
        inside = index <= last[group, None]
        index = torch.where(inside, index, torch.full_like(index, n))
        b, run = group // runs, group % runs
        disc = run // per_disc
        at = (b * (runs // per_disc) + disc)[:, None]
        crossing = crossings(tuple(c[at] for c in coefficients), y0 + index.to(conic[0].dtype) * dy)
        for i, t in enumerate((*crossing, index + b[:, None] * (n + 1), inside, disc[:, None])):
            out[i].append(t.expand_as(index).flatten())
    empty = (torch.zeros(0, dtype=conic[0].dtype, device=first.device),) * 2 + (
        torch.zeros(0, dtype=torch.long, device=first.device), torch.zeros(0, dtype=torch.bool, device=first.device),
        torch.zeros(0, dtype=torch.long, device=first.device))
    return tuple(torch.cat(p) if p else e for p, e in zip(out, empty))


def _line_best(values: torch.Tensor, target: torch.Tensor, inside: torch.Tensor, batch: int, n: int,
               reduce: str) -> torch.Tensor:
    """Per line the min or max (reduce) of flat values on lines `target` (as winner): B x N, inf (-inf) where
    none."""
    fill = math.inf if reduce == "amin" else -math.inf
    src = torch.where(~values.isnan() & inside, values, torch.full_like(values, fill))
    best = torch.full((batch * (n + 1),), fill, dtype=values.dtype, device=values.device)
    return best.scatter_reduce(0, target, src, reduce).view(batch, n + 1)[:, :n]


def _range_reduce(values: torch.Tensor, first: torch.Tensor, last: torch.Tensor, op) -> torch.Tensor:
    """op (torch.maximum or torch.minimum) of B x N values over each of the B x K line ranges first .. last
    (ranges that span none give op of two arbitrary values), by a sparse table: B x K."""
    n = values.shape[1]
    table = [values]
    while 2 ** len(table) <= n:
        step, prev = 2 ** (len(table) - 1), table[-1]
        table.append(torch.cat([op(prev[:, :-step], prev[:, step:]), prev[:, n - step:]], 1))
    length = (last - first + 1).clamp(1, n)
    level = torch.zeros_like(length)
    for j in range(1, len(table)):
        level += (length >= 2 ** j).long()
    stacked = torch.stack(table)  # J x B x N
    rows = torch.arange(values.shape[0], device=values.device)[:, None].expand_as(first)
    start = first.clamp(0, n - 1)
    end = (start + length - (2 ** level)).clamp(0, n - 1)
    return op(stacked[level, rows, start], stacked[level, rows, end])


def winner(values: torch.Tensor, target: torch.Tensor, inside: torch.Tensor, part: torch.Tensor, batch: int,
            n: int, reduce: str, parts: int) -> torch.Tensor:
    """Per line, which part holds the min or max (reduce: `amin` or `amax`) of flat values on the lines
    `target` (b (N + 1) + line, line N where `inside` is False; those and NaN are ignored), the parts numbered
    0 .. parts-1 by `part`: B x N part indices, `parts` where a line has none (the lowest on a tie)."""
    fill = math.inf if reduce == "amin" else -math.inf
    found = ~values.isnan() & inside
    src = torch.where(found, values, torch.full_like(values, fill))
    best = torch.full((batch * (n + 1),), fill, dtype=values.dtype, device=values.device)
    best = best.scatter_reduce(0, target, src, reduce)
    hit = found & (src == best.gather(0, target))
    part = torch.where(hit, part, torch.full_like(part, parts))
    none = torch.full((batch * (n + 1),), parts, dtype=part.dtype, device=values.device)
    return none.scatter_reduce(0, target, part, "amin").view(batch, n + 1)[:, :n]
