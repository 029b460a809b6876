"""The `radar` group: version, help listing only working subcommands, lazy loading, one-line errors."""

import subprocess
import sys

from click.testing import CliRunner

from radar_cli import __version__
from radar_cli.cli import COMMANDS, cli


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
    code = "import sys; from radar_cli.cli import cli; cli(['--help'], standalone_mode=False); print('torch' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().endswith("False")


def test_unknown_command_fails():
    result = CliRunner().invoke(cli, ["nope"])
    assert result.exit_code == 2
