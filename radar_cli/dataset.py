"""The one on-disk sample layout that `radar synth` and `radar masks` write and `radar train` reads.

    DATA/<split>/<sample id>/image.png   RGB crop, square
    DATA/<split>/<sample id>/mask.png    silhouette, L mode, 255 = object
    DATA/<split>/<sample id>/...         optional: ground truth (synth) or meta.json (masks)

Splits are folder names (`train`, `test`); sample ids are folder names made of [A-Za-z0-9._-].
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from radar_cli.errors import InputError
from radar_cli.fileio import PNG_LEVEL, read_image, write_image

IMAGE_FILE = "image.png"
MASK_FILE = "mask.png"
SPLITS = ("train", "test")
_ID_RE = re.compile(r"^[A-Za-z0-9._-]{1,128}$")


@dataclass(frozen=True)
class SampleRef:
    """Where one sample lives."""

    root: Path
    split: str
    sample_id: str

    @property
    def folder(self) -> Path:
        return self.root / self.split / self.sample_id

    @property
    def image_path(self) -> Path:
        return self.folder / IMAGE_FILE

    @property
    def mask_path(self) -> Path:
        return self.folder / MASK_FILE


def safe_id(text: str) -> str:
    """Turn any string into a sample id (letters, digits, '.', '_', '-'), never a path."""
    cleaned = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._")[:128]
    if not cleaned:
        raise InputError(f"cannot make a sample id from {text!r}")
    return cleaned


def sample_ref(root: str | Path, split: str, sample_id: str) -> SampleRef:
    """A SampleRef, validating the split and id so no path is built from arbitrary strings."""
    if not _ID_RE.match(split) or not _ID_RE.match(sample_id) or sample_id in (".", ".."):
        raise InputError(f"bad split or sample id: {split!r}/{sample_id!r}")
    return SampleRef(Path(root), split, sample_id)


def is_dataset(root: str | Path) -> bool:
    """True if `root` holds at least one `<split>/<id>/image.png`."""
    root = Path(root)
    return root.is_dir() and any(root.glob(f"*/*/{IMAGE_FILE}"))


def list_samples(root: str | Path, split: str) -> list[SampleRef]:
    """All complete samples (image and mask present) of a split, sorted by id."""
    split_dir = Path(root) / split
    if not split_dir.is_dir():
        raise InputError(f"{split_dir}: no such split folder")
    refs = []
    for d in sorted(split_dir.iterdir()):
        if d.is_dir() and _ID_RE.match(d.name) and (d / IMAGE_FILE).is_file() and (d / MASK_FILE).is_file():
            refs.append(SampleRef(Path(root), split, d.name))
    return refs


def read_sample(ref: SampleRef) -> tuple[np.ndarray, np.ndarray]:
    """Image (H x W x 3 uint8) and mask (H x W bool) of a sample; InputError names the file on any problem."""
    image = read_image(ref.image_path, "RGB")
    mask = read_image(ref.mask_path, "L") > 127
    if image.shape[:2] != mask.shape:
        raise InputError(f"{ref.mask_path}: size {mask.shape} does not match image {image.shape[:2]}")
    return image, mask


def write_sample(ref: SampleRef, image: np.ndarray, mask: np.ndarray, png_level: int = PNG_LEVEL) -> None:
    """Write a sample's image (H x W x 3, float [0,1] or uint8) and mask (H x W bool); atomic per file."""
    for name, array in sample_images(image, mask).items():
        write_image(ref.folder / name, array, png_level)


def sample_images(image: np.ndarray, mask: np.ndarray) -> dict[str, np.ndarray]:
    """{IMAGE_FILE: the image as given, MASK_FILE: H x W uint8 0/255}: what a sample folder holds."""
    return {IMAGE_FILE: image, MASK_FILE: (mask > 0.5).astype(np.uint8) * 255}
