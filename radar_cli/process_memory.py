"""The memory of a process and the worker processes it started, together (Linux /proc; zeros elsewhere): RSS
counts the pages they share (torch's libraries) once in each process, PSS shares them out, so PSS is what they
take from the machine."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path


def process_tree(pid: int) -> list[int]:
    """pid and its descendants (Linux /proc; just pid elsewhere)."""
    try:
        children = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
    except OSError:
        return [pid]
    return [pid] + [p for child in children for p in process_tree(int(child))]


def proc_kib(path: str, *keys: str) -> list[int]:
    """The KiB figures after each of `keys` in a /proc file, read once (0 for a key it lacks or a file gone)."""
    found = dict.fromkeys(keys, 0)
    try:
        for line in Path(path).read_text().splitlines():
            key = line.split(maxsplit=1)[0] if line else ""
            if key in found:
                found[key] = int(line.split()[1])
    except (OSError, ValueError, IndexError):
        pass
    return [found[key] for key in keys]


def _reset_peak() -> None:
    """Start this process's VmHWM afresh (Linux >= 4.0: "5" to clear_refs), so the peak is the block's, not the
    one of whatever the process did before it; a no-op where that is refused."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass


class PeakMemory:
    """The memory of this process and its workers together while the block runs: `rss`, the sum of each
    process's own peak resident set (the kernel's VmHWM, read every RSS_S: no peak is missed, and the sum bounds
    the processes' peak together from above), and `pss`, the peak of their proportional set sizes summed (read
    every PSS_S: smaps_rollup walks a process's whole memory map, too costly to read often), MiB. This process's
    own peak starts at the block's start; its workers start within it."""

    RSS_S, PSS_S = 0.1, 1.0

    def __enter__(self) -> "PeakMemory":
        _reset_peak()
        self.hwm: dict[int, int] = {}
        self.pss = 0.0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._sample, daemon=True)
        self.thread.start()
        return self

    def _sample(self) -> None:
        last_pss = 0.0
        while not self.stop.wait(self.RSS_S):
            pids = process_tree(os.getpid())
            for pid in pids:
                self.hwm[pid] = max(self.hwm.get(pid, 0), proc_kib(f"/proc/{pid}/status", "VmHWM:")[0])
            if time.monotonic() - last_pss >= self.PSS_S:
                last_pss = time.monotonic()
                self.pss = max(self.pss, sum(proc_kib(f"/proc/{pid}/smaps_rollup", "Pss:")[0] for pid in pids) / 1024)

    @property
    def rss(self) -> float:
        return sum(self.hwm.values()) / 1024

    def __exit__(self, *exc: object) -> None:
        self.stop.set()
        self.thread.join()


def tree_memory_mib(pid: int) -> tuple[float, float] | None:
    """(RSS, PSS) now of pid and its descendants together, MiB; None when pid has ended."""
    if not Path(f"/proc/{pid}").exists():
        return None
    rss, pss = (sum(values) / 1024 for values in zip(*(proc_kib(f"/proc/{p}/smaps_rollup", "Rss:", "Pss:")
                                                       for p in process_tree(pid))))
    return rss, pss
