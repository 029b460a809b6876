"""One 256-colour palette for a set of images and each pixel's nearest entry in it (the turntable GIF's frames).

The palette is Pillow's median cut over an evenly spread sample of the pixels; every pixel is then mapped to the
entry nearest to it in RGB (exactly: squared distances in integers, ties to the lower index), which draws the
images closer than median cut's own box-by-box mapping of every pixel, at a fraction of its cost
(docs/resolution.md)."""

from __future__ import annotations

import numpy as np
from PIL import Image

COLOURS = 256
SAMPLE_STRIDE = 61
"""Every 61st pixel of the flattened images feeds the median cut (34,000 of 8 frames at 512 px): a prime stride
walks through every column of images of any width, so a horizontal ramp keeps all its levels."""
CELL = 8  # side of the cubes of RGB space over which the candidates for the nearest entry are pruned
CHUNK = 65536  # colours whose candidates' distances are held at once


def palette_of(pixels: np.ndarray) -> np.ndarray:
    """The median-cut palette of a sample of `pixels` (M x 3 uint8): K x 3 int32, K <= 256 entries."""
    sample = np.ascontiguousarray(pixels[::SAMPLE_STRIDE])[None]  # 1 x M' x 3
    quantized = Image.fromarray(sample).quantize(COLOURS, method=Image.Quantize.MEDIANCUT)
    used = int(np.asarray(quantized).max()) + 1
    entries = quantized.getpalette() or []  # a "P" image always has one
    return np.asarray(entries[: 3 * used], np.int32).reshape(used, 3)


def _candidates(palette: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """For each RGB cube (C cube indices, side CELL), the entries that can be nearest to some colour in it:
    C x K bool. An entry is left out when its nearest point of the cube is farther than another entry's farthest."""
    per_axis = 256 // CELL
    near = np.zeros((len(cells), len(palette)), np.int32)
    far = np.zeros_like(near)
    for axis, lo in enumerate([cells // (per_axis * per_axis), (cells // per_axis) % per_axis, cells % per_axis]):
        lo = (lo.astype(np.int32) * CELL)[:, None]  # C x 1
        p = palette[None, :, axis]  # 1 x K
        below, above = lo - p, p - (lo + CELL - 1)  # C x K: > 0 where the entry lies outside the cube
        near += np.maximum(np.maximum(below, above), 0) ** 2
        far += np.maximum(-below, -above) ** 2
    return near <= far.min(1, keepdims=True)


def nearest_entries(colours: np.ndarray, palette: np.ndarray) -> np.ndarray:
    """The index of the entry of `palette` (K x 3 int32) nearest to each of `colours` (U x 3 int32 in 0..255),
    ties to the lower index: U uint8."""
    per_axis = 256 // CELL
    cube = colours // CELL
    cell = (cube[:, 0] * per_axis + cube[:, 1]) * per_axis + cube[:, 2]
    cells, of = np.unique(cell, return_inverse=True)
    allowed = _candidates(palette, cells)  # C x K
    count = allowed.sum(1)  # C
    # each cube's candidates in index order, padded with its first (a repeat never wins: argmin keeps the first)
    order = np.argsort(~allowed, axis=1, kind="stable")[:, : int(count.max())]  # C x width
    order = np.where(np.arange(order.shape[1])[None] < count[:, None], order, order[:, :1])
    out = np.empty(len(colours), np.uint8)
    bucket = np.ceil(np.log2(count[of])).astype(np.int64)  # U: the colours padded to the same power of two
    for b in np.unique(bucket):
        which = np.flatnonzero(bucket == b)
        for s in range(0, len(which), CHUNK):
            rows = which[s:s + CHUNK]
            cand = order[of[rows], : 1 << b]  # n x 2^b
            d = sum((palette[cand, k] - colours[rows, k, None]) ** 2 for k in range(3))  # n x 2^b
            out[rows] = np.take_along_axis(cand, d.argmin(1)[:, None], 1)[:, 0]
    return out


def quantize(images: list[np.ndarray]) -> tuple[list[np.ndarray], np.ndarray]:
    """Images (each H x W x 3 uint8) as indices into one shared palette.

    Returns:
        (each image's H x W uint8 indices, the palette K x 3 uint8)."""
    pixels = np.concatenate([im.reshape(-1, 3) for im in images])  # M x 3
    palette = palette_of(pixels)
    key = (pixels[:, 0].astype(np.int32) << 16) | (pixels[:, 1].astype(np.int32) << 8) | pixels[:, 2]
    seen = np.zeros(1 << 24, bool)
    seen[key] = True
    present = np.flatnonzero(seen)  # the distinct colours, as keys
    colours = np.stack([present >> 16, (present >> 8) & 255, present & 255], 1).astype(np.int32)
    lookup = np.zeros(1 << 24, np.uint8)
    lookup[present] = nearest_entries(colours, palette)
    index = lookup[key]
    bounds = np.cumsum([0] + [im.shape[0] * im.shape[1] for im in images])
    return ([index[a:b].reshape(im.shape[:2]) for a, b, im in zip(bounds[:-1], bounds[1:], images)],
            palette.astype(np.uint8))
