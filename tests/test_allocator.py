"""The malloc tuning applies where glibc is present and is safe to call twice."""

from __future__ import annotations

import platform

from radar_cli.allocator import keep_freed_memory


def test_keep_freed_memory_applies_on_glibc_and_is_idempotent():
    applied = keep_freed_memory()
    assert keep_freed_memory() == applied
    if platform.system() == "Linux" and platform.libc_ver()[0] == "glibc":
        assert applied
