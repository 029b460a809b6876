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


@bench.command("train")
@click.option("--config", "config_path", default="pipelines/syn_vases_cpu.toml", show_default=True,
              type=click.Path(dir_okay=False), help="Preset TOML to time.")
@click.option("--device", default="auto", show_default=True, type=click.Choice(["cpu", "cuda", "auto"]))
@click.option("--steps", default=5, show_default=True, type=click.IntRange(min=1), help="Timed steps (median).")
@click.option("--warmup", default=2, show_default=True, type=click.IntRange(min=0), help="Untimed first steps.")
@click.option("--batch", default=None, type=click.IntRange(min=1), help="Batch size (default: the preset's).")
@click.option("--threads", default=None, type=click.IntRange(min=1), help="CPU threads (default: the preset's).")
def train(config_path: str, device: str, steps: int, warmup: int, batch: int | None, threads: int | None) -> None:
    """Seconds per full training step (model + discriminator, forward, backward, Adam) and peak memory."""
    from radar_cli.train.benchmark import bench_train

    click.echo(json.dumps(bench_train(config_path, steps, warmup, batch, device, threads), indent=2))
