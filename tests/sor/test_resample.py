"""Resampling a radius column to more rows: monotone cubic through the rows, no overshoot."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from radar_cli.sor.resample import smooth_rows


def test_matches_scipy_pchip() -> None:
    interpolate = pytest.importorskip("scipy.interpolate")
    values = torch.rand(3, 32, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    out = smooth_rows(values, 128)
    reference = np.stack([interpolate.PchipInterpolator(np.arange(32), v)(np.linspace(0, 31, 128))
                          for v in values.numpy()])
    np.testing.assert_allclose(out.numpy(), reference, atol=1e-12)


def test_passes_through_the_rows_without_overshoot() -> None:
    values = torch.tensor([[0.3, 0.5, 0.5, 0.2, 0.25, 0.6, 0.6, 0.1]])
    out = smooth_rows(values, 1 + 7 * 6)  # every 6th new row is an old one
    torch.testing.assert_close(out[:, ::6], values)
    for k in range(7):  # each interval stays within its two rows' range
        piece = out[0, 6 * k : 6 * k + 7]
        lo, hi = sorted((float(values[0, k]), float(values[0, k + 1])))
        assert lo - 1e-7 <= float(piece.min()) and float(piece.max()) <= hi + 1e-7
    assert smooth_rows(values, 8) is values
    torch.testing.assert_close(smooth_rows(values[:, :2], 5), torch.linspace(0.3, 0.5, 5)[None])


def test_rejects_fewer_than_two_rows() -> None:
    with pytest.raises(ValueError, match="at least 2 rows"):
        smooth_rows(torch.ones(1, 4), 1)
