"""A contact sheet of de-rendered catalogue photographs beside the catalogue's drawing, to look at.

    python -m experiments.catalogue_sheet RESULTS OUT.png [--drawings DIR] [--only NAME ...] [--side 160]

One row per result folder (or those named by --only): the network's input crop, the reconstruction, the normals,
the first turntable frame (when the folder has turntable.png) and the drawing `DIR/<id>-profile.png` of the
object id before the first `_` of the folder's name.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np

from radar_cli.fileio import read_image, write_image
from radar_cli.results import INPUT_FILE, NORMAL_RENDERED_FILE, RECON_FILE, TURNTABLE_STRIP_FILE


def _tile(image: np.ndarray | None, side: int) -> np.ndarray:
    """An image fitted into a white side x side tile (blank where None)."""
    tile = np.full((side, side, 3), 255, np.uint8)
    if image is None:
        return tile
    h, w = image.shape[:2]
    k = side / max(h, w)
    small = cv2.resize(image, (max(1, int(w * k)), max(1, int(h * k))), interpolation=cv2.INTER_AREA)
    y, x = (side - small.shape[0]) // 2, (side - small.shape[1]) // 2
    tile[y : y + small.shape[0], x : x + small.shape[1]] = small
    return tile


def row(folder: Path, drawings: Path | None, side: int) -> np.ndarray:
    """One result's tiles side by side, its name written on the first."""
    read = lambda p: read_image(p, "RGB") if p.is_file() else None  # noqa: E731
    strip = read(folder / TURNTABLE_STRIP_FILE)
    frame = None if strip is None else strip[:, : strip.shape[0]]
    drawing = None if drawings is None else read(drawings / f"{folder.name.split('_')[0]}-profile.png")
    tiles = [_tile(read(folder / f), side) for f in (INPUT_FILE, RECON_FILE, NORMAL_RENDERED_FILE)]
    tiles += [_tile(frame, side), _tile(drawing, side)]
    cv2.putText(tiles[0], folder.name, (4, 14), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (200, 0, 0), 1)
    return np.concatenate(tiles, 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("results", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--drawings", type=Path)
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--side", type=int, default=160)
    args = parser.parse_args()
    folders = sorted(d for d in args.results.iterdir() if d.is_dir() and not d.name.startswith("."))
    if args.only:
        folders = [d for d in folders if d.name in set(args.only)]
    if not folders:
        raise SystemExit(f"{args.results}: no result folders")
    write_image(args.out, np.concatenate([row(d, args.drawings, args.side) for d in folders], 0))


if __name__ == "__main__":
    main()
