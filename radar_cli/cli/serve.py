"""`radar serve`: show a results folder's gallery, with its 3D viewer, at a local address."""

from __future__ import annotations

from pathlib import Path

import click

from radar_cli.derender.present.server import serve as run_server


@click.command("serve")
@click.argument("results", type=click.Path(file_okay=False, path_type=Path))
@click.option("--port", type=click.IntRange(0, 65535), default=8023, show_default=True,
              help="Port on 127.0.0.1 (0: any free port).")
@click.option("--log", is_flag=True, help="Print one line per request.")
def serve(results: Path, port: int, log: bool) -> None:
    """Serve RESULTS (a `radar derender --out` folder) read-only on 127.0.0.1 until Ctrl-C."""
    run_server(results, port, say=click.echo, quiet=not log)
