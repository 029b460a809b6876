"""README's command blocks run as written: every ```bash block not marked `<!-- readme-test: skip (why) -->` runs
in order in a scratch folder holding the checkout's examples/ and pipelines/, with `make install` standing for an
installed radar (a `.venv/bin/radar` and a `radar` that run this checkout)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"(?:(<!-- readme-test: skip \([^)]*\) -->)\n)?```(?:bash|sh)\n(.*?)```", re.S)
SHIM = '#!/bin/sh\nexec "{python}" -m radar_cli "$@"\n'
PRELUDE = ('set -euo pipefail\n'
           'make() { [ "$*" = install ] || { echo "make $*: not run by this test" >&2; return 1; }; }\n')


def blocks() -> list[tuple[bool, str]]:
    """(skipped, commands) of every bash block of README.md, in order."""
    return [(bool(skip), body) for skip, body in BLOCK.findall((REPO / "README.md").read_text(encoding="utf-8"))]


def test_readme_blocks_are_found_and_the_network_ones_marked() -> None:
    found = blocks()
    assert len(found) >= 4 and any(not skip for skip, _ in found)
    for skip, body in found:
        if "radar fetch" in body or "make demo" in body:
            assert skip, body  # network (PyPI, the Met API) or hours of training


@pytest.mark.slow
def test_readme_commands_run_as_written(tmp_path: Path) -> None:
    for name in ("examples", "pipelines"):
        (tmp_path / name).symlink_to(REPO / name)
    bin_dir = tmp_path / ".venv" / "bin"
    bin_dir.mkdir(parents=True)
    (bin_dir / "radar").write_text(SHIM.format(python=sys.executable))
    (bin_dir / "radar").chmod(0o755)
    env = dict(os.environ, PYTHONPATH=str(REPO), OMP_NUM_THREADS="1", PATH=f"{bin_dir}:{os.environ['PATH']}")
    for skip, body in blocks():
        if skip:
            continue
        done = subprocess.run(["bash", "-c", PRELUDE + body], cwd=tmp_path, env=env, capture_output=True, text=True,
                              timeout=600)
        assert done.returncode == 0, f"{body}\n{done.stderr[-3000:]}"
    assert (tmp_path / "relit.png").is_file() and (tmp_path / "relit_sunset.png").is_file()
