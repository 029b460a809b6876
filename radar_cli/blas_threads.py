"""numpy's BLAS on one thread: set by the `radar` command before any of its commands imports numpy.

radar runs its objects side by side (`--workers` threads, worker processes) and its numpy matrices are small
(backdrop fits, least squares over a few hundred rows), so OpenBLAS's own threads (as numpy's wheels ship it) only
spin on the cores the other workers need. 24 photos at 512 px on 2 cores, `radar derender` with 2 workers: 76 ->
64-66 CPU s and 41 -> 35 s in the run, the same bytes (docs/performance.md).
"""

from __future__ import annotations

import os

VARIABLE = "OPENBLAS_NUM_THREADS"
"""Read by OpenBLAS when it loads, in this process and in the processes it starts (spawned pools)."""


def single_threaded_blas() -> bool:
    """One BLAS thread for this process and its children, unless the user set VARIABLE; True if set here. Takes
    effect only before numpy is first imported."""
    if VARIABLE in os.environ:
        return False
    os.environ[VARIABLE] = "1"
    return True
