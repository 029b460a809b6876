"""The `radar` command group: a thin layer that parses options and calls one function per subcommand.

Each subcommand lives in its own module of this package and is registered in COMMANDS only once it works.
"""

from __future__ import annotations

import importlib

import click

from radar_cli import __version__
from radar_cli.allocator import keep_freed_memory
from radar_cli.blas_threads import single_threaded_blas
from radar_cli.errors import RadarError

# (command name, module, attribute, one-line help): one line per working subcommand, in pipeline order.
# Modules are imported only when their command runs, so `radar --help` and `radar fetch` never load torch.
COMMANDS: list[tuple[str, str, str, str]] = [
    ("fetch", "radar_cli.cli.fetch", "fetch", "Harvest a museum's open-access collection (Met Collection API)."),
    ("masks", "radar_cli.cli.masks", "masks", "Crop photographs and make silhouettes (GrabCut), with quality scores."),
    ("synth", "radar_cli.cli.synth", "synth", "Render synthetic vases with full ground truth."),
    ("train", "radar_cli.cli.train", "train", "Train the RADAR model on a prepared or synthetic dataset."),
    ("train-reader", "radar_cli.cli.train", "train_reader",
     "Teach the specular-albedo reader with synthetic ground truth."),
    ("derender", "radar_cli.cli.derender", "derender", "De-render photographs into per-object folders of exports."),
    ("serve", "radar_cli.cli.serve", "serve", "Show a results folder's gallery and 3D viewer at a local address."),
    ("relight", "radar_cli.cli.relight", "relight", "Re-render a de-rendered object under new light and view."),
    ("eval", "radar_cli.cli.eval", "eval_cmd", "Score de-rendering results against synthetic ground truth."),
    ("eval-catalog", "radar_cli.cli.eval_catalog", "eval_catalog",
     "Measure results of real photographs against a catalogue's dimensions and drawings."),
    ("eval-views", "radar_cli.cli.eval_views", "eval_views",
     "Score objects with several photos by predicting each side view from the others."),
    ("bench", "radar_cli.cli.bench", "bench", "Time a stage of the pipeline and print JSON."),
]


class RadarUsageError(click.ClickException):
    """A RadarError shown as one line `Error: ...` on stderr, with the error's exit status (2 unless it says)."""

    def __init__(self, error: RadarError) -> None:
        super().__init__(str(error))
        self.exit_code = error.exit_status  # type: ignore[misc]  # click declares it on the class; each error has its own


class RadarGroup(click.Group):
    """Click group with lazily imported subcommands that turns RadarError into a one-line message."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return [name for name, _module, _attr, _help in COMMANDS]

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        for name, module, attr, _help in COMMANDS:
            if name == cmd_name:
                return getattr(importlib.import_module(module), attr)
        return None

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, help_text) for name, _module, _attr, help_text in COMMANDS]
        with formatter.section("Commands"):
            formatter.write_dl(rows)

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except RadarError as e:
            raise RadarUsageError(e) from None


@click.group(cls=RadarGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="radar")
def cli() -> None:
    """De-render photographs of vases and other solids of revolution into 3D shape, pose, albedo, lighting and
    material. Subcommands chain: fetch -> masks -> train -> derender."""


def main() -> None:
    """Console-script entry point."""
    single_threaded_blas()  # before any command imports numpy
    keep_freed_memory()
    cli()
