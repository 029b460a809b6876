"""`radar masks`: photographs -> square training crops with silhouettes (see radar_cli/masks/prepare.py)."""

from __future__ import annotations

import click

from radar_cli.masks.crop import DEFAULT_MARGIN
from radar_cli.masks.pipeline import Settings
from radar_cli.masks.prepare import DetectorSpec, prepare
from radar_cli.masks.quality import Thresholds


@click.command("masks")
@click.argument("data", type=click.Path(exists=True, file_okay=False))
@click.option("--out", required=True, type=click.Path(file_okay=False), help="Dataset folder to write.")
@click.option("--size", default=256, show_default=True, type=click.IntRange(32, 2048), help="Crop side (px).")
@click.option("--margin", default=DEFAULT_MARGIN, show_default=True, type=click.FloatRange(0.0, 0.45),
              help="Margin per side, fraction of the crop.")
@click.option("--min-symmetry", default=Thresholds().min_symmetry, show_default=True,
              type=click.FloatRange(0.0, 1.0), help="Reject crops whose solid-of-revolution score is lower.")
@click.option("--workers", default=1, show_default=True, type=click.IntRange(1, 64),
              help="Processes working on photos in parallel.")
@click.option("--detector", type=click.Choice(["classical", "onnx"]), default="classical", show_default=True,
              help="classical: the backdrop-model detector; onnx: an object detector from --model.")
@click.option("--model", type=click.Path(exists=True, dir_okay=False), help="ONNX model for --detector onnx.")
@click.option("--no-contact-sheet", is_flag=True, help="Skip the PNG contact sheets.")
def masks(data, out, size, margin, min_symmetry, workers, detector, model, no_contact_sheet) -> None:
    """Detect, refine (GrabCut), crop and score the objects in DATA (a `radar fetch` folder or any folder of
    photographs); write OUT/<split>/<id>/{image,mask}.png + meta.json. Exits 1 if any photo was unreadable."""
    if detector == "onnx" and not model:
        raise click.UsageError("--detector onnx needs --model FILE")
    settings = Settings(size=size, margin=margin, limits=Thresholds(min_symmetry=min_symmetry))
    s = prepare(data, out, settings, workers, DetectorSpec(detector, model), not no_contact_sheet)
    accepted = ", ".join(f"{k} {v}" for k, v in sorted(s.accepted.items())) or "none"
    click.echo(f"{s.photos} photos ({s.skipped_done} already done): accepted {accepted}; rejected {s.rejected} "
               f"{s.reasons or ''}; no object {s.no_object}; unreadable {s.failed}; "
               f"{s.photos_per_second or '-'} photos/s")
    for sheet in s.sheets:
        click.echo(f"contact sheet: {sheet}")
    if s.failed:
        raise SystemExit(1)
