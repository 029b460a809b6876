"""Closed-form, no-grad ray queries against a solid of revolution with a piecewise-linear profile.

Between two profile rows the surface is a cone frustum rho = a + b y, so a ray meets it where a quadratic vanishes;
the caps are the planes y = +-h. Every query here is exact up to rounding and runs on a flat list of
(ray, segment) pairs, one per profile segment that the ray's span through the bounding cylinder crosses, so the
work follows the rays' actual extent rather than a fixed number of samples.

Each ray is re-centred at its closest approach to the object's centre (parameter t = s - s_c) so the quadratics
have O(1) coefficients and stay accurate in float32.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch

BIG = 1e6  # a parameter far beyond any object (object-space units)
SEARCH_CHUNK = 16384
"""Rays searched at a time on the CPU: a 512 px view's 262k rays cross ~8M (ray, segment) pairs, whose ~15 working
tensors took 500 MB at once; chunks of 16k rays take ~30 MB (with 32k a de-rendering's two worker processes peaked
140 MiB higher, at the same speed; docs/performance.md). Every ray's search is its own (elementwise operations and
per-ray minima), so the result is the same bits in chunks or at once."""
GPU_SEARCH_CHUNK = 1 << 21
"""Rays searched at a time on a GPU (~4 GB of working tensors): a training batch of 24 views at 256 px (1.6M rays)
in one chunk. In 32k-ray chunks it took 48, each ~350 kernel launches and several host synchronisations, and the
paper preset's step was bound by the launches (0.25 s against ~0.08 s of GPU time on an H100)."""


@dataclass(frozen=True)
class Found:
    """Per-ray search results (M rays, no grad), as ray parameters s along the unit direction.

    Attributes:
        s_min: minimiser of F along the ray (for the soft-silhouette margin and misses' closest approach).
        s_hit: the visible surface point (entry, or for rays entering through the mouth, the inner wall).
        hit: bool, the ray meets the solid.
        inner: bool, the visible point is on the inside (seen through the mouth).
        cap: bool, the visible point is on the bottom disc.
    """

    s_min: torch.Tensor
    s_hit: torch.Tensor
    hit: torch.Tensor
    inner: torch.Tensor
    cap: torch.Tensor


@dataclass(frozen=True)
class _Ray:
    """Re-centred rays, all M-vectors: rho^2(t) = qa t^2 + qb t + qc, y(t) = oy + t dy."""

    qa: torch.Tensor
    qb: torch.Tensor
    qc: torch.Tensor
    oy: torch.Tensor
    dy: torch.Tensor

    def take(self, idx: torch.Tensor) -> "_Ray":
        """The rays at indices idx (one per (ray, segment) pair)."""
        return _Ray(*(x.index_select(0, idx) for x in (self.qa, self.qb, self.qc, self.oy, self.dy)))

    def rho(self, t: torch.Tensor) -> torch.Tensor:
        qa, qb, qc = self.qa, self.qb, self.qc
        if t.dim() > qa.dim():
            qa, qb, qc = qa[:, None], qb[:, None], qc[:, None]
        return torch.sqrt((qa * t * t + qb * t + qc).clamp_min(0.0))


def _cone_roots(ray: _Ray, alpha: torch.Tensor, beta: torch.Tensor):
    """Both parameters t where rho(t) = alpha + beta t (on the nappe alpha + beta t >= 0), inf where none."""
    a2 = ray.qa - beta * beta
    b2 = ray.qb - 2.0 * alpha * beta
    c2 = ray.qc - alpha * alpha
    disc = b2 * b2 - 4.0 * a2 * c2
    sq = torch.sqrt(disc.clamp_min(0.0))
    q = -0.5 * (b2 + torch.where(b2 >= 0, sq, -sq))  # stable: no cancellation between b2 and sq
    inf = torch.full_like(q, float("inf"))
    roots = []
    for t in (q / a2, c2 / q):
        ok = (disc >= 0) & torch.isfinite(t) & (alpha + beta * t >= 0)
        roots.append(torch.where(ok, t, inf))
    return roots


def _segment_pairs(ray: _Ray, h: torch.Tensor, t_near: torch.Tensor, t_far: torch.Tensor, n_rows: int):
    """(ray index, segment index) of every profile segment each ray's span crosses. P each."""
    last = n_rows - 2
    rows = [((h - (ray.oy + t * ray.dy)) / (2 * h) * (n_rows - 1)).floor().clamp(0, last) for t in (t_near, t_far)]
    lo, hi = torch.minimum(*rows).long(), torch.maximum(*rows).long()
    count = hi - lo + 1  # M, >= 1
    ray_idx = torch.repeat_interleave(torch.arange(count.shape[0], device=count.device), count)
    start = torch.cumsum(count, 0) - count
    seg = lo[ray_idx] + torch.arange(ray_idx.shape[0], device=count.device) - start[ray_idx]
    return ray_idx, seg


def _first(values: torch.Tensor, ray_idx: torch.Tensor, m: int) -> torch.Tensor:
    """Per-ray minimum of pair values (P) -> M, inf for rays without pairs."""
    out = torch.full((m,), float("inf"), device=values.device, dtype=values.dtype)
    return out.scatter_reduce(0, ray_idx, values, reduce="amin", include_self=True)


@torch.no_grad()
def search(origin: torch.Tensor, direction: torch.Tensor, rows: torch.Tensor, b_idx: torch.Tensor,
           h: torch.Tensor, s_near: torch.Tensor, s_far: torch.Tensor, deep: float = float("inf"),
           misses: bool = True, hits_only: bool = False) -> Found:
    """Exact first hits, mouth exits and minimisers of F = max(rho - r(y), |y| - h) along M rays, SEARCH_CHUNK
    (on a GPU GPU_SEARCH_CHUNK) rays at a time (see _search for the arguments)."""
    m = origin.shape[0]
    chunk = GPU_SEARCH_CHUNK if origin.is_cuda else SEARCH_CHUNK
    if m <= chunk:
        return _search(origin, direction, rows, b_idx, h, s_near, s_far, deep, misses, hits_only)
    parts = []
    for i in range(0, m, chunk):
        part = slice(i, i + chunk)
        parts.append(_search(origin[part], direction[part], rows, b_idx[part], h[part], s_near[part], s_far[part],
                             deep, misses, hits_only))
    return Found(*(torch.cat([getattr(f, name) for f in parts]) for name in ("s_min", "s_hit", "hit", "inner", "cap")))


def _search(origin: torch.Tensor, direction: torch.Tensor, rows: torch.Tensor, b_idx: torch.Tensor,
            h: torch.Tensor, s_near: torch.Tensor, s_far: torch.Tensor, deep: float, misses: bool,
            hits_only: bool = False) -> Found:
    """Exact first hits, mouth exits and minimisers of F = max(rho - r(y), |y| - h) along M rays.

    Args:
        origin, direction: M x 3 canonical-frame rays (direction of unit length).
        rows: B x L profile radii in object-space units (row 0 at y = +h).
        b_idx: M batch index of each ray.
        h: M half-heights in object-space units.
        s_near, s_far: M span of each ray inside the (inflated) bounding cylinder.
        deep: rays whose chord through the solid has F < -deep at its middle skip the exact minimisation of F
            (their soft silhouette is saturated): s_min is that middle point instead.
        misses: minimise F along the rays that miss too (for their soft silhouette); False skips them, for a
            caller that only needs the hits (their s_min is then the closest approach to the object's centre).
        hits_only: stop after the hits (hit, inner, cap and s_hit as always; s_min is then the middle of the first
            chord through the solid, or the entry): for a caller that needs the hard silhouette alone.

    Returns:
        Found (all M).
    """
    n_rows = rows.shape[1]
    s_c = -(origin * direction).sum(-1)
    oc = origin + s_c[:, None] * direction
    dx, dy, dz = direction.unbind(-1)
    dy = torch.where(dy.abs() < 1e-9, torch.where(dy < 0, -1e-9, 1e-9), dy)
    ray = _Ray(dx * dx + dz * dz, 2 * (oc[:, 0] * dx + oc[:, 2] * dz), oc[:, 0] ** 2 + oc[:, 2] ** 2, oc[:, 1], dy)
    ray_idx, seg = _segment_pairs(ray, h, s_near - s_c, s_far - s_c, n_rows)
    flat = rows.reshape(-1)
    pair = ray.take(ray_idx)
    base = b_idx.index_select(0, ray_idx) * n_rows + seg
    r_top, r_bot = flat.index_select(0, base), flat.index_select(0, base + 1)
    hp = h.index_select(0, ray_idx)
    y_top = hp * (1 - 2 * seg.to(hp.dtype) / (n_rows - 1))
    y_bot = hp * (1 - 2 * (seg + 1).to(hp.dtype) / (n_rows - 1))
    slope = (r_top - r_bot) / (y_top - y_bot)  # dr/dy of the frustum
    alpha = r_top + slope * (pair.oy - y_top)  # frustum radius at t = 0 ...
    beta = slope * pair.dy  # ... and its rate along the ray
    t_lo, t_hi = [(y - pair.oy) / pair.dy for y in (y_top, y_bot)]
    t_lo, t_hi = torch.minimum(t_lo, t_hi), torch.maximum(t_lo, t_hi)

    hits = _hits(ray, pair, ray_idx, alpha, beta, t_lo, t_hi, flat, b_idx, h, n_rows, -s_c)
    if hits_only:
        return Found(hits.s_min + s_c, hits.s_hit + s_c, hits.hit, hits.inner, hits.cap)
    mid = hits.s_min
    inside = hits.hit & (_implicit(ray, mid[:, None], h, flat, b_idx, n_rows)[:, 0] < -deep)
    skip = inside if misses else inside | ~hits.hit  # rays whose s_min is not minimised
    keep = (~skip.index_select(0, ray_idx)).nonzero()[:, 0]  # one nonzero for all the pair tensors
    if keep.shape[0] < ray_idx.shape[0]:
        pair = pair.take(keep)
        ray_idx, alpha, beta, t_lo, t_hi, hp = (x.index_select(0, keep) for x in (ray_idx, alpha, beta, t_lo, t_hi, hp))
    t_min = _minimiser(ray, pair, ray_idx, alpha, beta, t_lo, t_hi, hp, flat, b_idx, h, n_rows,
                       (~skip).nonzero()[:, 0])
    t_min = torch.where(inside, mid, torch.where(skip, torch.zeros_like(mid), t_min))
    s_hit = torch.where(hits.hit, hits.s_hit, t_min) + s_c
    return Found(t_min + s_c, s_hit, hits.hit, hits.inner, hits.cap)


def _hits(ray, pair, ray_idx, alpha, beta, t_lo, t_hi, flat, b_idx, h, n_rows, t_camera) -> Found:
    """Entry, mouth and visible point from the frustum quadratics and the two cap planes (t parameters); s_min holds
    the middle of the first chord through the solid (the entry where there is none)."""
    m = ray.qa.shape[0]
    inf = float("inf")
    first = []
    t_cam = t_camera.index_select(0, ray_idx)
    for t in _cone_roots(pair, alpha, beta):
        ok = (t >= t_lo) & (t <= t_hi) & (t > t_cam)
        first.append(torch.where(ok, t, torch.full_like(t, inf)))
    nearest = torch.minimum(*first)
    t_side = _first(nearest, ray_idx, m)
    caps = []
    for y_cap, r_cap in ((h, flat[b_idx * n_rows]), (-h, flat[b_idx * n_rows + n_rows - 1])):
        t = (y_cap - ray.oy) / ray.dy
        ok = (ray.rho(t) <= r_cap) & (t > t_camera)
        caps.append(torch.where(ok, t, torch.full_like(t, inf)))
    t_top, t_bottom = caps
    t_other = torch.minimum(t_side, t_bottom)
    entry = torch.minimum(t_top, t_other)
    hit = torch.isfinite(entry)
    mouth = hit & (t_top < t_other) & torch.isfinite(t_other)
    visible = torch.where(mouth, t_other, entry)
    on_cap = hit & (visible == t_bottom) & (t_bottom < t_side)
    # the next crossing after the entry closes the first chord through the solid; its middle is deep inside
    after = entry.index_select(0, ray_idx)
    t_next = _first(torch.minimum(*[torch.where(t > after, t, torch.full_like(t, inf)) for t in first]), ray_idx, m)
    for t in caps:
        t_next = torch.minimum(t_next, torch.where(t > entry, t, torch.full_like(t, inf)))
    mid = torch.where(hit & torch.isfinite(t_next), 0.5 * (entry + t_next), entry)
    return Found(mid, visible, hit, mouth, on_cap)


def _minimiser(ray, pair, ray_idx, alpha, beta, t_lo, t_hi, hp, flat, b_idx, h, n_rows, idx) -> torch.Tensor:
    """argmin_t F along each ray: exact per frustum (convex there) plus the rims' corner candidates."""
    m = ray.qa.shape[0]
    qa = pair.qa.clamp_min(1e-12)
    t_axis = -pair.qb / (2 * qa)  # closest approach to the axis
    m2 = (pair.qc - pair.qb * pair.qb / (4 * qa)).clamp_min(0.0)  # its squared distance
    # stationary point of rho(t) - (alpha + beta t): qa u / sqrt(qa u^2 + m2) = beta, u = t - t_axis
    room = qa - beta * beta
    u = torch.where(room > 0, beta * torch.sqrt(m2 / (qa * room.clamp_min(1e-20))), torch.sign(beta) * BIG)
    oy, dy = pair.oy, pair.dy
    # where the lateral term meets the cap term of the segment's half (deep hits near the caps)
    side = torch.where(oy + 0.5 * (t_lo + t_hi) * dy >= 0, 1.0, -1.0).to(alpha.dtype)  # sign of y
    # rho - (alpha + beta t) = side * y(t) - h  <=>  rho = (alpha - h + side oy) + (beta + side dy) t
    crossings = _cone_roots(pair, alpha - hp + side * oy, beta + side * dy)
    f_best = torch.full_like(ray.qa, float("inf"))
    t_best = torch.zeros_like(f_best)
    for t in [t_axis + u] + crossings:
        t = torch.where(torch.isfinite(t), t, t_lo)
        t = torch.minimum(torch.maximum(t, t_lo), t_hi)
        f = torch.maximum(pair.rho(t) - (alpha + beta * t), (oy + t * dy).abs() - hp)
        f_ray = _first(f, ray_idx, m)
        sel = (f <= f_ray.index_select(0, ray_idx)) & (f_ray < f_best).index_select(0, ray_idx)
        t_best = t_best.index_put((ray_idx[sel],), t[sel])
        f_best = torch.minimum(f_best, f_ray)
    # the rims' candidates, for the rays that still need an exact minimum (idx)
    sub, h_s, b_s = ray.take(idx), h.index_select(0, idx), b_idx.index_select(0, idx)
    t_axis = -sub.qb / (2 * sub.qa.clamp_min(1e-12))
    cand = _rim_candidates(sub, t_axis, h_s, flat, b_s, n_rows)  # M' x C
    f_cand = _implicit(sub, cand, h_s, flat, b_s, n_rows)
    k = f_cand.argmin(1, keepdim=True)
    f_rim, t_rim = f_cand.gather(1, k)[:, 0], cand.gather(1, k)[:, 0]
    better = f_rim < f_best.index_select(0, idx)
    return t_best.index_put((idx[better],), t_rim[better])


def _rim_candidates(ray, t_axis, h, flat, b_idx, n_rows) -> torch.Tensor:
    """Parameters where F's minimum may sit near the rims: the cap planes, the closest approach to the axis, and
    where the lateral and cap terms cross above/below the solid and in the end segments. M x 12."""
    r0, r1 = flat[b_idx * n_rows], flat[b_idx * n_rows + 1]
    rl, rl1 = flat[b_idx * n_rows + n_rows - 1], flat[b_idx * n_rows + n_rows - 2]
    dy_row = 2 * h / (n_rows - 1)
    s_top, s_bot = (r0 - r1) / dy_row, (rl1 - rl) / dy_row  # dr/dy in the end segments
    a_top, a_bot = r0 - s_top * h, rl + s_bot * h  # r = a + s y there
    t_top, t_bot = (h - ray.oy) / ray.dy, (-h - ray.oy) / ray.dy
    cands = [t_top, t_bot, t_axis]
    for a, s, sign in ((r0, 0.0, 1.0), (a_top, s_top, 1.0), (rl, 0.0, -1.0), (a_bot, s_bot, -1.0)):
        # rho - (a + s y) = sign * y - h  <=>  rho = (a - h) + (s + sign) y
        k = s + sign
        cands += _cone_roots(ray, a - h + k * ray.oy, k * ray.dy)
    cand = torch.stack(cands, dim=1)
    return torch.where(torch.isfinite(cand), cand, t_axis[:, None])


def _implicit(ray, t, h, flat, b_idx, n_rows) -> torch.Tensor:
    """F at parameters t (M x C) with the piecewise-linear profile (clamped beyond the caps)."""
    y = ray.oy[:, None] + t * ray.dy[:, None]
    row = ((h[:, None] - y) / (2 * h[:, None]) * (n_rows - 1)).clamp(0, n_rows - 1)
    i0 = row.floor().clamp(0, n_rows - 2)
    w = row - i0
    base = b_idx[:, None] * n_rows + i0.long()
    r = flat[base] * (1 - w) + flat[base + 1] * w
    return torch.maximum(ray.rho(t) - r, y.abs() - h[:, None])
