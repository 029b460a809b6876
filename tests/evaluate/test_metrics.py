"""The paper's metrics on tiny arrays with hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from radar_cli.errors import InputError
from radar_cli.evaluate import metrics


def test_scale_invariant_mse_ignores_scale():
    gt = np.array([[[0.2, 0.4, 0.1], [0.5, 0.3, 0.9]]])  # 1 x 2 x 3
    assert metrics.scale_invariant_mse(gt * 0.25, gt) == pytest.approx(0.0, abs=1e-15)


def test_scale_invariant_mse_hand_computed():
    pred = np.array([[1.0, 1.0, 5.0]])  # 1 x 3, one channel
    gt = np.array([[1.0, 3.0, 0.0]])
    mask = np.array([[True, True, False]])
    # best scale a = (1*1 + 1*3) / (1 + 1) = 2; errors (2-1)^2 = 1 and (2-3)^2 = 1 -> mean 1
    assert metrics.scale_invariant_mse(pred, gt, mask) == pytest.approx(1.0)
    # without the mask: a = (1 + 3 + 0) / (1 + 1 + 25) = 4/27
    a = 4 / 27
    expected = ((a - 1) ** 2 + (a - 3) ** 2 + (5 * a) ** 2) / 3
    assert metrics.scale_invariant_mse(pred, gt) == pytest.approx(expected)


def test_scale_invariant_mse_of_zero_prediction_is_mean_square_truth():
    gt = np.array([[0.5, 1.0]])
    assert metrics.scale_invariant_mse(np.zeros_like(gt), gt) == pytest.approx((0.25 + 1.0) / 2)


def test_scale_invariant_mse_errors():
    with pytest.raises(InputError, match="does not match"):
        metrics.scale_invariant_mse(np.zeros((2, 2)), np.zeros((2, 3)))
    with pytest.raises(InputError, match="empty"):
        metrics.scale_invariant_mse(np.ones((2, 2)), np.ones((2, 2)), np.zeros((2, 2), bool))


def test_angular_error_hand_computed():
    t = math.radians(30)
    gt = np.array([[[0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]]])  # 1 x 3 x 3
    pred = np.array([[[math.sin(t), 0.0, -math.cos(t)], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]]])  # 30, 90, 90 deg
    mask = np.array([[True, True, False]])
    assert metrics.angular_error_deg(pred, gt, mask) == pytest.approx((30 + 90) / 2)
    assert metrics.angular_error_deg(gt, gt, np.ones((1, 3), bool)) == pytest.approx(0.0, abs=1e-6)


def test_normals_decode_from_png_convention():
    img = np.array([[[255, 128, 0]]], dtype=np.uint8)
    assert metrics.decode_normals(img)[0, 0] == pytest.approx([1.0, 128 / 255 * 2 - 1, -1.0])


def test_front_half_is_the_middle_half_of_the_columns():
    env = np.arange(16, dtype=float).reshape(2, 8)
    assert metrics.front_half(env).tolist() == [[2, 3, 4, 5], [10, 11, 12, 13]]


def test_env_error_uses_only_the_front_half_and_is_scale_invariant():
    gt = np.zeros((2, 8))
    gt[:, 3] = 1.0
    pred = 3.0 * gt
    pred[:, 0] = 50.0  # behind the object: not scored
    assert metrics.env_error(pred, gt) == pytest.approx(0.0)
    flat = np.ones((2, 8))  # a = 2 / 8 over the front half: errors (0.25-1)^2 twice, 0.25^2 six times, / 8
    assert metrics.env_error(flat, gt) == pytest.approx((2 * 0.75**2 + 6 * 0.25**2) / 8)
    # a prediction at another resolution is resized to the truth's first
    assert metrics.env_error(np.ones((4, 16)), np.ones((2, 8))) == pytest.approx(0.0, abs=1e-12)


def test_abs_error_and_mean_std():
    assert metrics.abs_error(12.5, 10.0) == 2.5 and metrics.abs_error(10.0, 12.5) == 2.5
    assert metrics.mean_std([1.0, 3.0]) == (2.0, 1.0)
    assert all(math.isnan(v) for v in metrics.mean_std([]))
