"""`radar bench render`: prints JSON with one timing per size; bad options exit 2 with one line."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from radar_cli.cli import cli


def test_bench_render_prints_json_per_size():
    result = CliRunner().invoke(cli, ["bench", "render", "--device", "cpu", "--sizes", "16,24", "--batch", "2",
                                      "--repeats", "1"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert report["device"] == "cpu"
    assert [r["size"] for r in report["results"]] == [16, 24]
    for r in report["results"]:
        assert r["seconds"] > 0 and r["seconds_forward"] > 0 and r["peak_mib"] > 0 and r["batch"] == 2


def test_bench_render_rejects_bad_sizes():
    result = CliRunner().invoke(cli, ["bench", "render", "--device", "cpu", "--sizes", "64,abc"])
    assert result.exit_code == 2 and "--sizes" in result.output
    result = CliRunner().invoke(cli, ["bench", "render", "--device", "cpu", "--sizes", "4"])
    assert result.exit_code == 2 and "--sizes" in result.output


@pytest.mark.slow
def test_bench_masks_and_derender_print_json():
    result = CliRunner().invoke(cli, ["bench", "masks", "--photos", "1", "--long-side", "400", "--size", "64",
                                      "--workers", "1"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert report["photos"] == 1 and report["photos_per_second"] > 0
    result = CliRunner().invoke(cli, ["bench", "derender", "--images", "2", "--exports", "1", "--batch-size", "2",
                                      "--resolution", "96", "--full", "3"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    assert report["network_images_per_s"] > 0 and report["full_images_per_s"] > 0 and report["failed"] == 0
    assert report["resolution"] == [96] and report["export_seconds_per_object"] > 0 and report["peak_rss_mib"] > 0
    assert report["n_full"] == 3 and report["full_peak_pss_mib"] > 0


@pytest.mark.slow
def test_bench_masks_with_worker_processes_finishes():
    # worker processes started after the parent used OpenCV and torch once deadlocked (forked thread pools)
    import subprocess
    import sys

    code = ("import torch, sys; from radar_cli.cli import cli; "
            "cli(['bench', 'masks', '--photos', '2', '--long-side', '400', '--size', '64', '--workers', '2'])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=180)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["photos"] == 2


def test_bench_synth_prints_throughput_and_stage_split():
    result = CliRunner().invoke(cli, ["bench", "synth", "--size", "32", "--n", "3", "--workers", "1"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    assert out["samples"] == 3 and out["failed"] == 0 and out["samples_per_sec"] > 0
    assert 0 < out["startup_sec"] and out["steady_samples_per_sec"] > 0
    assert out["sec_per_sample_make"] > 0 and out["sec_per_sample_write"] > 0
