"""Generated photographs with a known answer to "can a curator publish this?" (docs/real-photos.md, "What `ok`
means"): clean rendered vases on grey (should be `ok`) beside things that are not whole solids of revolution
(should not be): a flat patterned slab, a sherd cut-out, a vase's broken upper half with a jagged lower edge,
a vase with a head-shaped lid.

    python -m experiments.status_cases --out data/status_cases --n 4 --seed 3

writes <kind>_<i>.png and truth.tsv (name, kind, expected: ok or not).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import cv2
import numpy as np

from radar_cli.fileio import write_image, write_text
from radar_cli.masks.synthetic import composite, render_vases

KINDS = ("vase", "slab", "sherd", "broken", "lid")
EXPECTED = {"vase": "ok"}  # every other kind: not ok
SHAPE = (480, 400)


def _pattern(h: int, w: int, rng: np.random.Generator) -> np.ndarray:
    """h x w x 3 float painted surface: a ground colour with bands, a meander-like step motif and speckle."""
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    ground, paint = rng.uniform(0.15, 0.85, 3), rng.uniform(0.05, 0.9, 3)
    period = rng.uniform(0.12, 0.25) * h
    bands = np.sin(2 * math.pi * yy / period + rng.uniform(0, 6)) > rng.uniform(0.3, 0.8)
    cell = max(6.0, w / rng.uniform(6, 12))
    steps = ((xx // cell + yy // cell) % 3 == 0) & (np.sin(2 * math.pi * yy / (3 * period)) > 0.2)
    pick = (bands | steps).astype(np.float32)[..., None]
    img = ground * (1 - pick) + paint * pick
    return np.clip(img + rng.normal(0, 0.02, img.shape), 0, 1).astype(np.float32)


def _on_grey(obj: np.ndarray, mask: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Paste an h x w x 3 float object (inside its bool mask) centred on a plain grey SHAPE backdrop."""
    h, w = SHAPE
    grey = rng.uniform(0.55, 0.8)
    canvas = np.full((h, w, 3), grey, np.float32) + rng.normal(0, 0.008, (h, w, 3)).astype(np.float32)
    oh, ow = mask.shape
    top, left = (h - oh) // 2 + int(rng.integers(-10, 10)), (w - ow) // 2 + int(rng.integers(-10, 10))
    alpha = cv2.GaussianBlur(mask.astype(np.float32), (0, 0), 0.7)[..., None]
    region = canvas[top:top + oh, left:left + ow]
    region[:] = obj * alpha + region * (1 - alpha)
    return (canvas.clip(0, 1) * 255 + 0.5).astype(np.uint8)


def slab(rng: np.random.Generator) -> np.ndarray:
    """A flat patterned rectangle (a tile, a painted panel), evenly lit, on grey."""
    h, w = int(SHAPE[0] * rng.uniform(0.5, 0.7)), int(SHAPE[1] * rng.uniform(0.4, 0.65))
    light = 1.0 - rng.uniform(0.0, 0.1) * np.linspace(0, 1, h)[:, None, None]  # a faint sweep, no curvature
    return _on_grey(_pattern(h, w, rng) * light, np.ones((h, w), bool), rng)


def sherd(rng: np.random.Generator) -> np.ndarray:
    """An irregular broken piece: a polygon of 6-9 straight breaks around an ellipse, painted, nearly flat."""
    h, w = int(SHAPE[0] * rng.uniform(0.4, 0.6)), int(SHAPE[1] * rng.uniform(0.45, 0.7))
    n = int(rng.integers(6, 10))
    angles = np.sort(rng.uniform(0, 2 * math.pi, n))
    reach = rng.uniform(0.7, 1.0, n)
    pts = np.stack([w / 2 + 0.5 * w * reach * np.cos(angles), h / 2 + 0.5 * h * reach * np.sin(angles)], 1)
    mask = np.zeros((h, w), np.uint8)
    cv2.fillPoly(mask, [np.round(pts).astype(np.int32)], 1)
    tilt = 1.0 - rng.uniform(0.0, 0.15) * np.linspace(0, 1, w)[None, :, None]  # a slight bend: a wall piece
    return _on_grey(_pattern(h, w, rng) * tilt, mask > 0, rng)


def _vase(rng: np.random.Generator, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """One rendered vase pasted on a plain backdrop: (photo H x W x 3 uint8, its bool silhouette)."""
    vases, alpha, masks = render_vases(1, 320, seed=seed)
    return composite(vases[0], alpha[0], masks[0], "plain", rng, shape=SHAPE)


def broken(rng: np.random.Generator, seed: int) -> np.ndarray:
    """A vase's upper part, broken off below the shoulder along a jagged line: the rest is backdrop."""
    photo, mask = _vase(rng, seed)
    ys, xs = np.nonzero(mask)
    y0, y1 = ys.min(), ys.max()
    cut = y0 + rng.uniform(0.45, 0.65) * (y1 - y0)
    cols = np.arange(mask.shape[1])
    walk = np.cumsum(rng.normal(0, 1, cols.size))
    walk = walk - np.interp(cols, [0, cols.size - 1], [walk[0], walk[-1]])
    line = cut + (y1 - y0) * 0.08 * walk / max(float(np.abs(walk).max()), 1e-6)
    below = np.arange(mask.shape[0])[:, None] > line[None]
    grey = np.median(photo[~mask], axis=0)
    out = photo.copy()
    halo = cv2.dilate(mask.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0  # the pasted edge's blend too
    out[below & halo] = grey.astype(np.uint8)
    return out


def lid(rng: np.random.Generator, seed: int) -> np.ndarray:
    """A vase with a head-shaped lid: an off-centre skull, a nose on one side, a chin, not a solid of
    revolution."""
    photo, mask = _vase(rng, seed)
    ys, xs = np.nonzero(mask)
    top = ys.min()
    row = xs[ys == top]
    cx, width = int(row.mean()), max(20, int((xs.max() - xs.min()) * rng.uniform(0.45, 0.6)))
    head = np.zeros(mask.shape, np.uint8)
    r = width // 2
    cy = max(r + 2, top - int(0.8 * r))
    cv2.ellipse(head, (cx, cy), (int(0.8 * r), r), 0, 0, 360, 1, -1)
    side = 1 if rng.random() < 0.5 else -1
    nose = np.array([[cx + side * int(0.7 * r), cy - r // 4], [cx + side * int(1.25 * r), cy + r // 6],
                     [cx + side * int(0.7 * r), cy + r // 3]], np.int32)
    cv2.fillPoly(head, [nose], 1)
    cv2.rectangle(head, (cx - r // 2, cy), (cx + r // 2, top + 2), 1, -1)  # the neck the lid sits in
    colour = rng.uniform(0.2, 0.8, 3) * 255
    shade = np.clip(1.0 - 0.5 * np.abs(np.arange(mask.shape[1]) - cx) / max(r, 1), 0.5, 1.0)
    out = photo.astype(np.float32)
    paint = colour[None, None] * shade[None, :, None]
    out = np.where(head[..., None] > 0, paint, out)
    return out.clip(0, 255).astype(np.uint8)


def make_cases(out: Path, n: int, seed: int) -> list[tuple[str, str]]:
    """Write n photographs of each kind (KINDS) into `out`; returns (name, kind) rows."""
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for i in range(n):
        rng = np.random.default_rng(seed * 1000 + i)
        vase_seed = seed * 100 + i
        images = {"vase": _vase(rng, vase_seed)[0], "slab": slab(rng), "sherd": sherd(rng),
                  "broken": broken(rng, vase_seed + 50), "lid": lid(rng, vase_seed + 70)}
        for kind in KINDS:
            name = f"{kind}_{i:02d}"
            write_image(out / f"{name}.png", images[kind])
            rows.append((name, kind))
    lines = ["name\tkind\texpected"] + [f"{n}\t{k}\t{EXPECTED.get(k, 'not')}" for n, k in rows]
    write_text(out / "truth.tsv", "\n".join(lines) + "\n")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--n", type=int, default=4)
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args()
    rows = make_cases(args.out, args.n, args.seed)
    print(f"{len(rows)} photographs in {args.out}")


if __name__ == "__main__":
    main()
