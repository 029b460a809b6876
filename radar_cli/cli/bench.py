"""`radar bench`: speed and memory benchmarks, one subcommand per stage (render, train, masks, synth, derender)."""

from __future__ import annotations

import json

import click

from radar_cli.cli.derender import RESOLUTION
from radar_cli.derender.refine.driver import REFINE_MODES
from radar_cli.derender.run.inputs import DEFAULT_RESOLUTION, Resolution
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
@click.option("--config", "config_path", default=None, type=click.Path(dir_okay=False),
              help="Preset TOML to time, e.g. pipelines/cpu/syn_vases_cpu.toml, or a .safetensors model whose stored "
                   "configuration to time (default: the bundled model's, found in the installed package).")
@click.option("--device", default="auto", show_default=True, type=click.Choice(["cpu", "cuda", "auto"]),
              help="Where to train; auto = cuda when available.")
@click.option("--steps", default=5, show_default=True, type=click.IntRange(min=1), help="Timed steps (median).")
@click.option("--warmup", default=2, show_default=True, type=click.IntRange(min=0), help="Untimed first steps.")
@click.option("--batch", default=None, type=click.IntRange(min=1), help="Batch size (default: the preset's).")
@click.option("--threads", default=None, type=click.IntRange(min=1), help="CPU threads (default: the preset's).")
@click.option("--profile", "profile_path", default=None, type=click.Path(dir_okay=False),
              help="Also write torch.profiler's operator tables of 3 more steps to this text file.")
def train(config_path: str | None, device: str, steps: int, warmup: int, batch: int | None, threads: int | None,
          profile_path: str | None) -> None:
    """Seconds per full training step (model + discriminator, forward, backward, Adam) and peak memory."""
    from radar_cli.derender.run.predictor import bundled_checkpoint
    from radar_cli.train.benchmark import bench_train

    result = bench_train(config_path or bundled_checkpoint(), steps, warmup, batch, device, threads, profile_path)
    click.echo(json.dumps(result, indent=2))


@bench.command("masks")
@click.option("--photos", default=12, show_default=True, type=click.IntRange(min=1), help="Generated studio photos.")
@click.option("--long-side", default=4000, show_default=True, type=click.IntRange(min=64),
              help="Long edge of each photo in pixels.")
@click.option("--size", default=256, show_default=True, type=click.IntRange(min=16), help="Crop side in pixels.")
@click.option("--workers", default=2, show_default=True, type=click.IntRange(min=1),
              help="Processes detecting and cropping photos (radar masks --workers).")
def masks(photos: int, long_side: int, size: int, workers: int) -> None:
    """Photos per second through `radar masks` (decode, detect, GrabCut, crop, score, write)."""
    from radar_cli.masks.benchmark import bench_masks

    click.echo(json.dumps(bench_masks(photos, long_side, size, workers), indent=2))


@bench.command("synth")
@click.option("--size", default=256, show_default=True, type=click.IntRange(16, 1024), help="Image side in pixels.")
@click.option("--n", "n", default=120, show_default=True, type=click.IntRange(min=1), help="Samples to generate.")
@click.option("--workers", default=2, show_default=True, type=click.IntRange(min=1),
              help="Processes rendering samples (radar synth --workers).")
@click.option("--shading-size", default=0, show_default=True, type=click.IntRange(min=0),
              help="Lighting grid side for the frontal third (0 = radar synth's default).")
def synth(size: int, n: int, workers: int, shading_size: int) -> None:
    """Samples per second through `radar synth` (sample, render every map, write), and make vs write time."""
    from radar_cli.synth.benchmark import bench_synth

    click.echo(json.dumps(bench_synth(size, n, workers, shading_size), indent=2))


@bench.command("derender")
@click.option("--checkpoint", default=None, type=click.Path(dir_okay=False), help="Default: the bundled model.")
@click.option("--device", default="cpu", show_default=True, help="auto, cpu, cuda or cuda:N.")
@click.option("--images", default=32, show_default=True, type=click.IntRange(min=1),
              help="Images through the network alone.")
@click.option("--exports", default=4, show_default=True, type=click.IntRange(min=1),
              help="Images exported one at a time, for the seconds and memory per object.")
@click.option("--full", "n_full", default=24, show_default=True, type=click.IntRange(min=1),
              help="Photos de-rendered end to end by `radar derender` (the exported ones cycled).")
@click.option("--batch-size", default=8, show_default=True, type=click.IntRange(min=1),
              help="Images per network batch (radar derender --batch-size).")
@click.option("--threads", default=1, show_default=True, type=click.IntRange(min=1), help="torch threads.")
@click.option("--workers", default=2, show_default=True, type=click.IntRange(min=0),
              help="Objects de-rendered at a time in the full run (radar derender --workers).")
@click.option("--albedo", type=click.Choice(["network", "divided"]), default="divided", show_default=True,
              help="radar derender --albedo.")
@click.option("--pitch", type=click.Choice(["network", "search"]), default="network", show_default=True,
              help="radar derender --pitch.")
@click.option("--resolution", type=RESOLUTION, default=str(DEFAULT_RESOLUTION), show_default=True,
              help="radar derender --resolution (the benchmark's photos are 1.6 x this side).")
@click.option("--refine", type=click.Choice(REFINE_MODES), default="full", show_default=True,
              help="radar derender --refine.")
def derender(checkpoint: str | None, device: str, images: int, exports: int, n_full: int, batch_size: int,
             threads: int, workers: int, albedo: str, pitch: str, resolution: Resolution, refine: str) -> None:
    """Images per second for the network alone and for the full de-rendering with all exports; seconds per
    object and peak memory of the export at the output resolution."""
    from radar_cli.derender.run.benchmark import bench_derender

    click.echo(json.dumps(bench_derender(checkpoint, device, images, exports, batch_size, threads, workers=workers,
                                         albedo=albedo, pitch=pitch, resolution=resolution,  # type: ignore[arg-type]
                                         refine=refine, n_full=n_full),  # type: ignore[arg-type]
                          indent=2))
