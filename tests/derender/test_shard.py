"""Splitting a collection: shares own whole batches, together de-render every input exactly once, and give the
same bytes per object as one process; under torchrun (2 CPU ranks, gloo) rank 0 writes one report for all, and a
rerun finishes the share of a rank that was killed."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor
from radar_cli.derender.run.shard import Shard
from radar_cli.errors import InputError

from .conftest import SETUP, FakeModel, write_photo

REPO = Path(__file__).resolve().parents[2]
N_INPUTS = 10
EXPORT = ExportConfig(views=0, view_size=32)


def object_files(root: Path) -> dict[str, bytes]:
    """Every file of every object folder (relative path -> bytes); the report's own files are left out."""
    return {str(p.relative_to(root)): p.read_bytes() for d in sorted(root.iterdir())
            if d.is_dir() and not d.name.startswith(".") for p in sorted(d.rglob("*")) if p.is_file()}


def summary_objects(root: Path) -> list[str]:
    with open(root / "summary.csv", newline="") as f:
        return [row["object"] for row in csv.DictReader(f)]


@pytest.fixture(scope="module")
def photos(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("photos")
    for k in range(N_INPUTS):
        write_photo(folder / f"vase_{k:02d}.png", k, (80, 96))
    return folder


def test_parse_and_blocks() -> None:
    assert Shard.parse("1/4") == Shard(1, 4) and Shard.parse(" 0 / 1 ") == Shard()
    for bad in ("4/4", "-1/2", "1", "a/b", "0/0"):
        with pytest.raises(InputError, match="--shard"):
            Shard.parse(bad)
    items = list(range(10))
    shares = [Shard(k, 3).blocks(items, 2) for k in range(3)]
    assert shares == [[[0, 1], [6, 7]], [[2, 3], [8, 9]], [[4, 5]]]
    assert sorted(i for s in shares for b in s for i in b) == items


@pytest.mark.slow
def test_shares_together_equal_one_process(photos: Path, tmp_path: Path) -> None:
    """Two --shard runs into one folder: every input once, one merged report, the same bytes per object."""
    predictor = Predictor(FakeModel(), SETUP, "fake-model", "cpu")
    bad = tmp_path / "notes.txt"
    bad.write_text("not an image")
    single = derender([photos, bad], predictor, DerenderOptions(out=tmp_path / "one", batch_size=3, export=EXPORT))
    shares = [derender([photos, bad], predictor, DerenderOptions(out=tmp_path / "two", batch_size=3, export=EXPORT,
                                                                  shard=Shard(k, 2))) for k in range(2)]
    assert sorted(shares[0].done + shares[1].done) == sorted(single.done) and len(single.done) == N_INPUTS
    assert not set(shares[0].done) & set(shares[1].done)
    assert object_files(tmp_path / "two") == object_files(tmp_path / "one")
    assert summary_objects(tmp_path / "two") == summary_objects(tmp_path / "one")
    failures = (tmp_path / "two" / "failures.csv").read_text().splitlines()
    assert len(failures) == 2 and "notes.txt" in failures[1]  # the input error once, though both shares saw it


@pytest.mark.slow
def test_rerun_redoes_a_half_written_object_to_the_same_bytes(photos: Path, tmp_path: Path) -> None:
    """What a killed process leaves (no material.json, a temporary file mid-rename) is redone and cleaned."""
    predictor = Predictor(FakeModel(), SETUP, "fake-model", "cpu")
    options = DerenderOptions(out=tmp_path / "out", batch_size=3, export=EXPORT)
    derender([photos], predictor, options)
    before = object_files(tmp_path / "out")
    folder = tmp_path / "out" / "vase_04"
    (folder / "material.json").unlink()
    (folder / ".albedo.png.x1y2z3w4.tmp.png").write_bytes(b"half")  # mkstemp: 8 random characters
    summary = derender([photos], predictor, options)
    assert summary.done == ["vase_04"] and len(summary.skipped) == N_INPUTS - 1
    assert object_files(tmp_path / "out") == before


def test_cli_rejects_a_bad_shard(photos: Path, tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["derender", str(photos), "--out", str(tmp_path / "o"), "--shard", "2/2"])
    assert result.exit_code == 2 and "--shard" in result.output


def _derender_cmd(photos: Path, out: Path, nproc: int) -> list[str]:
    args = ["-m", "radar_cli", "derender", str(photos), "--out", str(out), "--views", "0", "--view-size", "32",
            "--batch-size", "2", "--workers", "1", "--device", "cpu", "--refine", "none"]
    if nproc == 1:
        return [sys.executable, *args]
    return [sys.executable, "-m", "torch.distributed.run", "--standalone", f"--nproc_per_node={nproc}", *args]


def _env(scratch: Path) -> dict[str, str]:
    """The subprocess's environment: one thread, this checkout, and temporary files (torchrun's own log folders)
    under `scratch`, not left in the system's."""
    return dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=str(REPO), TMPDIR=str(scratch))


def _run(cmd: list[str], scratch: Path) -> subprocess.CompletedProcess:
    """`cmd` run to its end in `_env(scratch)`, its output kept."""
    return subprocess.run(cmd, env=_env(scratch), capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def single_run(photos: Path, tmp_path_factory) -> Path:
    """The bundled model over the inputs in one process: the reference bytes."""
    out = tmp_path_factory.mktemp("single") / "out"
    done = _run(_derender_cmd(photos, out, 1), out.parent)
    assert done.returncode == 0, done.stderr[-3000:]
    return out


@pytest.mark.slow
def test_torchrun_two_gloo_ranks_match_one_process(photos: Path, single_run: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = _run(_derender_cmd(photos, out, 2), tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    assert summary_objects(out) == [f"vase_{k:02d}" for k in range(N_INPUTS)]  # each once, one merged summary
    assert (out / "failures.csv").read_text().splitlines() == ["source,problem"]
    assert (out / "index.html").is_file() and (out / ".gallery" / "data.js").is_file()
    assert object_files(out) == object_files(single_run)  # the same bytes per object
    # rank 0 alone prints the summary, of both ranks' work (rank 0 took batches 0, 2, 4 and rank 1 batches 1, 3)
    lines = [line for line in done.stdout.splitlines() if "de-rendered" in line]
    assert len(lines) == 1 and lines[0].startswith("10 de-rendered, 0 skipped"), done.stdout


def _worker_pid(parent: int, rank: str) -> int | None:
    """The pid of torchrun's worker with RANK=`rank` (a child of its agent `parent`), if started."""
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            environ = (entry / "environ").read_bytes().split(b"\0")
        except OSError:
            continue
        if int(stat[1]) == parent and f"RANK={rank}".encode() in environ:
            return int(entry.name)
    return None


@pytest.mark.skipif(not Path("/proc/self/environ").is_file(), reason="finds torchrun's workers through /proc")
@pytest.mark.slow
def test_a_killed_rank_is_finished_by_rerunning(photos: Path, single_run: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"
    agent = subprocess.Popen(_derender_cmd(photos, out, 2), env=_env(tmp_path), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    share1 = [f"vase_{k:02d}" for k in (2, 3, 6, 7)]  # rank 1's batches of two: the 2nd and the 4th
    deadline, killed = time.monotonic() + 240, False
    while time.monotonic() < deadline and agent.poll() is None:
        pid = _worker_pid(agent.pid, "1")
        if pid is not None and (out / share1[0] / "material.json").is_file():
            os.kill(pid, signal.SIGKILL)
            killed = True
            break
        time.sleep(0.02)
    agent.communicate(timeout=240)
    assert killed and agent.returncode != 0
    unfinished = [n for n in share1 if not (out / n / "material.json").is_file()]
    assert unfinished, "rank 1 finished its share before it could be killed"
    done = _run(_derender_cmd(photos, out, 2), tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    assert summary_objects(out) == [f"vase_{k:02d}" for k in range(N_INPUTS)]
    assert object_files(out) == object_files(single_run)


@pytest.mark.slow
def test_torchrun_refuses_a_shard_option(photos: Path, tmp_path: Path) -> None:
    cmd = _derender_cmd(photos, tmp_path / "out", 2) + ["--shard", "0/2"]
    done = _run(cmd, tmp_path)
    assert done.returncode != 0 and "--shard cannot be combined with torchrun" in done.stderr
