"""Argument checks name the argument and the expected shape."""

import pytest
import torch

from radar_cli.checks import check_finite, check_float, check_range, check_shape
from radar_cli.errors import InputError


def test_check_shape_binds_letters():
    dims = check_shape(torch.zeros(2, 3, 8, 8), "B 3 H W", "image")
    assert dims == {"B": 2, "H": 8, "W": 8}
    check_shape(torch.zeros(2, 8, 8), "B H W", "mask", dims)
    with pytest.raises(InputError, match=r"mask: expected shape \(B H W\) with B=2"):
        check_shape(torch.zeros(3, 8, 8), "B H W", "mask", dims)


@pytest.mark.parametrize("shape", [(2, 4, 8, 8), (2, 3, 8), (3,)])
def test_check_shape_rejects(shape):
    with pytest.raises(InputError, match=r"image: expected shape \(B 3 H W\), got"):
        check_shape(torch.zeros(*shape), "B 3 H W", "image")


def test_check_shape_non_tensor():
    with pytest.raises(InputError, match="image: expected a tensor"):
        check_shape([1, 2], "B", "image")


def test_values():
    with pytest.raises(InputError, match="x: contains NaN"):
        check_finite(torch.tensor([1.0, float("nan")]), "x")
    with pytest.raises(InputError, match=r"r: values must lie in \[0, 1\]"):
        check_range(torch.tensor([0.5, 1.5]), 0, 1, "r")
    with pytest.raises(InputError, match="expected a floating-point tensor"):
        check_float(torch.tensor([1, 2]), "n")
    check_range(torch.tensor([0.0, 1.0]), 0, 1, "ok")
