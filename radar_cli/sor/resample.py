"""Resampling a radius column to more rows along the axis with a smooth, shape-preserving curve (monotone cubic
Hermite, Fritsch-Carlson / PCHIP): C1, no overshoot, so radii stay within each pair of neighbouring rows' range."""

from __future__ import annotations

import torch

from radar_cli.checks import check_shape


def _pchip_slopes(values: torch.Tensor) -> torch.Tensor:
    """dr/drow (B x L) at the rows of an evenly spaced column, PCHIP's rule: the harmonic mean of the
    neighbouring differences inside (0 at a local extremum), the shape-preserving three-point formula at the
    ends."""
    d = values[:, 1:] - values[:, :-1]  # B x (L-1)
    a, b = d[:, :-1], d[:, 1:]
    same_sign = a * b > 0
    inner = torch.where(same_sign, 2 * a * b / torch.where(same_sign, a + b, torch.ones_like(a)),
                        torch.zeros_like(a))
    if d.shape[1] == 1:
        return torch.cat([d, d], dim=1)
    ends = []
    for d0, d1 in ((d[:, 0], d[:, 1]), (d[:, -1], d[:, -2])):
        m = (3 * d0 - d1) / 2
        m = torch.where(m * d0 <= 0, torch.zeros_like(m), m)
        m = torch.where((d0 * d1 < 0) & (m.abs() > 3 * d0.abs()), 3 * d0, m)
        ends.append(m[:, None])
    return torch.cat([ends[0], inner, ends[1]], dim=1)


def smooth_rows(values: torch.Tensor, rows: int) -> torch.Tensor:
    """Resample per-row values (B x L, rows evenly spaced from the top, row 0 and L-1 kept) to `rows` rows.

    Args:
        values: B x L, L >= 2 (a radius column).
        rows: M >= 2, the new number of rows.

    Returns:
        B x M; at M = L the input itself. The curve passes through every input row.
    """
    dims = check_shape(values, "B L", "values")
    if rows < 2 or dims["L"] < 2:
        raise ValueError(f"need at least 2 rows in and out, got {dims['L']} -> {rows}")
    if rows == dims["L"]:
        return values
    slopes = _pchip_slopes(values)  # B x L
    t = torch.linspace(0, dims["L"] - 1, rows, dtype=values.dtype, device=values.device)  # M
    i0 = t.floor().clamp(max=dims["L"] - 2).long()
    s = (t - i0.to(t.dtype))[None]  # 1 x M, position within the interval
    y0, y1 = values[:, i0], values[:, i0 + 1]
    m0, m1 = slopes[:, i0], slopes[:, i0 + 1]
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
    return h00 * y0 + h10 * m0 + h01 * y1 + h11 * m1
