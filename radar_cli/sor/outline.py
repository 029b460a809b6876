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
from radar_cli.sor.pose import rotation_matrix, translation
from radar_cli.sor.profile import radius_at

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


def disc_conics(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, n_discs: int,
                camera: CameraConfig) -> torch.Tensor:
    """The image conics of n_discs discs evenly spaced along the axis (top to bottom), in normalised image
    coordinates (x right, y up, both tan(fov/2) = 1): point m = (x, y, 1) is on disc k's ellipse iff m^T Q_k m = 0.

    Args:
        radius: B x L radius column; height: B; pose: B x 4 (as cast_rays). Computed in float64.

    Returns:
        B x n_discs x 3 x 3 symmetric conics, each scaled to unit norm.
    """
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
    g = torch.stack([e1, e3, centre], dim=-1) * scale[:, None]  # B x K x 3 x 3: (cos, sin, 1) -> image
    adj = _adjugate(g)  # proportional to g^-1
    q = adj.transpose(-1, -2) @ torch.diag(torch.tensor([1.0, 1.0, -1.0], dtype=dt, device=radius.device)) @ adj
    return q / q.flatten(-2).norm(dim=-1)[..., None, None]


def _adjugate(m: torch.Tensor) -> torch.Tensor:
    """Adjugate of ... x 3 x 3 matrices (det(m) * inverse, without the division)."""
    c = torch.linalg.cross
    a, b, d = m[..., :, 0], m[..., :, 1], m[..., :, 2]
    return torch.stack([c(b, d), c(d, a), c(a, b)], dim=-2)


def n_discs_for(size: int, height_frac: float = 2.0) -> int:
    """Discs to sample for an S px image: enough that neighbouring discs' ellipses overlap at any pitch."""
    return max(64, int(math.ceil(SUBROWS_PER_PIXEL * size * height_frac)))


def _row_ends(q: torch.Tensor, y: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Left and right ends (normalised x) of the union of the discs' ellipses along horizontal lines.

    Two parts, each exact where the other is not: the ellipses' own crossings of each line (the caps' arcs), and
    the polylines through consecutive ellipses' leftmost and rightmost points (the side contour; a disc seen
    almost edge-on is a thin line that most rows fall between).

    Args:
        q: B x K x 3 x 3 conics, discs in order along the axis. y: N line heights (normalised, up).

    Returns:
        (left, right), B x N each, NaN where a line misses every ellipse.
    """
    q00, q01, q02 = q[..., 0, 0], q[..., 0, 1], q[..., 0, 2]
    q11, q12, q22 = q[..., 1, 1], q[..., 1, 2], q[..., 2, 2]
    y_ = y[None, None, :]
    lo, hi = roots(q00[..., None], (q01[..., None] * y_ + q02[..., None]),
                    q11[..., None] * y_ * y_ + 2 * q12[..., None] * y_ + q22[..., None])  # B x K x N
    # leftmost / rightmost points: d/dy (m^T Q m) = 0, i.e. y = a x + b on the ellipse
    a, b = -q01 / q11, -q12 / q11
    xa, xb = roots(q00 + 2 * q01 * a + q11 * a * a, q01 * b + q11 * a * b + q02 + q12 * a,
                    q11 * b * b + 2 * q12 * b + q22)  # B x K
    left = torch.cat([lo, _polyline(xa, a * xa + b, y)], dim=1)
    right = torch.cat([hi, _polyline(xb, a * xb + b, y)], dim=1)
    return _extreme(left, torch.amin, math.inf), _extreme(right, torch.amax, -math.inf)


def roots(qa: torch.Tensor, qb: torch.Tensor, qc: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The smaller and larger real root of qa t^2 + 2 qb t + qc = 0 (NaN where there is none)."""
    disc = qb * qb - qa * qc
    real = (disc > 0) & (qa.abs() > 0)
    root = torch.sqrt(torch.where(real, disc, torch.ones_like(disc)))
    inv = 1.0 / torch.where(real, qa, torch.ones_like(qa))
    t1, t2 = (-qb - root) * inv, (-qb + root) * inv
    nan = torch.full_like(t1, math.nan)
    return torch.where(real, torch.minimum(t1, t2), nan), torch.where(real, torch.maximum(t1, t2), nan)


def _polyline(x: torch.Tensor, y: torch.Tensor, at: torch.Tensor) -> torch.Tensor:
    """x of the polylines through B x K points (x, y), in order, on the lines y = at (N): B x (K-1) x N, NaN
    off each segment's y-range."""
    x0, x1, y0, y1 = x[:, :-1, None], x[:, 1:, None], y[:, :-1, None], y[:, 1:, None]
    at = at[None, None, :]
    span = y1 - y0
    w = (at - y0) / torch.where(span.abs() > 1e-12, span, torch.full_like(span, 1e-12))
    inside = (w >= 0) & (w <= 1)
    return torch.where(inside, x0 + w * (x1 - x0), torch.full_like(w, math.nan))


def _extreme(values: torch.Tensor, reduce, fill: float) -> torch.Tensor:
    """min or max over dim 1 ignoring NaN (NaN where all are)."""
    found = ~values.isnan()
    out = reduce(torch.where(found, values, torch.full_like(values, fill)), dim=1)
    return torch.where(found.any(dim=1), out, torch.full_like(out, math.nan))


SWAP_XY = torch.tensor([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], dtype=torch.float64)


def outline(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, size: int,
            camera: CameraConfig = CameraConfig(), n_discs: int | None = None) -> Outline:
    """The silhouette's ends along every row and column of an S x S image.

    Args:
        radius: B x L; height: B; pose: B x 4 (see cast_rays). size: S. n_discs: discs sampled along the axis
            (default n_discs_for(size)).

    Returns:
        Outline in pixel-centre coordinates (float64).
    """
    q = disc_conics(radius, height, pose, n_discs or n_discs_for(size), camera)  # B x K x 3 x 3
    c = (torch.arange(size, dtype=q.dtype, device=q.device) + 0.5) * (2.0 / size) - 1.0  # pixel centres
    left, right = _row_ends(q, -c)  # rows: normalised y = -c (up)
    swap = SWAP_XY.to(q.device)
    low, high = _row_ends(swap @ q @ swap, c)  # columns: the same with x and y exchanged
    to_px = lambda t: (t + 1.0) * (size / 2.0) - 0.5  # noqa: E731 (normalised -> pixel-centre index)
    return Outline(to_px(left), to_px(right), to_px(-high), to_px(-low))


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
