"""Tasks for the worker-process tests (test_processes): a module of its own, found through sys.path, so that a
spawned helper can import what it is given (pytest imports test modules under names a child cannot)."""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Callable

TASK_S = 0.25


def square(task: int) -> tuple[int, int]:
    """task^2 and the process that worked it out, after TASK_S."""
    time.sleep(TASK_S)
    return task * task, os.getpid()


def square_worker(marker: Path) -> Callable[[int], tuple[int, int]]:
    """square, touching `marker` first: the helper has taken a task."""
    def work(task: int) -> tuple[int, int]:
        marker.touch()
        return square(task)
    return work


def dying_worker(marker: Path) -> Callable[[str], str]:
    """A worker that ends its process (exit code 3) at the task "die", after touching `marker`."""
    def work(task: str) -> str:
        if task == "die":
            marker.touch()
            os._exit(3)
        return f"helper {task}"
    return work
