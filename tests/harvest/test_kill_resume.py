"""SIGKILL `radar fetch` mid-harvest (twice), rerun, and compare with an uninterrupted run."""

from __future__ import annotations

import hashlib
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
# The `fetch` command module loaded by path: importing radar_cli.cli would import every other subcommand
# (torch included, seconds per process on 2 busy cores) for nothing.
# Ctrl-C's default handler restored first: a child inherits an ignored SIGINT from its parent (as some runners
# and earlier tests leave it), and Python then never raises KeyboardInterrupt.
FETCH = ("import signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
         "import importlib.util as u; s = u.spec_from_file_location('fetch', 'radar_cli/cli/fetch.py'); "
         "m = u.module_from_spec(s); s.loader.exec_module(m); m.fetch()")
N = 40


def command(met_server, out: Path) -> list[str]:
    return [sys.executable, "-c", FETCH, "--out", str(out), "--api-url", met_server.api_url, "--rate", "0",
            "--no-progress", "--timeout", "10"]


def kill_when(met_server, out: Path, path_prefix: str, count: int) -> None:
    """Start a harvest and SIGKILL it once `count` requests to `path_prefix` were served."""
    proc = subprocess.Popen(command(met_server, out), cwd=REPO, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 30
        while sum(p.startswith(path_prefix) for p in met_server.log) < count:
            assert proc.poll() is None, "the harvest finished before it could be killed"
            assert time.monotonic() < deadline
            time.sleep(0.005)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL


def snapshot(out: Path) -> tuple[list[tuple], dict[str, str]]:
    """Catalog rows (without timestamps) and every file's sha256."""
    db = sqlite3.connect(out / "catalog.sqlite")
    assert db.execute("PRAGMA integrity_check").fetchone() == ("ok",)
    db.row_factory = sqlite3.Row
    rows = [tuple(v for k, v in dict(r).items() if k != "updated_at")
            for r in db.execute("SELECT * FROM objects ORDER BY object_id")]
    db.close()
    files = {p.relative_to(out).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
             for p in sorted((out / "met").iterdir())}
    return rows, files


def test_sigkill_then_resume_equals_uninterrupted_run(met_server, tmp_path):
    for i in range(1, N + 1):
        met_server.add(1000 + i, kind="not_pd" if i % 10 == 0 else "pd_cover")
    met_server.delay = 0.01  # ~1 s of requests: room to kill mid-stage
    killed = tmp_path / "killed"
    kill_when(met_server, killed, "/api/v1/objects/", 12)  # during the records stage
    met_server.log.clear()
    kill_when(met_server, killed, "/images/", 9)  # during the images stage
    met_server.delay = 0.0
    resumed = subprocess.run(command(met_server, killed), cwd=REPO, capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert "have 36 images" in resumed.stdout and "not_public_domain 4" in resumed.stdout
    clean = tmp_path / "clean"
    assert subprocess.run(command(met_server, clean), cwd=REPO, capture_output=True).returncode == 0

    rows, files = snapshot(killed)
    assert (rows, files) == snapshot(clean)
    assert len(rows) == N and sum(name.endswith(".jpg") for name in files) == 36
    assert not [p for p in killed.rglob("*") if ".tmp" in p.name]  # no partial files left


def test_ctrl_c_prints_a_summary_and_exits_130(met_server, tmp_path):
    for i in range(1, 21):
        met_server.add(i)
    met_server.delay = 0.1  # the other 35 requests take 3.5 s: the interrupt lands mid-run even on a busy machine
    proc = subprocess.Popen(command(met_server, tmp_path / "data"), cwd=REPO, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 30
    while met_server.hits("/api/v1/objects/5") == 0:
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.005)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 130, stderr
    assert "[interrupted: rerun to resume]" in stdout and "found 20" in stdout
    assert "Traceback" not in stderr
