"""`radar derender`: de-render photographs into per-object folders with meshes, maps, renders and a gallery."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from radar_cli.derender.export.object_folder import MIN_VIEW_SIZE, ExportConfig
from radar_cli.derender.present.contact_sheet import contact_sheet as write_contact_sheet
from radar_cli.derender.refine.driver import REFINE_MODES
from radar_cli.derender.run.batch import DerenderOptions
from radar_cli.derender.run.inputs import DEFAULT_RESOLUTION, MAX_RESOLUTION, MIN_RESOLUTION, Resolution
from radar_cli.derender.run.launch import derender_sharded
from radar_cli.derender.run.predictor import ALBEDO_SOURCES, PITCH_SOURCES, Predictor
from radar_cli.derender.run.shard import Shard


class ResolutionType(click.ParamType):
    """--resolution: an integer side in [MIN_RESOLUTION, MAX_RESOLUTION] or `photo`."""

    name = "SIDE|photo"

    def convert(self, value, param, ctx) -> Resolution:
        if value == "photo" or isinstance(value, int):
            return value
        try:
            side = int(value)
        except ValueError:
            self.fail(f"expected an integer side in px or 'photo', got {value!r}", param, ctx)
        if not MIN_RESOLUTION <= side <= MAX_RESOLUTION:
            self.fail(f"{side} is not in [{MIN_RESOLUTION}, {MAX_RESOLUTION}]", param, ctx)
        return side


RESOLUTION = ResolutionType()


@click.command("derender")
@click.argument("inputs", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("--out", required=True, type=click.Path(file_okay=False, path_type=Path),
              help="Results folder: one sub-folder per object, plus index.html, summary.csv, failures.csv.")
@click.option("--checkpoint", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Model weights (.safetensors); default: the bundled model.")
@click.option("--masks", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Folder of known silhouettes (<stem>.png or <stem>/mask.png) used to crop.")
@click.option("--crop", type=click.Choice(["auto", "none"]), default="auto", show_default=True,
              help="auto: locate the object and crop around it as `radar masks` does (dataset samples are "
                   "crops already); none: pad the whole photo to a square.")
@click.option("--backdrop", type=click.Choice(["white", "keep"]), default="white", show_default=True,
              help="white: put the object on white through its silhouette (found by --crop auto, --masks or a "
                   "dataset's mask.png) before the network, as synthetic training images are; keep: as photographed.")
@click.option("--device", default="auto", show_default=True, help="auto, cpu, cuda or cuda:N.")
@click.option("--albedo", type=click.Choice(ALBEDO_SOURCES), default="divided", show_default=True,
              help="divided: the photo's texture divided by the predicted shading (keeps painted detail); "
                   "network: the albedo network's output, as the paper.")
@click.option("--pitch", type=click.Choice(PITCH_SOURCES), default="network", show_default=True,
              help="network: the shape network's pitch; search: the pitch whose re-rendering best matches the "
                   "photo and its silhouette, searched over the range (slower).")
@click.option("--refine", type=click.Choice(REFINE_MODES), default="full", show_default=True,
              help="full: fit each object's shape and pose to its silhouette and rim at the output resolution, "
                   "re-read lighting, material and albedo there (the specular albedo with --specular-reader), then "
                   "fit the environment map to the photo's shading; shape: the same without the lighting fit; "
                   "none: the network's prediction as it is.")
@click.option("--specular-reader", "reader", default="bundled", show_default=True, metavar="bundled|none|FILE",
              help="With --refine full or shape: the specular-albedo reader (`radar train-reader`) that reads it "
                   "at the fitted shape; none: the lighting network's reading, at most 1.")
@click.option("--views", type=click.IntRange(0, 360), default=8, show_default=True, help="Turntable frames.")
@click.option("--resolution", type=RESOLUTION, default=str(DEFAULT_RESOLUTION), show_default=True,
              help="Side in pixels of the outputs (crop, renders, the frontal third of the maps): an integer, "
                   "or 'photo' for each crop's own size; never more than the crop's pixels in the photo. At the "
                   "network's side the network-only outputs are written.")
@click.option("--view-size", type=click.IntRange(16, 1024), default=None,
              help="Side in pixels of turntable frames, relit views and the material sphere "
                   f"[default: the output side, at least {MIN_VIEW_SIZE}].")
@click.option("--env", "envs", multiple=True, type=click.Path(dir_okay=False, path_type=Path),
              help="Extra relighting environment map (.hdr, .exr, .png, .npy); repeatable.")
@click.option("--batch-size", type=click.IntRange(1, 1024), default=8, show_default=True,
              help="Images per network batch.")
@click.option("--workers", type=click.IntRange(0, 64), default=2, show_default=True,
              help="Objects de-rendered at a time: processes where the model runs on the CPU (each holds its own "
                   "copy, about 0.7 GB at 512 px), threads beside a GPU.")
@click.option("--threads", type=click.IntRange(1, 256), default=1, show_default=True,
              help="torch threads for the network (more helps only on an otherwise idle machine).")
@click.option("--overwrite", is_flag=True, help="Redo objects whose folders are already complete.")
@click.option("--shard", "shard", default="0/1", show_default=True, metavar="K/N",
              help="De-render only share K (0..N-1) of N, for batch schedulers; under torchrun each rank takes "
                   "its share by itself. Every share writes into the same --out.")
@click.option("--dimensions", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Table of catalogued sizes (TSV or CSV: an object/id column, height_cm, optional rim_cm, "
                   "body_cm, foot_cm): results named <id> or <id>_<view>, or photos in a folder <id>/, get meshes "
                   "in metres at that height; its title, object_name, kind or shape columns are read by the status "
                   "(a fragment, a head vase, a lid: review). Without it a harvested record's size and title are "
                   "used where there is one.")
@click.option("--contact-sheet", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Also write a contact sheet PNG (input, reconstruction, albedo, relit view per object).")
def derender(inputs: tuple[Path, ...], out: Path, checkpoint: Path | None, masks: Path | None, crop: str,
             backdrop: str, device: str, albedo: str, pitch: str, refine: str, reader: str, resolution: Resolution,
             views: int, view_size: int | None, envs: tuple[Path, ...], batch_size: int, workers: int,
             threads: int, overwrite: bool, shard: str, dimensions: Path | None,
             contact_sheet: Path | None) -> None:
    """De-render INPUTS (image files, folders, prepared dataset folders) into --out.

    On many processes or machines: `torchrun --nnodes N --nproc_per_node P -m radar_cli derender ...` (rank 0
    writes the report for all), or one `--shard K/N` job per share. Rerunning the same command finishes the
    objects a killed process left."""
    def load(dev: str) -> Predictor:
        return Predictor.from_checkpoint(checkpoint, dev, albedo, pitch, refine, reader)  # type: ignore[arg-type]

    options = DerenderOptions(out=out, crop=crop, backdrop=backdrop, masks=masks,  # type: ignore[arg-type]
                              envs=envs, batch_size=batch_size, workers=workers, threads=threads, overwrite=overwrite,
                              export=ExportConfig(views, view_size), resolution=resolution, shard=Shard.parse(shard),
                              dimensions=dimensions, processes=True)
    summary = derender_sharded(list(inputs), load, options, device, say=lambda line: click.echo(line, err=True))
    if contact_sheet is not None and summary.index is not None and (summary.done or summary.skipped):
        click.echo(f"contact sheet: {write_contact_sheet(out, contact_sheet)}")
    if summary.printed:
        click.echo(summary.line())
    if summary.index is not None:
        click.echo(f"gallery: {summary.index}")
    if summary.failures:
        click.echo(f"{len(summary.failures)} input(s) failed: see {out / 'failures.csv'}", err=True)
        sys.exit(1)
