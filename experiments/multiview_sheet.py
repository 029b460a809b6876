"""The contact sheet of docs/multiview.md: for every object de-rendered from several views, its coverage map, its
turntable from the fused albedo, and the turntable that `radar derender` gives its first view alone (the front
mirrored round).

    .venv/bin/python -m experiments.multiview_sheet MULTI SINGLE OUT.png

MULTI: the results of `radar derender ROOT`; SINGLE: the results of `radar derender` on the same objects' photos
one by one (matched by the photo each object was drawn from).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from radar_cli.fileio import write_image
from radar_cli.results import COVERAGE_FILE, MATERIAL_FILE, TURNTABLE_STRIP_FILE

ROW_HEIGHT = 160


def _strip(path: Path, label: str) -> np.ndarray:
    """An image scaled to ROW_HEIGHT rows with a label in its corner."""
    image = Image.open(path).convert("RGB")
    image = image.resize((round(image.width * ROW_HEIGHT / image.height), ROW_HEIGHT), Image.Resampling.LANCZOS)
    ImageDraw.Draw(image).text((4, 4), label, fill=(0, 0, 0))
    return np.asarray(image)


def _sources(root: Path) -> dict[str, Path]:
    """Each object folder under root by the resolved photo it was drawn from."""
    found = {}
    for record in sorted(root.glob(f"*/{MATERIAL_FILE}")):
        source = json.loads(record.read_text(encoding="utf-8"))["source"]
        found[str(Path(source).resolve())] = record.parent
    return found


def main(multi: Path, single: Path, out: Path) -> None:
    singles = _sources(single)
    rows = []
    for source, folder in _sources(multi).items():
        if not (folder / COVERAGE_FILE).is_file() or source not in singles:
            continue
        parts = [_strip(folder / COVERAGE_FILE, f"{folder.name}: coverage"),
                 _strip(folder / TURNTABLE_STRIP_FILE, "all views fused"),
                 _strip(singles[source] / TURNTABLE_STRIP_FILE, "first view alone (mirrored)")]
        rows.append(np.concatenate([np.pad(parts[0], ((0, ROW_HEIGHT), (0, 0), (0, 0)), constant_values=255),
                                   np.concatenate(parts[1:], axis=0)], axis=1))
    width = max(r.shape[1] for r in rows)
    sheet = np.concatenate([np.pad(r, ((0, 8), (0, width - r.shape[1]), (0, 0)), constant_values=255) for r in rows])
    write_image(out, sheet)


if __name__ == "__main__":
    main(*(Path(a) for a in sys.argv[1:4]))
