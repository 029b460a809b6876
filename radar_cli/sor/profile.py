"""The radius column r (B x L) and half-height h (B): interpolation along the axis and argument checks.

Conventions used everywhere in radar:
- sizes are fractions of CameraConfig.r_max (the half-extent of the view at the object);
- the profile spans y in [-h, h] * r_max; row 0 of the radius column is the TOP (y = +h), row L-1 the bottom;
- the axial texture coordinate v in [-1, 1] runs top (-1) to bottom (+1), the grid_sample convention for rows.
"""

from __future__ import annotations

import torch

from radar_cli.checks import check_finite, check_float, check_range, check_shape


def rescale(x: torch.Tensor, lo: float, hi: float) -> torch.Tensor:
    """Map x in [0, 1] (a sigmoid output) linearly to [lo, hi]."""
    return lo + (hi - lo) * x


def check_sor(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor) -> dict[str, int]:
    """Validate SoR parameters at a public boundary.

    Args:
        radius: B x L radius column, fractions of r_max, in (0, 1.5].
        height: B half-heights, fractions of r_max, in (0, 1.5].
        pose: B x 4 (pitch deg, roll deg, tx, ty) with angles in [-90, 90] and translations in [-1, 1].

    Returns:
        Bound sizes {"B": ..., "L": ...}.
    """
    dims = check_shape(radius, "B L", "radius")
    check_shape(height, "B", "height", dims)
    check_shape(pose, "B 4", "pose", dims)
    for t, n in ((radius, "radius"), (height, "height"), (pose, "pose")):
        check_float(t, n)
    if dims["L"] < 2:
        raise_l = f"radius: need at least 2 rows, got {dims['L']}"
        from radar_cli.errors import InputError

        raise InputError(raise_l)
    check_range(radius, 1e-4, 1.5, "radius")
    check_range(height, 1e-3, 1.5, "height")
    check_range(pose[:, :2], -90.0, 90.0, "pose[:, :2] (pitch, roll in degrees)")
    check_range(pose[:, 2:], -1.0, 1.0, "pose[:, 2:] (tx, ty as fractions of r_max)")
    check_finite(pose, "pose")
    return dims


def row_coordinate(v: torch.Tensor, n_rows: int) -> torch.Tensor:
    """Fractional row index in [0, L-1] of axial coordinate v in [-1, 1] (clamped)."""
    return ((v.clamp(-1.0, 1.0) + 1.0) * 0.5) * (n_rows - 1)


def lerp_rows(values: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Linearly interpolate per-row values (B x L) at axial coordinates v (B x N) -> B x N."""
    n_rows = values.shape[1]
    t = row_coordinate(v, n_rows)
    i0 = t.detach().floor().clamp(0, n_rows - 2).long()
    w = t - i0.to(t.dtype)
    a = torch.gather(values, 1, i0)
    b = torch.gather(values, 1, i0 + 1)
    return a + (b - a) * w


def radius_at(radius: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Piecewise-linear radius r(v).

    Args:
        radius: B x L radius column.
        v: B x N axial coordinates in [-1, 1] (clamped), -1 = top.

    Returns:
        B x N radii, same units as `radius`.
    """
    return lerp_rows(radius, v)


def row_slopes(radius: torch.Tensor, height: torch.Tensor) -> torch.Tensor:
    """dr/dy at each row (B x L), central differences inside, one-sided at the ends.

    y grows upwards while rows grow downwards, so the row spacing in y is -2h / (L - 1).
    """
    n_rows = radius.shape[1]
    dy = -2.0 * height[:, None] / (n_rows - 1)  # B x 1
    diff = radius[:, 1:] - radius[:, :-1]  # B x (L-1)
    central = torch.cat([diff[:, :1], 0.5 * (diff[:, 1:] + diff[:, :-1]), diff[:, -1:]], dim=1)
    return central / dy


def slope_at(radius: torch.Tensor, height: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Smoothly interpolated dr/dy at axial coordinates v (B x N): gives smooth shading normals."""
    return lerp_rows(row_slopes(radius, height), v)
