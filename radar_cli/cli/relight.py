"""`radar relight`: re-render a de-rendered object under a new environment map from a new view."""

from __future__ import annotations

from pathlib import Path

import click

from radar_cli.derender.export.relight import relight as run_relight


@click.command("relight")
@click.argument("object_dir", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--env", "env", required=True, metavar="NAME|FILE",
              help="A built-in environment (studio, sunset, overcast, two_lights: those of the relit views radar "
                   "derender writes) or a map file: .hdr, .exr, .png/.jpg or .npy (equirectangular, camera frame).")
@click.option("--yaw", type=float, default=0.0, show_default=True, help="Spin about the object's axis (deg).")
@click.option("--pitch", type=float, default=None, help="Camera elevation in degrees (default: predicted).")
@click.option("--size", type=int, default=None, help="Image side in pixels (default: the input's).")
@click.option("--absolute", is_flag=True,
              help="Use the map's radiance as is (default: scaled to the exposure of the object's own lighting).")
@click.option("--out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="Image to write: .png, .jpg or .webp, in an existing folder.")
def relight(object_dir: Path, env: str, yaw: float, pitch: float | None, size: int | None, absolute: bool,
            out: Path) -> None:
    """Relight OBJECT_DIR (a folder written by `radar derender`) without the network."""
    click.echo(f"wrote {run_relight(object_dir, env, out, yaw, pitch, size, match=not absolute)}")
