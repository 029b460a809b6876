"""Files radar writes get the mode an ordinary write gives under the umask, and a run removes only radar's own
temporary files; the light commands (masks, synth, eval) fail loudly on inputs with nothing in them."""

from __future__ import annotations

import os
import stat
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from radar_cli.cli import cli
from radar_cli.fileio import is_temp_name, ordinary_file_mode, remove_stale_temps, write_image, write_text


@contextmanager
def umask(mask: int):
    before = os.umask(mask)
    try:
        yield
    finally:
        os.umask(before)


def file_modes(root: Path) -> set[int]:
    return {stat.S_IMODE(p.stat().st_mode) for p in root.rglob("*") if p.is_file()}


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o027, 0o640), (0o077, 0o600)])
def test_atomic_writes_follow_the_umask(tmp_path, mask, mode) -> None:
    with umask(mask):
        assert ordinary_file_mode() == mode
        write_text(tmp_path / "a.txt", "x")
        write_image(tmp_path / "b.png", np.zeros((4, 4, 3), np.uint8))
        (tmp_path / "ordinary.txt").write_text("x")
    assert file_modes(tmp_path) == {mode}


def test_only_radars_temp_names_are_removed(tmp_path) -> None:
    radar_temps = [".summary.csv.k3j_x9aa.tmp.csv", ".data.js.abcdefgh.tmp.js", ".model.safetensors.a1b2c3d4.tmp"
                   ".safetensors", ".env_map.hdr.zzzzzzzz.tmp.hdr"]
    others = [".notes.tmp", "summary.csv", ".summary.csv", "x.tmp.csv", ".a.short.tmp.csv"]
    assert all(is_temp_name(n) for n in radar_temps) and not any(is_temp_name(n) for n in others)
    (tmp_path / "sub").mkdir()
    for name in radar_temps + others:
        (tmp_path / name).write_text("x")
        (tmp_path / "sub" / name).write_text("x")
    assert remove_stale_temps(tmp_path) == len(radar_temps)
    assert remove_stale_temps(tmp_path, recursive=True, min_age_s=3600) == 0  # too fresh: another process's
    assert remove_stale_temps(tmp_path, recursive=True) == len(radar_temps)
    assert sorted(p.name for p in tmp_path.iterdir() if p.is_file()) == sorted(others)


def test_masks_outputs_modes_and_failures_on_stderr(tmp_path) -> None:
    photos = tmp_path / "photos"
    photos.mkdir()
    image = np.full((120, 90, 3), 255, np.uint8)
    image[20:100, 30:60] = (150, 90, 40)
    Image.fromarray(image).save(photos / "vase.png")
    (photos / "broken.jpg").write_bytes(b"not a jpeg")
    out = tmp_path / "prepared"
    (out / "train").mkdir(parents=True)
    (out / ".summary.json.ab12cd34.tmp.json").write_text("{")
    with umask(0o022):
        result = CliRunner().invoke(cli, ["masks", str(photos), "--out", str(out), "--size", "64"])
    assert result.exit_code == 1
    assert "broken.jpg: not a readable image" in result.stderr and "broken.jpg" not in result.stdout
    assert not (out / ".summary.json.ab12cd34.tmp.json").exists()
    assert file_modes(out) == {0o644}


def test_masks_on_an_empty_folder_exits_1_and_writes_nothing(tmp_path) -> None:
    (tmp_path / "empty").mkdir()
    result = CliRunner().invoke(cli, ["masks", str(tmp_path / "empty"), "--out", str(tmp_path / "out")])
    assert result.exit_code == 1 and result.stdout == ""
    assert result.stderr.startswith(f"Error: {tmp_path / 'empty'}: no photographs")
    assert not (tmp_path / "out").exists()
    same = CliRunner().invoke(cli, ["masks", str(tmp_path / "empty"), "--out", str(tmp_path / "empty")])
    assert same.exit_code == 2 and "--out is the photo folder" in same.stderr


def test_synth_modes_and_eval_with_nothing_scored(tmp_path) -> None:
    data = tmp_path / "syn"
    data.mkdir()
    (data / ".synth.json.ab12cd34.tmp.json").write_text("{")
    with umask(0o022):
        made = CliRunner().invoke(cli, ["synth", "--out", str(data), "--n", "1", "--size", "32", "--split", "test",
                                        "--workers", "1"])
    assert made.exit_code == 0, made.output
    assert file_modes(data) == {0o644} and not (data / ".synth.json.ab12cd34.tmp.json").exists()
    (tmp_path / "results").mkdir()
    result = CliRunner().invoke(cli, ["eval", "--pred", str(tmp_path / "results"), "--gt", str(data)])
    assert result.exit_code == 1 and result.stdout == ""
    assert result.stderr.strip().splitlines()[-1] == (
        f"Error: {tmp_path / 'results'}: nothing scored against {data} (0 result(s) without ground truth, "
        "1 sample(s) without a result, 0 unreadable)")
