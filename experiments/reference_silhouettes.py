"""Careful reference silhouettes of real photographs, made independently of radar's locator: GrabCut over the
whole photo at 640 px seeded from the border's colour, then GrabCut again at full resolution in a band around
that outline. A few photos need hand-placed seeds (`SEEDS`); every reference was checked by eye on an overlay
(`python -m experiments.small_crops --overlays DIR`).

The reference is the vessel's whole outline, handles included, the backdrop seen between a handle and the body
excluded.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

COARSE_SIDE = 640  # the first cut runs at this long side
BAND = 6  # the full-resolution cut decides only this many pixels either side of the coarse outline (at 640 px: 2)

# Hand-tuned seeds, per photo: (sure backdrop rectangles, sure object rectangles) as fractions of the photo
# (x0, y0, x1, y1). Only where the automatic cut was wrong on the overlay.
Box = tuple[float, float, float, float]
SEEDS: dict[str, tuple[tuple[Box, ...], tuple[Box, ...]]] = {}


def _border_model(image: np.ndarray, width: int) -> tuple[np.ndarray, float]:
    """Per-row median colour of the left and right border strips (a sweep changes top to bottom) and its spread."""
    strips = np.concatenate([image[:, :width], image[:, -width:]], axis=1).astype(np.float32)
    rows = np.median(strips, axis=1)  # H x 3
    spread = float(np.median(np.abs(strips - rows[:, None]).sum(2))) + 4.0
    return rows, spread


def _coarse(image: np.ndarray, name: str) -> np.ndarray:
    """H x W bool first cut of a COARSE_SIDE photo."""
    h, w = image.shape[:2]
    band = max(4, round(0.02 * max(h, w)))
    rows, spread = _border_model(image, band)
    dist = np.abs(image.astype(np.float32) - rows[:, None]).sum(2)
    tri = np.full((h, w), cv2.GC_PR_BGD, np.uint8)
    tri[dist > 4 * spread] = cv2.GC_PR_FGD
    tri[:band], tri[:, :band], tri[:, -band:] = cv2.GC_BGD, cv2.GC_BGD, cv2.GC_BGD
    bottom = dist[-band:] < 4 * spread  # the floor may hold the foot: only its backdrop-coloured pixels are sure
    tri[-band:][bottom] = cv2.GC_BGD
    _apply_seeds(tri, name)
    _grabcut(image, tri, 6)
    return _tidy((tri == cv2.GC_FGD) | (tri == cv2.GC_PR_FGD))


def _apply_seeds(tri: np.ndarray, name: str) -> None:
    h, w = tri.shape
    back, front = SEEDS.get(name, ((), ()))
    for boxes, label in ((back, cv2.GC_BGD), (front, cv2.GC_FGD)):
        for x0, y0, x1, y1 in boxes:
            tri[round(y0 * h) : round(y1 * h), round(x0 * w) : round(x1 * w)] = label


def _grabcut(image: np.ndarray, tri: np.ndarray, iterations: int) -> None:
    bgd, fgd = np.zeros((1, 65), np.float64), np.zeros((1, 65), np.float64)
    cv2.setRNGSeed(0)
    cv2.grabCut(np.ascontiguousarray(image), tri, None, bgd, fgd, iterations, cv2.GC_INIT_WITH_MASK)


def _tidy(mask: np.ndarray) -> np.ndarray:
    """The largest part, holes under 0.3 % of it filled (a gap beside a handle is larger and stays)."""
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    if n <= 1:
        return mask
    main = labels == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    n, labels, stats, _ = cv2.connectedComponentsWithStats((~main).astype(np.uint8), connectivity=4)
    h, w = main.shape
    for i in range(1, n):
        x, y, bw, bh, area = stats[i]
        if x > 0 and y > 0 and x + bw < w and y + bh < h and area < 0.003 * main.sum():
            main[labels == i] = True
    return main


def reference(photo: np.ndarray, name: str) -> np.ndarray:
    """H x W bool reference silhouette of the one vessel in an H x W x 3 uint8 RGB photo."""
    h, w = photo.shape[:2]
    k = COARSE_SIDE / max(h, w)
    small = cv2.resize(photo, (round(w * k), round(h * k)), interpolation=cv2.INTER_AREA)
    coarse = cv2.resize(_coarse(small, name).astype(np.uint8), (w, h), interpolation=cv2.INTER_LINEAR) > 0
    cols, rows = np.nonzero(coarse.any(0))[0], np.nonzero(coarse.any(1))[0]
    x0, y0 = max(0, cols.min() - 4 * BAND), max(0, rows.min() - 4 * BAND)
    x1, y1 = min(w, cols.max() + 4 * BAND), min(h, rows.max() + 4 * BAND)
    part = coarse[y0:y1, x0:x1].astype(np.uint8)
    disk = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * BAND + 1, 2 * BAND + 1))
    tri = np.full(part.shape, cv2.GC_BGD, np.uint8)
    tri[cv2.dilate(part, disk) > 0] = cv2.GC_PR_BGD
    tri[part > 0] = cv2.GC_PR_FGD
    tri[cv2.erode(part, disk) > 0] = cv2.GC_FGD
    _grabcut(photo[y0:y1, x0:x1], tri, 3)
    out = np.zeros((h, w), bool)
    out[y0:y1, x0:x1] = (tri == cv2.GC_FGD) | (tri == cv2.GC_PR_FGD)
    return _tidy(out)


def cached_reference(photo: np.ndarray, name: str, folder: Path) -> np.ndarray:
    """`reference`, kept as folder/<name>.png (recomputed when missing)."""
    from radar_cli.fileio import read_image, write_image

    path = folder / f"{name}.png"
    if path.is_file():
        mask = read_image(path, "L") > 127
        if mask.shape == photo.shape[:2]:
            return mask
    mask = reference(photo, name)
    write_image(path, mask.astype(np.uint8) * 255)
    return mask
