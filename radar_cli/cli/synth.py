"""`radar synth`: synthetic vases with full ground truth (thin wrapper over radar_cli.synth.generator)."""

from __future__ import annotations

import os

import click

from radar_cli.synth.generator import FORMAT_VERSION, SynthConfig, generate
from radar_cli.synth.layout import DEFAULT_SPLIT_SIZES, FAILURES_FILE


def split_sizes(split: str, n: int | None) -> dict[str, int]:
    """Samples per split: the paper's 4115/460 by default; --n sets one split, or train (test in proportion)."""
    if split != "both":
        return {split: DEFAULT_SPLIT_SIZES[split] if n is None else n}
    if n is None:
        return dict(DEFAULT_SPLIT_SIZES)
    ratio = DEFAULT_SPLIT_SIZES["test"] / DEFAULT_SPLIT_SIZES["train"]
    return {"train": n, "test": max(1, round(n * ratio)) if n > 0 else 0}


@click.command("synth")
@click.option("--out", required=True, type=click.Path(file_okay=False), help="Dataset root to write (or resume).")
@click.option("--n", "n", type=click.IntRange(min=0), default=None,
              help="Samples in --split (with 'both': train, and test in the paper's proportion). "
                   "Default: 4115 train, 460 test.")
@click.option("--size", type=click.IntRange(16, 1024), default=256, show_default=True, help="Image side (px).")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Random seed: the same seed, size and settings give the same samples.")
@click.option("--split", type=click.Choice(["both", "train", "test"]), default="both", show_default=True,
              help="Which split to write (both: train and test).")
@click.option("--textures", type=click.Path(exists=True, file_okay=False), default=None,
              help="Folder of texture images to use instead of procedural pottery textures.")
@click.option("--workers", type=click.IntRange(min=1), default=os.cpu_count() or 1, show_default="CPU count",
              help="Processes rendering samples.")
@click.option("--background", type=click.FloatRange(0, 1), default=1.0, show_default=True,
              help="Grey level of the plain background.")
@click.option("--tex-size", type=click.IntRange(min=0), default=0, help="Albedo map rows (0 = image size).")
@click.option("--shading-size", type=click.IntRange(min=0), default=0,
              help="Lighting grid side for the frontal third (0 = min(32, size/2): 32 x 96 over the full turn).")
@click.option("--random-roll", is_flag=True, help="Roll uniform in the geometry's range (default 0).")
@click.option("--random-translation", is_flag=True, help="tx, ty uniform in the geometry's range (default 0).")
def synth(out: str, n: int | None, size: int, seed: int, split: str, textures: str | None, workers: int,
          background: float, tex_size: int, shading_size: int, random_roll: bool, random_translation: bool) -> None:
    """Render synthetic vases with full ground truth (paper supplementary, "Synthetic Vases")."""
    cfg = SynthConfig(size=size, seed=seed, tex_size=tex_size, shading_size=shading_size, background=background,
                      random_roll=random_roll, random_translation=random_translation,
                      textures=os.path.abspath(textures) if textures else "")
    sizes = split_sizes(split, n)
    summary = generate(out, sizes, cfg, workers=workers)
    click.echo(f"synth: {summary.written} written, {summary.skipped} already done, {len(summary.failed)} failed "
               f"in {summary.seconds:.1f} s ({summary.rate:.2f} samples/s, {workers} worker(s)) -> {out} "
               f"(synthesis format {FORMAT_VERSION})")
    if summary.failed:
        click.echo(f"failures listed in {os.path.join(out, FAILURES_FILE)}", err=True)
        raise SystemExit(1)
