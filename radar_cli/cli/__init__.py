"""The `radar` command group: a thin layer that parses options and calls one function per subcommand.

Each subcommand lives in its own module of this package and is registered in COMMANDS only once it works.
"""

from __future__ import annotations

import importlib
import click

from radar_cli import __version__
from radar_cli.errors import RadarError

# (module, command attribute): one line per working subcommand.
COMMANDS: list[tuple[str, str]] = [
    ("radar_cli.cli.fetch", "fetch"),
    ("radar_cli.cli.masks", "masks"),
    ("radar_cli.cli.synth", "synth"),
    ("radar_cli.cli.train", "train"),
    ("radar_cli.cli.derender", "derender"),
    ("radar_cli.cli.relight", "relight"),
    ("radar_cli.cli.eval", "eval"),
    ("radar_cli.cli.bench", "bench"),
]


class RadarUsageError(click.ClickException):
    """A RadarError shown as one line `Error: ...` with exit code 2."""

    exit_code = 2


class RadarGroup(click.Group):
    """Click group that turns RadarError (bad input, config, checkpoint) into a one-line message."""

    def invoke(self, ctx: click.Context):  # type: ignore[override]
        try:
            return super().invoke(ctx)
        except RadarError as e:
            raise RadarUsageError(str(e)) from None


@click.group(cls=RadarGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="radar")
def cli() -> None:
    """De-render photographs of vases and other solids of revolution into 3D shape, pose, albedo, lighting and
    material. Subcommands chain: fetch -> masks -> train -> derender."""


for _module, _attr in COMMANDS:
    cli.add_command(getattr(importlib.import_module(_module), _attr))


def main() -> None:
    """Console-script entry point."""
    cli()
