"""`radar bench`: speed and memory benchmarks, one subcommand per stage (render; train, masks, derender later)."""

from __future__ import annotations

import json

import click

from radar_cli.errors import InputError


@click.group("bench")
def bench() -> None:
    """Time a stage of the pipeline and print JSON (seconds, peak memory)."""


@bench.command("render")
@click.option("--device", default="auto", show_default=True, type=click.Choice(["cpu", "cuda", "auto"]),
              help="Where to render; auto = cuda when available.")
@click.option("--sizes", default="64,128,256", show_default=True, help="Comma-separated image sizes in pixels.")
@click.option("--batch", default=24, show_default=True, type=int, help="Images per batch.")
@click.option("--repeats", default=3, show_default=True, type=int, help="Timed runs per size (median reported).")
@click.option("--threads", default=0, type=int, help="CPU intra-op threads (0 = torch's default).")
def render(device: str, sizes: str, batch: int, repeats: int, threads: int) -> None:
    """Forward+backward of silhouette + shading + frontal texture render + unwrap, per image size."""
    from radar_cli.render.benchmark import run_benchmark

    try:
        size_list = [int(s) for s in sizes.split(",") if s.strip()]
    except ValueError:
        raise InputError(f"--sizes: expected comma-separated integers, got {sizes!r}") from None
    click.echo(json.dumps(run_benchmark(size_list, batch, device, repeats, threads), indent=2))
