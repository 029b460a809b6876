"""Splitting one `radar derender` collection over processes and machines: which inputs a share owns and the
per-share failure lists (run/launch.py drives the shares).

A share owns whole batches of the single-process run (batch k goes to share k mod N); each object's files are
the same bytes as without sharding (every photo is predicted on its own, see run/batch.py). Shares meet only
through the results folder (a filesystem all machines see), so `--shard K/N` needs no network between jobs.
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence, TypeVar

from radar_cli.derender.run.inputs import Failure
from radar_cli.errors import InputError
from radar_cli.fileio import write_text

T = TypeVar("T")
SHARDS_DIR = ".shards"  # RESULTS/.shards/failures-K-of-N.csv: each share's failures, merged into failures.csv
MAX_FAILURE_BYTES = 64 * 1024 * 1024  # a share's failure list is read back; refuse absurd files


@dataclass(frozen=True)
class Shard:
    """Share `index` (0-based) of `count`."""

    index: int = 0
    count: int = 1

    def __post_init__(self) -> None:
        if self.count < 1 or not 0 <= self.index < self.count:
            raise InputError(f"--shard {self.index}/{self.count}: K must lie in 0..N-1 and N >= 1")

    @classmethod
    def parse(cls, text: str) -> "Shard":
        """'K/N' (0-based K, e.g. a SLURM array's task id) -> Shard; InputError on anything else."""
        match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", text)
        if match is None:
            raise InputError(f"--shard {text!r}: expected K/N, e.g. 0/4 (K = 0..N-1)")
        return cls(int(match.group(1)), int(match.group(2)))

    @property
    def enabled(self) -> bool:
        return self.count > 1

    def blocks(self, items: Sequence[T], size: int) -> list[list[T]]:
        """This share's batches: the run's items cut into batches of `size` in order, every N-th from K."""
        batches = [list(items[i : i + size]) for i in range(0, len(items), size)]
        return batches[self.index :: self.count]

    def failures_path(self, out: Path) -> Path:
        return out / SHARDS_DIR / f"failures-{self.index}-of-{self.count}.csv"


def write_share_failures(out: Path, shard: Shard, failures: list[Failure]) -> None:
    """Record one share's failures where the report's writer finds them."""
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(("source", "problem"))
    writer.writerows((f.source, f.problem) for f in failures)
    write_text(shard.failures_path(out), buf.getvalue())


def read_share_failures(out: Path, count: int) -> list[Failure]:
    """The failures of every share of an N-way run found under `out` (duplicates once, in share order)."""
    merged: dict[tuple[str, str], Failure] = {}
    for k in range(count):
        path = Shard(k, count).failures_path(out)
        if not path.is_file():
            continue
        if path.stat().st_size > MAX_FAILURE_BYTES:
            raise InputError(f"{path}: larger than {MAX_FAILURE_BYTES // 2**20} MB")
        rows = list(csv.reader(io.StringIO(path.read_text("utf-8"))))
        for row in rows[1:]:
            if len(row) == 2:
                merged.setdefault((row[0], row[1]), Failure(row[0], row[1]))
    return list(merged.values())
