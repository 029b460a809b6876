"""The `radar` command runs numpy's BLAS on one thread unless the user chose otherwise, and sets it before numpy
loads (OpenBLAS reads the variable once, when it loads)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from radar_cli.blas_threads import VARIABLE

MAIN = ("import os, sys; from radar_cli.cli import main; loaded = 'numpy' in sys.modules; sys.argv = ['radar', "
        "'--version']\ntry:\n    main()\nexcept SystemExit:\n    pass\nprint(loaded, os.environ.get('{var}'))")

THREADS = ("import os, sys; from radar_cli.cli import main; sys.argv = ['radar', '--version']\ntry:\n    main()\n"
           "except SystemExit:\n    pass\nbefore = len(os.listdir('/proc/self/task'))\nimport numpy as np\n"
           "a = np.ones((300, 300)); (a @ a).sum()\nprint(len(os.listdir('/proc/self/task')) - before)")


def _run(code: str, **env: str) -> str:
    clean = {k: v for k, v in os.environ.items() if k not in (VARIABLE, "OMP_NUM_THREADS")}
    return subprocess.run([sys.executable, "-c", code.replace("{var}", VARIABLE)], capture_output=True, text=True,
                          check=True, env={**clean, **env}).stdout.strip().splitlines()[-1]  # after the version line


def test_the_command_sets_one_blas_thread_before_numpy_loads():
    assert _run(MAIN) == "False 1"


def test_a_users_choice_is_kept():
    assert _run(MAIN, **{VARIABLE: "3"}) == "False 3"


@pytest.mark.skipif(not os.path.isdir("/proc/self/task") or (os.cpu_count() or 1) < 2,
                    reason="needs Linux's /proc and two cores (OpenBLAS starts no thread on one)")
def test_numpy_then_starts_no_blas_threads():
    assert _run(THREADS) == "0"
    assert int(_run(THREADS, **{VARIABLE: "2"})) >= 1  # the check sees the threads when there are some
