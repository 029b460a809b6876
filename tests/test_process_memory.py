"""The memory of a process and its children together (Linux /proc)."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from radar_cli.process_memory import PeakMemory, process_tree, tree_memory_mib

pytestmark = pytest.mark.skipif(not Path("/proc/self/smaps_rollup").exists(), reason="needs Linux /proc")


def test_a_child_holding_memory_is_counted_with_its_parent() -> None:
    hold = "import time; b = bytearray(200 * 2**20); b[::4096] = b'x' * len(b[::4096]); time.sleep(3)"
    alone = tree_memory_mib(os.getpid())
    with PeakMemory() as memory:
        child = subprocess.Popen([sys.executable, "-c", hold])
        try:
            time.sleep(1.5)
            assert child.pid in process_tree(os.getpid())
            both = tree_memory_mib(os.getpid())
        finally:
            child.kill()
            child.wait()
    assert alone is not None and both is not None
    assert both[0] > alone[0] + 150 and both[1] > alone[1] + 150  # the child's 200 MiB, RSS and PSS
    assert memory.rss >= both[0] - 1 and memory.pss > alone[1] + 150
    assert tree_memory_mib(child.pid) is None
