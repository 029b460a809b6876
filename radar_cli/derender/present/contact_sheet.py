"""A contact sheet of a results folder: one row per object with the input, the reconstruction, the albedo and
a relit view, labelled, as one PNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from radar_cli.derender.export.renders import relit_file
from radar_cli.derender.present.report import read_records
from radar_cli.errors import InputError
from radar_cli.fileio import write_image
from radar_cli.results import ALBEDO_RENDERED_FILE, INPUT_FILE, MASK_FILE, RECON_FILE

TILE = 160
LABEL_H = 16
NAME_W = 150
MAX_ROWS = 500


def tile(path: Path, matte: Path | None = None) -> Image.Image:
    """An image resized to TILE x TILE (grey if missing); with a matte (L mask), put on white outside it."""
    try:
        with Image.open(path) as im:
            tile = im.convert("RGB").resize((TILE, TILE), Image.Resampling.BILINEAR)
        if matte is not None:
            with Image.open(matte) as m:
                alpha = m.convert("L").resize((TILE, TILE), Image.Resampling.BILINEAR)
            tile = Image.composite(tile, Image.new("RGB", tile.size, (255, 255, 255)), alpha)
        return tile
    except (OSError, ValueError):
        return Image.new("RGB", (TILE, TILE), (200, 200, 200))


def contact_sheet(root: str | Path, out: str | Path, env: str = "studio") -> Path:
    """Write a contact sheet PNG of every complete object under `root`.

    Args:
        root: a `radar derender` results folder.
        out: the PNG to write.
        env: which relit view to show (a built-in name or a --env file's stem).

    Returns:
        The path written.
    """
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{root}: no such results folder")
    records = read_records(root)[:MAX_ROWS]
    if not records:
        raise InputError(f"{root}: no de-rendered objects to put on a contact sheet")
    columns = ((INPUT_FILE, "input"), (RECON_FILE, "reconstruction"), (ALBEDO_RENDERED_FILE, "albedo"),
               (relit_file(env), f"relit: {env}"))
    sheet = Image.new("RGB", (NAME_W + TILE * len(columns), LABEL_H + TILE * len(records)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for c, (_, label) in enumerate(columns):
        draw.text((NAME_W + c * TILE + 4, 2), label, fill=(0, 0, 0))
    for r, (name, _) in enumerate(records):
        y = LABEL_H + r * TILE
        draw.text((4, y + TILE // 2), name[:24], fill=(0, 0, 0))
        for c, (file, _) in enumerate(columns):
            matte = root / name / MASK_FILE if file == ALBEDO_RENDERED_FILE else None  # drawn on black for eval
            sheet.paste(tile(root / name / file, matte), (NAME_W + c * TILE, y))
    write_image(out, np.asarray(sheet))
    return Path(out)
