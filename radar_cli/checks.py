"""Argument checks for public tensor functions: shapes, dtypes and finite values, with messages that name the
argument."""

from __future__ import annotations

import torch

from radar_cli.errors import InputError


def check_shape(x: torch.Tensor, spec: str, name: str, dims: dict[str, int] | None = None) -> dict[str, int]:
    """Check that `x` matches a space-separated shape spec such as "B L" or "B 3 H W".

    Letters bind to sizes (the same letter must have the same size everywhere it appears, also across
    calls when `dims` is passed back in); digits must match exactly.

    Args:
        x: the tensor to check.
        spec: the expected shape, e.g. "B 3 H W".
        name: the argument's name, used in the error message.
        dims: sizes already bound by earlier checks (updated in place and returned).

    Returns:
        The dict of bound sizes.

    Raises:
        InputError: if `x` is not a tensor, or its shape does not match.
    """
    dims = {} if dims is None else dims
    if not isinstance(x, torch.Tensor):
        raise InputError(f"{name}: expected a tensor of shape ({spec}), got {type(x).__name__}")
    parts = spec.split()
    if x.dim() != len(parts):
        raise InputError(f"{name}: expected shape ({spec}), got {tuple(x.shape)}")
    for part, size in zip(parts, x.shape):
        if part.isdigit():
            if int(part) != size:
                raise InputError(f"{name}: expected shape ({spec}), got {tuple(x.shape)}")
        elif part in dims and dims[part] != size:
            raise InputError(f"{name}: expected shape ({spec}) with {part}={dims[part]}, got {tuple(x.shape)}")
        else:
            dims[part] = size
    return dims


def check_finite(x: torch.Tensor, name: str) -> None:
    """Raise InputError if `x` holds NaN or Inf."""
    if not torch.isfinite(x).all():
        raise InputError(f"{name}: contains NaN or Inf")


def check_range(x: torch.Tensor, lo: float, hi: float, name: str) -> None:
    """Raise InputError if `x` is not finite or any value lies outside [lo, hi]."""
    check_finite(x, name)
    if x.numel() and (x.min() < lo or x.max() > hi):
        raise InputError(f"{name}: values must lie in [{lo}, {hi}], got [{x.min().item():.4g}, {x.max().item():.4g}]")


def check_float(x: torch.Tensor, name: str) -> None:
    """Raise InputError unless `x` is a floating-point tensor."""
    if not x.is_floating_point():
        raise InputError(f"{name}: expected a floating-point tensor, got {x.dtype}")
