"""What a `radar derender` run leaves on disk: files readable as the umask says, no temporary files of a killed
run, nothing at all when the inputs hold no photo or --out is the photo folder."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from .conftest import write_photo

REPO = Path(__file__).resolve().parents[2]
FAST = ["--views", "2", "--view-size", "32", "--resolution", "64", "--refine", "none", "--workers", "1",
        "--device", "cpu"]


def radar(*args: str, umask: int = 0o022) -> subprocess.CompletedProcess:
    env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=str(REPO))
    return subprocess.run([sys.executable, "-m", "radar_cli", *args], env=env, capture_output=True, text=True,
                          timeout=300, preexec_fn=lambda: os.umask(umask))


def modes(root: Path) -> dict[str, int]:
    return {str(p.relative_to(root)): stat.S_IMODE(p.stat().st_mode) for p in root.rglob("*")}


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> tuple[Path, Path]:
    """One photo de-rendered under umask 022, then leftovers of a killed run planted in every folder."""
    root = tmp_path_factory.mktemp("hygiene")
    write_photo(root / "photos" / "vase.png", 3, (80, 96))
    done = radar("derender", str(root / "photos"), "--out", str(root / "out"), *FAST)
    assert done.returncode == 0, done.stderr[-2000:]
    return root / "photos", root / "out"


def test_every_output_has_the_mode_of_an_ordinary_write(run) -> None:
    found = modes(run[1])
    files = {k: v for k, v in found.items() if (run[1] / k).is_file()}
    assert len(files) > 20 and "index.html" in files and "vase/mesh.glb" in files
    assert set(files.values()) == {0o644}, {k: oct(v) for k, v in files.items() if v != 0o644}
    assert {v for k, v in found.items() if (run[1] / k).is_dir()} == {0o755}


def test_a_rerun_removes_radars_temp_files_only(run) -> None:
    photos, out = run
    leftovers = [out / ".summary.csv.k3j_x9aa.tmp.csv", out / ".gallery" / ".data.js.abcdefgh.tmp.js",
                 out / "vase" / ".mesh.glb.zz_12345.tmp.glb", out / ".index.html.0a1b2c3d.tmp.html"]
    for path in leftovers:
        path.write_bytes(b"half written")
    mine = [out / ".notes.tmp", out / "vase" / "notes.tmp.txt"]
    for path in mine:
        path.write_text("not radar's")
    done = radar("derender", str(photos), "--out", str(out), *FAST)
    assert done.returncode == 0 and "0 de-rendered, 1 skipped" in done.stdout
    assert [p for p in leftovers if p.exists()] == [] and all(p.is_file() for p in mine)


def test_out_equal_to_the_photo_folder_is_refused(run, tmp_path) -> None:
    write_photo(tmp_path / "vase.png", 1)
    done = radar("derender", str(tmp_path), "--out", str(tmp_path), *FAST)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.strip() == f"Error: {tmp_path}: --out is the input folder {tmp_path}; choose a results " \
                                  "folder outside it"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["vase.png"]


@pytest.mark.parametrize("kind", ["missing", "empty"])
def test_no_photo_exits_1_in_one_line_and_creates_nothing(tmp_path, kind) -> None:
    source = tmp_path / "photos"
    if kind == "empty":
        source.mkdir()
        (source / "notes.txt").write_text("no image here")
    done = radar("derender", str(source), "--out", str(tmp_path / "out"), *FAST)
    assert done.returncode == 1 and done.stdout == "" and done.stderr.count("\n") == 1
    assert str(source) in done.stderr and ("no such file" in done.stderr or "holds no images" in done.stderr)
    assert not (tmp_path / "out").exists()
