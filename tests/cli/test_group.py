"""The `radar` group: version, help listing only working subcommands, lazy loading, one-line errors."""

import json
import os
import subprocess
import sys
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from radar_cli import __version__
from radar_cli.cli import COMMANDS, cli

REPO = Path(__file__).resolve().parents[2]


def test_version():
    result = CliRunner().invoke(cli, ["--version"])
    assert result.exit_code == 0 and __version__ in result.output


def test_help_lists_registered_commands_with_their_help():
    result = CliRunner().invoke(cli, ["--help"])
    assert result.exit_code == 0
    for name, _module, _attr, help_text in COMMANDS:
        assert name in result.output and help_text[:30] in result.output


def test_every_registered_command_loads_and_has_help():
    runner = CliRunner()
    for name, *_rest in COMMANDS:
        command = cli.get_command(None, name)
        assert command is not None and command.name == name
        result = runner.invoke(cli, [name, "--help"])
        assert result.exit_code == 0, (name, result.output)


def test_help_does_not_import_torch():
    code = ("import sys; from radar_cli.cli import cli; cli(['--help'], standalone_mode=False); "
            "print('torch' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().endswith("False")


def test_unknown_command_fails():
    result = CliRunner().invoke(cli, ["nope"])
    assert result.exit_code == 2


def _leaf_commands(group: click.Group, prefix: str = ""):
    """(name, command) of every subcommand, nested groups (radar bench) included."""
    for name in group.list_commands(None):
        command = group.get_command(None, name)
        if isinstance(command, click.Group):
            yield from _leaf_commands(command, f"{prefix}{name} ")
        else:
            yield f"{prefix}{name}", command


def test_every_visible_option_has_help_text():
    missing = [f"{name} {param.opts[0]}" for name, command in _leaf_commands(cli) for param in command.params
               if isinstance(param, click.Option) and not param.hidden and not param.help]
    assert not missing, missing


@pytest.mark.slow
def test_bench_train_runs_outside_the_checkout(tmp_path):
    """Its default preset comes from the installed package, not a path relative to the repository."""
    env = dict(os.environ, PYTHONPATH=str(REPO), OMP_NUM_THREADS="1")
    done = subprocess.run([sys.executable, "-m", "radar_cli", "bench", "train", "--steps", "1", "--warmup", "0",
                           "--device", "cpu", "--batch", "2"], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    result = json.loads(done.stdout)
    assert result["steps"] == 1 and result["batch_size"] == 2 and result["sec_per_step"] > 0
