"""Tasks spread over processes: the calling process and `helpers` spawned ones take them from one queue, so
each core runs its own interpreter (no lock between the many small tensor operations of the fits, no second
core spent handing that lock over) and a slow task holds up no other.

A helper builds its worker once from a picklable `setup` (the model and options arrive pickled), and ignores
Ctrl-C (the calling process stops it); it ends at the queue's end or when the calling process is gone. A task
whose helper ended before sending its result is handed to `lost` with the reason: nothing is dropped silently.
Results are returned in task order, whoever ran them.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import multiprocessing as mp
import queue
import signal
import sys
from typing import Callable, Sequence, TypeVar

T = TypeVar("T")
R = TypeVar("R")
POLL_S = 0.5  # how often a waiting process looks whether the others are still there
PR_SET_PDEATHSIG = 1  # Linux prctl option: the signal a process gets when its parent ends


def spread(tasks: Sequence[T], work: Callable[[T], R], setup: Callable[[], Callable[[T], R]], helpers: int,
           arrived: Callable[[R], None], lost: Callable[[T, str], R]) -> list[R]:
    """Run every task once, on this process (`work`) and on `helpers` spawned processes (each runs `setup()`'s
    worker); `arrived` sees each result as it comes, in this process.

    Returns:
        The results in task order; `lost(task, reason)` for a task whose helper ended without its result.
    """
    if helpers < 1 or len(tasks) < 2:
        return [_arrive(work(task), arrived) for task in tasks]
    ctx = mp.get_context("spawn")  # not fork: torch's thread pools and open files do not survive a fork
    todo, done = ctx.Queue(), ctx.Queue()
    for item in enumerate(tasks):
        todo.put(item)
    helpers = min(helpers, len(tasks) - 1)
    for _ in range(helpers + 1):  # one end mark for each process, this one included
        todo.put(None)
    procs = [ctx.Process(target=_helper, args=(setup, todo, done), daemon=True) for _ in range(helpers)]
    for proc in procs:
        proc.start()
    results: dict[int, R] = {}
    try:
        while (got := todo.get()) is not None:
            _collect(done, results, arrived, block=False)
            index, task = got
            results[index] = _arrive(work(task), arrived)
        while len(results) < len(tasks) and (any(p.is_alive() for p in procs) or not done.empty()):
            _collect(done, results, arrived, block=True)
        _collect(done, results, arrived, block=False)
        for proc in procs:
            if len(results) == len(tasks):  # every result is in: a helper still starting holds no task
                proc.terminate()
            proc.join(timeout=POLL_S)
        ended = ", ".join(f"exit code {p.exitcode}" for p in procs if p.exitcode not in (0, None)) or "no result"
        for index, task in enumerate(tasks):
            if index not in results:
                results[index] = _arrive(lost(task, f"its worker process ended: {ended}"), arrived)
    finally:
        for proc in procs:
            if proc.is_alive():
                proc.terminate()
            proc.join()
        todo.close()
        done.close()
    return [results[i] for i in range(len(tasks))]


def _arrive(result: R, arrived: Callable[[R], None]) -> R:
    arrived(result)
    return result


def _collect(done, results: dict, arrived: Callable, block: bool) -> None:
    """Take the helpers' results that are there (block: waiting up to POLL_S for the first)."""
    while True:
        try:
            index, result = done.get(timeout=POLL_S) if block else done.get_nowait()
        except queue.Empty:
            return
        results[index] = _arrive(result, arrived)
        block = False


def _helper(setup: Callable[[], Callable], todo, done) -> None:
    """A helper process: build the worker, then run tasks until the end mark or the calling process is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the whole group: the calling process ends us
    _end_with_parent()
    parent = mp.parent_process()
    if parent is not None and not parent.is_alive():
        return
    work = setup()
    while True:
        try:
            got = todo.get(timeout=POLL_S)
        except queue.Empty:
            if parent is not None and not parent.is_alive():
                return
            continue
        if got is None:
            return
        index, task = got
        done.put((index, work(task)))


def _end_with_parent() -> None:
    """On Linux, have the kernel kill this process when its parent ends (a killed run leaves no helper writing
    into the folder a resumed run works in); elsewhere helpers notice within POLL_S at their next task."""
    if not sys.platform.startswith("linux"):
        return
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        pass
