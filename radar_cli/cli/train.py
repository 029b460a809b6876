"""`radar train`: train RADAR from a pipelines/**/*.toml preset on a dataset folder."""

from __future__ import annotations

import sys

import click

from radar_cli.model.config import load_run_config

OUT_OF_TIME_STATUS = 3


@click.command("train")
@click.option("--config", "config_path", required=True, type=click.Path(dir_okay=False),
              help="Preset TOML, e.g. pipelines/cpu/syn_vases_cpu.toml (pipelines/README.md lists them).")
@click.option("--data", "data_dir", required=True, type=click.Path(file_okay=False),
              help="Dataset root holding train/<id>/image.png + mask.png.")
@click.option("--out", "run_dir", required=True, type=click.Path(file_okay=False),
              help="Run folder for checkpoints, metrics.jsonl, images and the loss curve.")
@click.option("--resume", is_flag=True, help="Continue from the newest checkpoint in --out.")
@click.option("--device", type=click.Choice(["auto", "cpu", "cuda"]), default=None,
              help="Overrides train.device of the preset.")
@click.option("--overfit", type=click.IntRange(min=1), default=None, help="Train on the first N samples only.")
@click.option("--iterations", type=click.IntRange(min=0), default=None, help="Overrides train.iterations.")
@click.option("--init", "init", type=click.Path(dir_okay=False), default=None,
              help="Start from the weights of this checkpoint or model file (fine-tuning; fresh optimizers).")
@click.option("--threads", type=click.IntRange(min=1), default=None,
              help="Overrides train.threads (CPU threads; the CPU presets use 1 for shared machines).")
@click.option("--max-minutes", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Wall-time budget: past it, write a checkpoint and stop with exit status 3 (continue with "
                   "--resume).")
@click.option("--pitch-labels", type=click.Path(file_okay=False), default=None,
              help="`radar derender DATA/train --pitch search` results, for loss.pitch_label_weight "
                   "(self-training on pitch).")
def train(config_path: str, data_dir: str, run_dir: str, resume: bool, device: str | None, overfit: int | None,
          iterations: int | None, init: str | None, threads: int | None, max_minutes: float | None,
          pitch_labels: str | None) -> None:
    """Train the de-rendering model (shape, lighting, albedo networks + SAD discriminator)."""
    from radar_cli.train.trainer import train as run_training

    summary = run_training(load_run_config(config_path), data_dir, run_dir, resume=resume, device=device,
                           overfit=overfit, iterations=iterations, init=init, threads=threads,
                           max_minutes=max_minutes, pitch_labels=pitch_labels)
    losses = "  ".join(f"{k}={v:.4f}" for k, v in summary.losses.items())
    click.echo(f"trained steps {summary.start}..{summary.end} in {summary.seconds:.1f} s "
               f"({summary.sec_per_step:.3f} s/step)")
    click.echo(f"final losses: {losses}")
    click.echo(f"checkpoint: {summary.checkpoint}")
    if summary.out_of_time:  # not finished: status 3, so `radar train ... && radar derender ...` stops here
        click.echo(f"stopped by --max-minutes at step {summary.end}; continue with --resume")
        sys.exit(OUT_OF_TIME_STATUS)


@click.command("train-reader")
@click.option("--config", "config_path", default=None, type=click.Path(dir_okay=False),
              help="Reader TOML (pipelines/readers/specular_albedo.toml; default: its defaults).")
@click.option("--data", "data_dir", required=True, type=click.Path(file_okay=False),
              help="`radar synth` dataset: train/<id>/image.png + params.json (and test/, scored each epoch).")
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False),
              help="Run folder: specular_reader.safetensors, last.safetensors (resumed from), loss.png.")
@click.option("--checkpoint", "base", default=None, type=click.Path(dir_okay=False),
              help="Model whose f_L the reader starts from (default: the bundled model).")
def train_reader(config_path: str | None, data_dir: str, out_dir: str, base: str | None) -> None:
    """Teach the specular-albedo reader that `radar derender --refine` uses, from a model's f_L."""
    from radar_cli.config import load_toml
    from radar_cli.derender.run.predictor import bundled_checkpoint
    from radar_cli.train.specular_reader import ReaderConfig
    from radar_cli.train.specular_reader import train_reader as run

    config = load_toml(ReaderConfig, config_path) if config_path else ReaderConfig()
    summary = run(config, data_dir, out_dir, base or bundled_checkpoint(), say=click.echo)
    resumed = f", resumed after epoch {summary.resumed}" if summary.resumed else ""
    click.echo(f"reader: {summary.reader} ({summary.seconds:.1f} s{resumed})")
