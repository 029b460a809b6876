"""The outline of a solid of revolution in the image, in closed form: the solid is the union of its horizontal
discs, each disc projects (pinhole camera) to a filled ellipse, so the silhouette is the union of those ellipses.
Per image row its left and right ends, and per column its top and bottom ends, are the extremes over the discs of
a quadratic's roots: exact up to the sampling of the profile, differentiable in shape and pose, and far cheaper
than casting a ray per pixel (512 rows + 512 columns against every pixel of a 512 x 512 image).

Pixel coordinates here are pixel-centre indices (0 .. S-1), x to the right, rows down.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.sor.conic_lines import band, crossings, disc_winners, flat_lines, line_spans, roots, winner
from radar_cli.sor.pose import rotation_matrix, translation
from radar_cli.sor.profile import radius_at
from radar_cli.sor.solid import Solid

SUBROWS_PER_PIXEL = 0.5  # discs sampled along the axis per image row (the axis spans at most 2 image heights)


@dataclass(frozen=True)
class Outline:
    """The ends of a silhouette along every row and column of an S x S image (pixel-centre coordinates).

    Attributes:
        left, right: B x S x-extent of each row (NaN where the row misses the object).
        top, bottom: B x S y-extent of each column (NaN where the column misses the object).
    """

    left: torch.Tensor
    right: torch.Tensor
    top: torch.Tensor
    bottom: torch.Tensor


def disc_frames(solid: Solid, n_discs: int,
                camera: CameraConfig) -> torch.Tensor:
    """The maps from the unit circle to the image of n_discs discs evenly spaced along the axis (top to bottom):
    disc k's rim point at angle t is g_k (cos t, sin t, 1), in homogeneous normalised image coordinates (x right,
    y up, both tan(fov/2) = 1).

    Args:
        solid: B solids (as cast_rays). Computed in float64.

    Returns:
        B x n_discs x 3 x 3.
    """
    radius, height, pose = solid.radius, solid.height, solid.pose
    dt = torch.float64
    radius, height, pose = radius.to(dt), height.to(dt), pose.to(dt)
    v = torch.linspace(-1.0, 1.0, n_discs, dtype=dt, device=radius.device)  # -1 = top
    r = radius_at(radius, v.expand(radius.shape[0], -1)) * camera.r_max  # B x K
    y = -v[None] * height[:, None] * camera.r_max  # B x K
    rot = rotation_matrix(pose)  # B x 3 x 3
    centre = y[..., None] * rot[:, None, :, 1] + translation(pose, camera)[:, None, :]  # B x K x 3
    e1 = r[..., None] * rot[:, None, :, 0]  # the disc's x axis, scaled by its radius
    e3 = r[..., None] * rot[:, None, :, 2]
    tan = math.tan(math.radians(camera.fov_deg) / 2.0)
    scale = torch.tensor([1.0 / tan, 1.0 / tan, 1.0], dtype=dt, device=radius.device)
    return torch.stack([e1, e3, centre], dim=-1) * scale[:, None]


UNIT_CIRCLE = torch.diag(torch.tensor([1.0, 1.0, -1.0], dtype=torch.float64))  # x^2 + y^2 - 1 = 0, self-dual


def disc_conics(solid: Solid, n_discs: int,
                camera: CameraConfig) -> torch.Tensor:
    """The image conics of n_discs discs evenly spaced along the axis (top to bottom), in normalised image
    coordinates (x right, y up, both tan(fov/2) = 1): point m = (x, y, 1) is on disc k's ellipse iff m^T Q_k m = 0.

    Args:
        solid: B solids (as cast_rays). Computed in float64.

    Returns:
        B x n_discs x 3 x 3 symmetric conics, each scaled to unit norm.
    """
    return _conics(disc_frames(solid, n_discs, camera))


def _conics(g: torch.Tensor) -> torch.Tensor:
    """The unit-norm point conics of the discs whose frames are g (... x 3 x 3, disc_frames)."""
    adj = _adjugate(g)  # proportional to g^-1
    q = adj.transpose(-1, -2) @ UNIT_CIRCLE.to(adj.device) @ adj
    return q / q.flatten(-2).norm(dim=-1)[..., None, None]


def vertical_extent(solid: Solid, size: int,
                    camera: CameraConfig = CameraConfig(), n_discs: int | None = None,
                    margin: int = 3) -> tuple[torch.Tensor, torch.Tensor]:
    """The silhouette's top and bottom rows in an S x S image, as sampled by outline() (the least of its columns'
    tops and the greatest of their bottoms, pixel-centre coordinates; B each), computed only on the columns
    within `margin` of the extremes: each disc's extreme is in closed form from its dual conic g D g^T (the
    horizontal lines y = c tangent to it), which places them. Far cheaper than the full outline."""
    g = disc_frames(solid, n_discs or n_discs_for(size), camera)  # B x K x 3 x 3
    with torch.no_grad():
        dual = g @ UNIT_CIRCLE.to(g.device) @ g.transpose(-1, -2)
        low, high = _tangent_heights(dual)  # B x K normalised y, up; line (0, 1, -c) touches at dual @ (0, 1, -c)
        apex = []
        for c, k in ((high, torch.nan_to_num(high, nan=-math.inf).argmax(1)),
                     (low, torch.nan_to_num(low, nan=math.inf).argmin(1))):
            rows = torch.arange(len(k), device=k.device)
            touch = dual[rows, k, :, 1] - c[rows, k, None] * dual[rows, k, :, 2]  # B x 3
            apex.append(touch[:, 0] / touch[:, 2])
        columns = (torch.cat(apex) + 1.0) * (size / 2.0) - 0.5
        columns = columns[columns.isfinite()]
        first = max(int(columns.min().floor()) - margin, 0) if len(columns) else 0
        last = min(int(columns.max().ceil()) + margin, size - 1) if len(columns) else size - 1
        first, last = min(first, size - 1), max(last, min(first, size - 1))
    q = _conics(g)
    swap = SWAP_XY.to(q.device)
    step = 2.0 / size
    bottom, top = _row_ends(swap @ q @ swap, (1.0 / size - 1.0 + first * step, step, last - first + 1))
    to_row = lambda y: (1.0 - y) * (size / 2.0) - 0.5  # noqa: E731 (normalised y up -> pixel-centre row)
    return (to_row(_extreme(top, torch.amax, -math.inf)), to_row(_extreme(bottom, torch.amin, math.inf)))


def _tangent_heights(dual: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The lower and upper heights c of the horizontal lines y = c tangent to conics given by their duals
    (... x 3 x 3): the line l = (0, 1, -c) is tangent iff l^T dual l = dual_11 - 2 c dual_12 + c^2 dual_22 = 0."""
    return roots(dual[..., 2, 2], -dual[..., 1, 2], dual[..., 1, 1])


def _adjugate(m: torch.Tensor) -> torch.Tensor:
    """Adjugate of ... x 3 x 3 matrices (det(m) * inverse, without the division)."""
    c = torch.linalg.cross
    a, b, d = m[..., :, 0], m[..., :, 1], m[..., :, 2]
    return torch.stack([c(b, d), c(d, a), c(a, b)], dim=-2)


def n_discs_for(size: int, height_frac: float = 2.0) -> int:
    """Discs to sample for an S px image: enough that neighbouring discs' ellipses overlap at any pitch."""
    return max(64, int(math.ceil(SUBROWS_PER_PIXEL * size * height_frac)))


def _row_ends(q: torch.Tensor, lines: tuple[float, float, int]) -> tuple[torch.Tensor, torch.Tensor]:
    """Left and right ends (normalised x) of the union of the discs' ellipses along horizontal lines.

    Two parts, each exact where the other is not: the ellipses' own crossings of each line (the caps' arcs), and
    the polylines through consecutive ellipses' leftmost and rightmost points (the side contour; a disc seen
    almost edge-on is a thin line that most rows fall between). Each ellipse and each segment is evaluated, without
    gradients, only on the lines its height range spans (conic_lines), so the cost follows the area the parts
    cover, not K x N; then each line's winner is evaluated again, so the gradient's graph holds N values, not K x W.

    Args:
        q: B x K x 3 x 3 conics, discs in order along the axis. lines: (y0, dy, N): the line heights
            y0 + n dy (normalised, up), n = 0 .. N-1.

    Returns:
        (left, right), B x N each, NaN where a line misses every ellipse.
    """
    conic = tuple(q[..., i, j] for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))  # B x K each
    q00, q01, q02, q11, q12, q22 = conic
    # leftmost / rightmost points: d/dy (m^T Q m) = 0, i.e. y = a x + b on the ellipse
    a, b = -q01 / q11, -q12 / q11
    xa, xb = roots(q00 + 2 * q01 * a + q11 * a * a, q01 * b + q11 * a * b + q02 + q12 * a,
                   q11 * b * b + 2 * q12 * b + q22)  # B x K
    sides = ((xa, _on_line(xa, a, b)), (xb, _on_line(xb, a, b)))
    y0, dy, n = lines
    with torch.no_grad():
        discs = disc_winners(conic, *_tangent_heights(_adjugate(q)), sides, lines)  # (left, right), B x N
        segments = []
        for i, (x, ys) in enumerate(sides):
            seg_index, at = band(*line_spans(ys[:, :-1], ys[:, 1:], lines), lines)  # B x (K-1) x W
            values = _segment(x[:, :-1, None], x[:, 1:, None], ys[:, :-1, None], ys[:, 1:, None], at)
            segments.append(winner(values.flatten(), *flat_lines(seg_index, n), q.shape[0], n, ("amin", "amax")[i],
                                   q.shape[1] - 1))
        winners = list(zip(discs, segments))
    heights = y0 + torch.arange(n, device=q.device).to(q.dtype) * dy  # N
    ends = []
    for i, ((disc, segment), (x, ys)) in enumerate(zip(winners, sides)):
        k = disc.clamp(max=q.shape[1] - 1)
        crossing = crossings(tuple(c.gather(1, k) for c in conic), heights[None])[i]
        crossing = torch.where(disc < q.shape[1], crossing, torch.full_like(crossing, math.nan))
        k = segment.clamp(max=q.shape[1] - 2)
        side = _segment(x.gather(1, k), x.gather(1, k + 1), ys.gather(1, k), ys.gather(1, k + 1), heights[None])
        side = torch.where(segment < q.shape[1] - 1, side, torch.full_like(side, math.nan))
        ends.append(torch.fmin(crossing, side) if i == 0 else torch.fmax(crossing, side))
    return ends[0], ends[1]


def _on_line(x: torch.Tensor, a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """a x + b, NaN where x is, with no NaN in its gradient there (an ellipse seen edge-on has no leftmost point:
    a plain a x + b would send 0 x NaN back to a and poison the whole solid's gradient)."""
    found = ~x.isnan()
    return torch.where(found, a * torch.where(found, x, torch.zeros_like(x)) + b, x)


def _segment(x0: torch.Tensor, x1: torch.Tensor, y0: torch.Tensor, y1: torch.Tensor, at: torch.Tensor) -> torch.Tensor:
    """x of the segments from (x0, y0) to (x1, y1) on the lines y = at (all broadcasting), NaN off their
    y-range."""
    span = y1 - y0
    w = (at - y0) / torch.where(span.abs() > 1e-12, span, torch.full_like(span, 1e-12))
    inside = (w >= 0) & (w <= 1)
    return torch.where(inside, x0 + w * (x1 - x0), torch.full_like(w, math.nan))


def _extreme(values: torch.Tensor, reduce, fill: float) -> torch.Tensor:
    """min or max over dim 1 ignoring NaN (NaN where all are)."""
    found = ~values.isnan()
    out = reduce(torch.where(found, values, torch.full_like(values, fill)), dim=1)
    return torch.where(found.any(dim=1), out, torch.full_like(out, math.nan))


OUTLINE_CHUNK = 8
"""Solids outlined at a time: the refinement's 51 candidate pitches at 256 px held ~350 MB of float64 working
tensors at once. Each solid's outline is its own, so the result is the same in chunks."""

SWAP_XY = torch.tensor([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], dtype=torch.float64)


def outline(solid: Solid, size: int,
            camera: CameraConfig = CameraConfig(), n_discs: int | None = None) -> Outline:
    """The silhouette's ends along every row and column of an S x S image.

    Args:
        solid: B solids (see cast_rays). size: S. n_discs: discs sampled along the axis
            (default n_discs_for(size)).

    Returns:
        Outline in pixel-centre coordinates (float64).
    """
    batch = solid.radius.shape[0]
    if batch > OUTLINE_CHUNK:
        parts = [outline(solid.rows(i, i + OUTLINE_CHUNK), size, camera, n_discs)
                 for i in range(0, batch, OUTLINE_CHUNK)]
        return Outline(*(torch.cat([getattr(o, name) for o in parts]) for name in ("left", "right", "top", "bottom")))
    q = disc_conics(solid, n_discs or n_discs_for(size), camera)  # B x K x 3 x 3
    first, step = 1.0 / size - 1.0, 2.0 / size  # pixel centres, normalised
    left, right = _row_ends(q, (-first, -step, size))  # rows: normalised y = -c (up)
    swap = SWAP_XY.to(q.device)
    low, high = _row_ends(swap @ q @ swap, (first, step, size))  # columns: the same with x and y exchanged
    to_px = lambda t: (t + 1.0) * (size / 2.0) - 0.5  # noqa: E731 (normalised -> pixel-centre index)
    return Outline(to_px(left), to_px(right), to_px(-high), to_px(-low))


def row_mask(drawn: Outline) -> torch.Tensor:
    """The silhouette an outline draws, from its rows' ends: the pixels whose centres lie between a row's left and
    right end. B x S x S bool. Where every row crosses the silhouette in one run (an upright or slightly rolled
    axis; a row of a strongly rolled, waisted vessel can cross it twice and the gap counts as drawn), this is the
    ray cast's hard silhouette (render.raycast.hit_mask) but for the pixels an end passes within the discs'
    sampling of, at a fifth of its cost."""
    cols = torch.arange(drawn.left.shape[1], dtype=drawn.left.dtype, device=drawn.left.device)
    return (cols >= drawn.left[..., None]) & (cols <= drawn.right[..., None])  # NaN rows compare False


def mask_outline(mask: np.ndarray) -> Outline:
    """The ends of an S x S coverage mask (float in [0, 1] or bool) along every row and column, at sub-pixel
    precision: where the coverage crosses 0.5, linearly interpolated between pixel centres (a binary mask's
    ends fall on pixel edges). Batch of one; NaN for empty rows and columns."""
    m = np.asarray(mask, np.float64)
    left, right = _mask_ends(m)
    top, bottom = _mask_ends(m.T)
    as_t = lambda a: torch.from_numpy(a)[None]  # noqa: E731
    return Outline(as_t(left), as_t(right), as_t(top), as_t(bottom))


def _mask_ends(m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and last 0.5-crossing of each row of H x W coverage, sub-pixel (NaN for empty rows)."""
    inside = m >= 0.5
    any_in = inside.any(axis=1)
    width = m.shape[1]
    first = np.argmax(inside, axis=1)
    last = width - 1 - np.argmax(inside[:, ::-1], axis=1)
    rows = np.arange(m.shape[0])
    before = np.where(first > 0, m[rows, np.maximum(first - 1, 0)], 0.0)
    after = np.where(last < width - 1, m[rows, np.minimum(last + 1, width - 1)], 0.0)
    at_first, at_last = m[rows, first], m[rows, last]
    left = first - (at_first - 0.5) / np.maximum(at_first - before, 1e-6)
    right = last + (at_last - 0.5) / np.maximum(at_last - after, 1e-6)
    nan = np.full(m.shape[0], np.nan)
    return np.where(any_in, left, nan), np.where(any_in, right, nan)
