"""Torch's intra-op thread count, set for a block of work; independent pieces of work on a few threads."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from typing import Callable, Iterator, Sequence, TypeVar

import torch

T = TypeVar("T")
R = TypeVar("R")


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


def on_torch_threads(n: int, fn: Callable[..., R], *args) -> R:
    """fn(*args) with this thread's torch intra-op threads set to n, for a pool thread: OpenMP's thread count is
    per thread, so a pool thread would otherwise spin up every core and sum in another order than the calling
    thread (other bytes)."""
    torch.set_num_threads(n)
    return fn(*args)


def thread_map(fn: Callable[[T], R], items: Sequence[T], workers: int) -> list[R]:
    """[fn(x) for x in items], in order, on up to `workers` threads (in this thread when workers <= 1), each call
    on one torch thread (on_torch_threads). OpenCV, zlib and torch's operations release the GIL; Python between
    them does not."""
    if workers <= 1 or len(items) <= 1:
        return [fn(x) for x in items]
    with ThreadPoolExecutor(max_workers=min(workers, len(items))) as pool:
        return list(pool.map(lambda x: on_torch_threads(1, fn, x), items))
