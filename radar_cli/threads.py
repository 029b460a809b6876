"""Torch's intra-op thread count, set for a block of work."""

from __future__ import annotations

from contextlib import contextmanager
from typing import Iterator

import torch


@contextmanager
def torch_threads(n: int) -> Iterator[None]:
    """Run a block with `n` torch intra-op threads (n <= 0: unchanged), then restore the previous setting.

    On a shared machine fewer threads than cores is often faster: OpenMP threads spin while they wait.
    """
    before = torch.get_num_threads()
    if n > 0:
        torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)
