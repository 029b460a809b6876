"""Contact sheets: PNG grids of crops with their outline and scores, accepted (green) before rejected (red)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from radar_cli.fileio import read_image, write_image

THUMB = 128
COLUMNS = 10
MAX_PER_SHEET = 200


def thumbnail(image: np.ndarray, mask: np.ndarray, caption: str, accepted: bool) -> np.ndarray:
    """THUMB x THUMB x 3 uint8: the crop with the mask outline and a two-line caption."""
    thumb: np.ndarray = cv2.resize(image, (THUMB, THUMB), interpolation=cv2.INTER_AREA)
    m = cv2.resize(mask.astype(np.uint8), (THUMB, THUMB), interpolation=cv2.INTER_NEAREST)
    colour = (40, 200, 40) if accepted else (220, 40, 40)
    contours, _ = cv2.findContours(m, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    cv2.drawContours(thumb, contours, -1, colour, 1)
    cv2.rectangle(thumb, (0, 0), (THUMB - 1, THUMB - 1), colour, 2)
    thumb[THUMB - 24 : THUMB - 2, 2 : THUMB - 2] //= 3  # dark strip under the caption
    for k, line in enumerate(caption.split("\n")[:2]):
        cv2.putText(thumb, line[:26], (4, THUMB - 15 + 10 * k), cv2.FONT_HERSHEY_PLAIN, 0.65, (255, 255, 255), 1)
    return thumb


def caption(record: dict) -> str:
    """Two short lines: id, then symmetry / solidity / area (and the first rejection reason's word)."""
    s = record["scores"]
    line2 = f"sym{s['symmetry']:.2f} sol{s['solidity']:.2f} a{s['area']:.2f}"
    return f"{record['id'][:20]}\n{line2}"


def write_sheets(records: list[dict], root: Path, out_prefix: Path) -> list[Path]:
    """Write contact sheets for crop records (dicts with id, folder relative to root, accepted, scores).

    Returns:
        The PNG paths written (`<prefix>-001.png`, ...).
    """
    ordered = sorted(records, key=lambda r: (not r["accepted"], r["id"]))
    paths = []
    for start in range(0, len(ordered), MAX_PER_SHEET):
        chunk = ordered[start : start + MAX_PER_SHEET]
        tiles = []
        for rec in chunk:
            folder = root / rec["folder"]
            image = read_image(folder / "image.png", "RGB")
            mask = read_image(folder / "mask.png", "L") > 127
            tiles.append(thumbnail(image, mask, caption(rec), rec["accepted"]))
        rows = -(-len(tiles) // COLUMNS)
        sheet = np.full((rows * THUMB, min(len(tiles), COLUMNS) * THUMB, 3), 255, np.uint8)
        for k, tile in enumerate(tiles):
            r, c = divmod(k, COLUMNS)
            sheet[r * THUMB : (r + 1) * THUMB, c * THUMB : (c + 1) * THUMB] = tile
        path = out_prefix.with_name(f"{out_prefix.name}-{start // MAX_PER_SHEET + 1:03d}.png")
        write_image(path, sheet)
        paths.append(path)
    return paths
