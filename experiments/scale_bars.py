"""Real photographs with a black-and-white scale bar laid in front of the vessel, as documentation photographs
show one: does the bar stay out of the located object?

    python -m experiments.scale_bars OUT [--shared ../shared] [--seed 11] [--apart]

writes OUT/<name>_<place>.jpg for the front and side-ba views of the 5 whole kraters of `cva10` and the 12 Met
photographs of `real_vases`: the photo cut 4 % of its height under the vessel's lowest row (as `locate_object`
finds it) and given 12 % more backdrop below (the bottom rows' colour), with a bar of 10 equal segments (half to
nine tenths of the vessel's width long, 1.2-2.2 % of the photo's height tall, outlined in black) laid over the
foot's lowest rows (`centre`: under the axis; `offset`: moved by up to 0.3 of the vessel's width). With `--apart`
the bar lies 2-6 % of the height below the foot instead (`below`, `belowleft`) or stands upright beside it (`side`).
Then `radar derender OUT --out R --views 0` and `radar eval-catalog R --dimensions
../shared/data/cva10/objects.tsv` (docs/real-photos.md, "Scale bars").
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

from radar_cli.fileio import read_image
from radar_cli.masks.locate import locate_object

SIZE = 256  # the located crop's side for finding the vessel's extent


def _bar(canvas: np.ndarray, x: int, y: int, w: int, h: int, vertical: bool = False, n: int = 10) -> None:
    """n equal black and white segments in place, outlined in black."""
    for k in range(n):
        value = 15 if k % 2 == 0 else 245
        if vertical:
            canvas[y + k * h // n : y + (k + 1) * h // n, x : x + w] = value
        else:
            canvas[y : y + h, x + k * w // n : x + (k + 1) * w // n] = value
    cv2.rectangle(canvas, (x, y), (x + w - 1, y + h - 1), (15, 15, 15), max(1, min(w, h) // 12))


def _extent(photo: np.ndarray) -> tuple[int, int, int]:
    """(lowest row, leftmost and rightmost column + 1) of the located vessel in the photo's pixels."""
    found = locate_object(photo, SIZE)
    whole = found.silhouette | found.appendages
    ys, xs = np.nonzero(whole)
    k = found.box.side / SIZE
    return (int(found.box.y0 + (ys.max() + 1) * k), int(found.box.x0 + xs.min() * k),
            int(found.box.x0 + (xs.max() + 1) * k))


def _extended(photo: np.ndarray, bottom: int, extra: int) -> np.ndarray:
    """The photo cut `bottom` rows down and `extra` rows of its bottom rows' colour added."""
    cut = photo[: min(photo.shape[0], bottom)].astype(np.float32)
    row = cv2.GaussianBlur(cut[-10:].mean(0, keepdims=True), (31, 1), 0)
    return np.concatenate([cut, np.repeat(row, extra, 0)], 0)


def make_case(photo: np.ndarray, rng: np.random.Generator, apart: bool) -> tuple[np.ndarray, str]:
    """One photo with a bar: (H' x W x 3 uint8, where the bar lies)."""
    h, w = photo.shape[:2]
    bottom, left, right = _extent(photo)
    canvas = _extended(photo, bottom + int(0.04 * h), int(0.12 * h))
    width = right - left
    tall = max(8, int(rng.uniform(0.012, 0.022) * h))
    place = str(rng.choice(["below", "belowleft", "side"] if apart else ["centre", "offset"]))
    if place == "side":
        col = cv2.GaussianBlur(canvas[:, -10:].mean(1, keepdims=True), (1, 31), 0)
        canvas = np.concatenate([canvas, np.repeat(col, int(0.2 * w), 1)], 1)
        length = int(rng.uniform(0.3, 0.5) * h)
        _bar(canvas, w + int(0.08 * w), bottom - length - int(rng.uniform(0.0, 0.05) * h), max(8, int(0.025 * w)),
             length, vertical=True)
    else:
        length = int(rng.uniform(0.5, 0.9) * width)
        x = left + (width - length) // 2
        if place in ("offset", "belowleft"):
            x = left + int(rng.uniform(-0.3, 0.3) * width)
        y = bottom + int(rng.uniform(0.02, 0.06) * h) if apart else bottom - int(rng.uniform(0.0, 0.5) * tall)
        _bar(canvas, int(np.clip(x, 0, canvas.shape[1] - length - 1)), y, length, tall)
    return np.clip(canvas, 0, 255).astype(np.uint8), place


def sources(shared: Path) -> list[tuple[str, Path]]:
    """(name, photo) of the krater views and the Met photographs."""
    cva = shared / "data" / "cva10" / "photos"
    found = [(f"{o}_{v}", cva / o / f"{v}.jpg") for o in ("73AE135", "77AE11", "81AE161", "83AE255", "86AE205")
             for v in ("front", "side-ba")]
    return found + [(p.stem, p) for p in sorted((shared / "data" / "real_vases").glob("*.jpg"))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--shared", type=Path, default=Path("../shared"))
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--apart", action="store_true", help="the bar apart from the vessel")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    for name, path in sources(args.shared):
        image, place = make_case(read_image(path, "RGB"), rng, args.apart)
        Image.fromarray(image).save(args.out / f"{name}_{place}.jpg", quality=92)
        print(name, place)


if __name__ == "__main__":
    main()
