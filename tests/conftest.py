"""Shared test fixtures: where the read-only real data lives (../shared beside the repo), if present.

RADAR_SHARED=DIR points the tests at another copy; RADAR_SHARED=none runs them as on a fresh clone without it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("RADAR_SHARED") or REPO_ROOT.parent / "shared")  # "none": a path that is absent


@pytest.fixture
def shared_data() -> Callable[..., Path]:
    """`shared_data("data", "real_vases")`: a path under ../shared/, skipping the test cleanly when absent."""

    def lookup(*parts: str) -> Path:
        path = SHARED.joinpath(*parts)
        if not path.exists():
            pytest.skip(f"{path} not present (real data lives beside the repo)")
        return path

    return lookup
