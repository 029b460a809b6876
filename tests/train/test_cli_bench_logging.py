"""`radar train` through the CLI group (exit codes, files), the benchmark, and the logging helpers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.model.weights import load_model
from radar_cli.train.benchmark import bench_train
from radar_cli.train.checkpoint import list_checkpoints
from radar_cli.train.logging import loss_curve

from .conftest import tiny_config

PRESET = Path(__file__).resolve().parents[2] / "pipelines" / "cpu" / "syn_vases_cpu.toml"


def test_train_command_runs_the_cpu_preset(vases64, tmp_path):
    run = tmp_path / "run"
    result = CliRunner().invoke(cli, ["train", "--config", str(PRESET), "--data", str(vases64), "--out", str(run),
                                      "--overfit", "4", "--iterations", "2", "--device", "cpu"])
    assert result.exit_code == 0, result.output
    assert "trained steps 0..2" in result.output and "final losses:" in result.output
    ckpt = list_checkpoints(run)[-1]
    model, config = load_model(ckpt)
    assert config.name == "syn_vases_cpu" and config.train.iterations == 2 and config.train.batch_size == 4
    assert (run / "images" / "step_0000002.png").is_file() and (run / "loss_curve.png").is_file()
    exported, exported_config = load_model(run / "model.safetensors")  # the finished run's weights for derender
    assert exported_config == config
    for name, value in model.state_dict().items():
        assert torch.equal(value, exported.state_dict()[name]), name
    resumed = CliRunner().invoke(cli, ["train", "--config", str(PRESET), "--data", str(vases64), "--out", str(run),
                                       "--overfit", "4", "--iterations", "3", "--resume"])
    assert resumed.exit_code == 0, resumed.output
    assert "trained steps 2..3" in resumed.output
    budget = CliRunner().invoke(cli, ["train", "--config", str(PRESET), "--data", str(vases64), "--out", str(run),
                                      "--overfit", "4", "--iterations", "5", "--resume", "--max-minutes", "1e-9"])
    assert budget.exit_code == 3, budget.output  # not finished: a `&& radar derender` chain stops here
    assert "trained steps 3..4" in budget.output and "stopped by --max-minutes at step 4" in budget.output


def test_train_command_errors_are_one_line(vases64, tmp_path):
    runner = CliRunner()
    missing = runner.invoke(cli, ["train", "--config", str(tmp_path / "nope.toml"), "--data", str(vases64),
                                  "--out", str(tmp_path / "r")])
    assert missing.exit_code == 2 and "Error:" in missing.output and "nope.toml" in missing.output
    empty = tmp_path / "empty"
    (empty / "train").mkdir(parents=True)
    no_data = runner.invoke(cli, ["train", "--config", str(PRESET), "--data", str(empty), "--out",
                                  str(tmp_path / "r")])
    assert no_data.exit_code == 2 and "no samples" in no_data.output
    bad = tmp_path / "bad.safetensors"
    run = tmp_path / "r2"
    (run / "checkpoints").mkdir(parents=True)
    bad.write_bytes(b"junk")
    (run / "checkpoints" / "step_0000005.safetensors").write_bytes(b"junk" * 10)
    corrupt = runner.invoke(cli, ["train", "--config", str(PRESET), "--data", str(vases64), "--out", str(run),
                                  "--resume", "--iterations", "6"])
    assert corrupt.exit_code == 2 and "corrupt" in corrupt.output


def test_bench_train_reports_speed_and_memory():
    out = bench_train(tiny_config(), steps=2, warmup=1, device="cpu", threads=1)
    assert out["sec_per_step"] > 0 and out["peak_memory_mb"] > 0 and out["batch_size"] == 4


def test_bench_train_writes_a_profile(tmp_path):
    path = tmp_path / "profile.txt"
    bench_train(tiny_config(), steps=1, warmup=0, device="cpu", threads=1, profile=path)
    text = path.read_text()
    assert text.startswith("# torch.profiler, 3 training steps on cpu") and "aten::convolution" in text
    assert "# by own CPU time" in text


def test_loss_curve_draws_every_term():
    records = [{"step": s, "total": 1.0 / (s + 1), "sil": 0.5, "sec_per_step": 0.1} for s in range(20)]
    image = loss_curve(records)
    assert image.shape == (500, 900, 3) and image.dtype == np.uint8
    assert (image != 255).any(axis=2).sum() > 500  # lines and labels were drawn
    assert loss_curve([]).shape == (500, 900, 3)


def test_bench_train_command_prints_json():
    import json

    result = CliRunner().invoke(cli, ["bench", "train", "--config", str(PRESET), "--device", "cpu", "--steps", "1",
                                      "--warmup", "0", "--batch", "2", "--threads", "1"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    assert out["preset"] == "syn_vases_cpu" and out["batch_size"] == 2 and out["sec_per_step"] > 0
