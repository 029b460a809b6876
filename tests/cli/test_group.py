"""The `radar` group: version, help listing only working subcommands, one-line errors."""

from click.testing import CliRunner

from radar_cli import __version__
from radar_cli.cli import COMMANDS, cli


def test_version():
    result = CliRunner().invoke(cli, ["--version"])
    assert result.exit_code == 0 and __version__ in result.output


def test_help_lists_registered_commands():
    result = CliRunner().invoke(cli, ["--help"])
    assert result.exit_code == 0
    for _module, attr in COMMANDS:
        assert attr in result.output
    assert len(cli.commands) == len(COMMANDS)


def test_unknown_command_fails():
    result = CliRunner().invoke(cli, ["nope"])
    assert result.exit_code == 2
