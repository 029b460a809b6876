"""The CVA 10 side views as other photographers and sites would give them: how stable are the pitch, the ratios
and the status when the same vessel is photographed at another size, mirrored, exposed darker, cropped closer or
given more backdrop?

    python -m experiments.photo_variants OUT [--shared ../shared] [--kind whole|fragment]

writes OUT/<object>_<view>_<variant>.jpg for every object of that kind in `cva10/objects.tsv` and each of its
views but the top view (the 5 whole kraters' 20 side views, or the 8 fragments' outsides and insides), in up to 22
variants (`--variants` picks some):

- `orig`: the photograph as it is (a copy of the file; the others are written at JPEG quality 90);
- `half`, `quarter`: scaled to 1/2 and 1/4 (about 850 and 430 px; the quarter is a web image's size);
- `flip`: mirrored left to right (a solid of revolution's fit should not care);
- `dark`: every channel raised to the power 1.4 (a darker exposure of the midtones);
- `tight`: cut to 84 % of the width and 91 % of the height, so the handles or the foot may touch the frame;
- `wide`: 15 % of the photo's size more backdrop on every side (the border pixels repeated);
- `bright`: every channel to the power 0.7 (a lighter exposure);
- `warm`: red up 8 %, blue down 14 % (another white balance);
- `flat`: contrast to 70 % over a grey haze (a faded scan);
- `tilt`: turned 3 deg counter-clockwise in the image plane (a camera not quite level), the border repeated;
- `lean`: turned 4.5 deg clockwise, the same way;
- `web`: 1/2 size at JPEG quality 40 (a compressed web copy);
- `cool`: red down 8 %, blue up 12 % (the other way from `warm`);
- `ramp`: lit unevenly, from 0.8 on the left to 1.1 on the right (every channel);
- `darkwarm`, `darkhalf`, `warmflip`, `brightquarter`: `dark` then `warm`; the power 1.3 at 1/2 size; `warm`
  mirrored; the power 0.75 at 1/4 size;
- `grey`: greyscale (luma, as an older catalogue's plate); `blur`: out of focus (Gaussian, sigma 2.5 px); `noise`:
  sensor noise (Gaussian, sigma 8 levels, the same draw for every photo).

Then `radar derender OUT --out R --views 1` and `radar eval-catalog R --dimensions
../shared/data/cva10/objects.tsv --drawings docs/data/cva10-profiles` (a result `73AE135_front_half` is matched
to the object `73AE135`).
"""

from __future__ import annotations

import argparse
import csv
import shutil
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

from radar_cli.fileio import read_image


def _scaled(k: float) -> Callable[[np.ndarray], np.ndarray]:
    def scale(image: np.ndarray) -> np.ndarray:
        h, w = image.shape[:2]
        return cv2.resize(image, (int(w * k), int(h * k)), interpolation=cv2.INTER_AREA)

    return scale


def _tight(image: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    return image[int(0.06 * h) : int(0.97 * h), int(0.08 * w) : int(0.92 * w)]


def _wide(image: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    dy, dx = int(0.15 * h), int(0.15 * w)
    return cv2.copyMakeBorder(image, dy, dy, dx, dx, cv2.BORDER_REPLICATE)


def _gamma(power: float) -> Callable[[np.ndarray], np.ndarray]:
    def tone(image: np.ndarray) -> np.ndarray:
        return np.clip(255.0 * (image / 255.0) ** power, 0, 255).astype(np.uint8)

    return tone


def _warm(image: np.ndarray) -> np.ndarray:
    return np.clip(image * np.array([1.08, 1.0, 0.86]), 0, 255).astype(np.uint8)


def _flat(image: np.ndarray) -> np.ndarray:
    return np.clip(0.7 * image.astype(np.float32) + 0.18 * 255, 0, 255).astype(np.uint8)


def _cool(image: np.ndarray) -> np.ndarray:
    return np.clip(image * np.array([0.92, 1.0, 1.12]), 0, 255).astype(np.uint8)


def _ramp(image: np.ndarray) -> np.ndarray:
    light = np.linspace(0.8, 1.1, image.shape[1])[None, :, None]
    return np.clip(image * light, 0, 255).astype(np.uint8)


def _grey(image: np.ndarray) -> np.ndarray:
    luma = image.astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)
    return np.repeat(np.clip(luma, 0, 255).astype(np.uint8)[..., None], 3, axis=2)


def _noise(image: np.ndarray) -> np.ndarray:
    grain = np.random.default_rng(0).normal(0.0, 8.0, image.shape)
    return np.clip(image + grain, 0, 255).astype(np.uint8)


def _turned(deg: float) -> Callable[[np.ndarray], np.ndarray]:
    def turn(image: np.ndarray) -> np.ndarray:
        h, w = image.shape[:2]
        affine = cv2.getRotationMatrix2D((w / 2, h / 2), deg, 1.0)
        return cv2.warpAffine(image, affine, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)

    return turn


VARIANTS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "half": _scaled(0.5),
    "quarter": _scaled(0.25),
    "flip": lambda image: image[:, ::-1],
    "dark": _gamma(1.4),
    "tight": _tight,
    "wide": _wide,
    "bright": _gamma(0.7),
    "warm": _warm,
    "flat": _flat,
    "tilt": _turned(3.0),
    "lean": _turned(-4.5),
    "web": _scaled(0.5),
    "cool": _cool,
    "ramp": _ramp,
    "darkwarm": lambda image: _warm(_gamma(1.4)(image)),
    "darkhalf": lambda image: _scaled(0.5)(_gamma(1.3)(image)),
    "warmflip": lambda image: _warm(image[:, ::-1]),
    "brightquarter": lambda image: _scaled(0.25)(_gamma(0.75)(image)),
    "grey": _grey,
    "blur": lambda image: cv2.GaussianBlur(image, (0, 0), 2.5),
    "noise": _noise,
}
QUALITY = {"web": 40}  # variants written at a lower JPEG quality than the others' 90


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--shared", type=Path, default=Path("../shared"))
    parser.add_argument("--kind", choices=("whole", "fragment"), default="whole")
    parser.add_argument("--variants", nargs="+", choices=("orig", *VARIANTS), default=("orig", *VARIANTS))
    args = parser.parse_args()
    cva = args.shared / "data" / "cva10"
    with open(cva / "objects.tsv", newline="") as table:
        rows = [row for row in csv.DictReader(table, delimiter="\t") if row["kind"] == args.kind]
    args.out.mkdir(parents=True, exist_ok=True)
    count = 0
    for row in rows:
        obj = row["object"]
        for view in sorted(set(row["views"].split()) - {"top"}):
            source = cva / "photos" / obj / f"{view}.jpg"
            if "orig" in args.variants:
                shutil.copyfile(source, args.out / f"{obj}_{view}_orig.jpg")
            photo = read_image(source, "RGB")
            for name, make in VARIANTS.items():
                if name not in args.variants:
                    continue
                variant = Image.fromarray(np.ascontiguousarray(make(photo)))
                variant.save(args.out / f"{obj}_{view}_{name}.jpg", quality=QUALITY.get(name, 90))
            count += len(args.variants)
    print(f"{count} photos in {args.out}")


if __name__ == "__main__":
    main()
