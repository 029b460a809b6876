"""`radar eval-views`: score multi-view objects by predicting each side view from the others."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from radar_cli.cli.derender import RESOLUTION
from radar_cli.derender.run.inputs import DEFAULT_RESOLUTION
from radar_cli.derender.run.predictor import Predictor
from radar_cli.evaluate.held_out import evaluate_views, summary_line
from radar_cli.threads import torch_threads


@click.command("eval-views")
@click.argument("root", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--out", required=True, type=click.Path(file_okay=False, path_type=Path),
              help="Where held_out.csv and one picture per object (photo, multi-view, single-view) go.")
@click.option("--checkpoint", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Model weights (.safetensors); default: the bundled model.")
@click.option("--device", default="auto", show_default=True, help="auto, cpu, cuda or cuda:N.")
@click.option("--resolution", type=RESOLUTION, default=str(DEFAULT_RESOLUTION), show_default=True,
              help="Side in pixels the views are fitted and scored at.")
def eval_views(root: Path, out: Path, checkpoint: Path | None, device: str, resolution) -> None:
    """For every object under ROOT photographed from at least 3 sides (a sub-folder of photos), leave each side
    view out in turn, fit the object on the others and score the left-out view's prediction (PSNR, SSIM inside
    its silhouette) beside the nearest view's single-view (mirrored) prediction."""
    predictor = Predictor.from_checkpoint(checkpoint, device, "divided", "network", "full")
    with torch_threads(1):
        rows = evaluate_views(root, out, predictor, resolution, say=lambda line: click.echo(line, err=True))
    click.echo(summary_line(rows))
    click.echo(f"table: {out / 'held_out.csv'}")
    if not rows:
        sys.exit(1)
