"""One photograph -> its object crops: load (fast, downscaled JPEG decode), detect, refine, crop, score."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
from PIL import Image, ImageOps

from radar_cli.errors import InputError
from radar_cli.fileio import image_errors, read_image
from radar_cli.masks import crop as crops
from radar_cli.masks.detect import Detection, detect
from radar_cli.masks.quality import Thresholds, judge, score_mask
from radar_cli.masks.refine import main_component, refine
from radar_cli.masks.scale_bar import find_scale_bar

MIN_PHOTO_SIDE = 64  # photos whose long edge is shorter than this cannot give a useful crop ...
MIN_PHOTO_SHORT = 16  # ... nor those whose short edge is (a slender vessel's thumbnail, 60 x 190 px, can)
REFINE_PAD = 1.3  # the refinement window is this much larger than the final crop, so GrabCut sees backdrop


@dataclass(frozen=True)
class Settings:
    """How crops are made and judged."""

    size: int = 256
    """Side of the output crops in pixels."""
    margin: float = crops.DEFAULT_MARGIN
    """Per-side margin as a fraction of the crop (the object spans 1 - 2 * margin of the crop)."""
    limits: Thresholds = field(default_factory=Thresholds)


@dataclass(frozen=True)
class Crop:
    """One object's crop.

    Attributes:
        image: size x size x 3 uint8 RGB.
        mask: size x size bool silhouette.
        box: the crop window in the (decoded) photo's pixels, plus `photo_scale`: decoded / original pixels.
        scores: quality scores (area, touches_border, solidity, symmetry) and `detector`, `grabcut`.
        reasons: why it is rejected; empty if accepted.
    """

    image: np.ndarray
    mask: np.ndarray
    box: crops.CropBox
    photo_scale: float
    scores: dict
    reasons: list[str]

    @property
    def accepted(self) -> bool:
        return not self.reasons

    def original_box(self) -> list[float]:
        """The crop window [x0, y0, side] in the original photo's pixels (upright, after EXIF rotation)."""
        s = self.photo_scale
        return [round(self.box.x0 / s, 1), round(self.box.y0 / s, 1), round(self.box.side / s, 1)]


def load_photo(path: str | Path, min_long_side: int = 1024) -> tuple[np.ndarray, float]:
    """Read a photo as H x W x 3 uint8 RGB, upright (EXIF orientation applied). Big JPEGs are decoded at 1/2,
    1/4 or 1/8 scale (DCT draft, several times faster) when that still leaves a long edge >= `min_long_side`;
    other formats go through `fileio.read_image` (grey, RGBA, CMYK, 16-bit, bomb limit).

    Returns:
        (image, scale = decoded pixels per pixel of the upright original).
    """
    path = Path(path)
    with image_errors(path), Image.open(path) as im:
        if im.format == "JPEG":
            original = im.size
            want = min_long_side / max(original)
            if want < 0.5:
                im.draft("RGB", (max(1, int(original[0] * want)), max(1, int(original[1] * want))))
            rgb = np.asarray(ImageOps.exif_transpose(im).convert("RGB")).copy()
            return rgb, _decoded_scale(rgb, original)
    return read_image(path, "RGB"), 1.0


def _decoded_scale(rgb: np.ndarray, original: tuple[int, int]) -> float:
    """Decoded pixels per original pixel, whatever the EXIF rotation did to the axes."""
    return max(rgb.shape[:2]) / max(original)


def check_photo(image: np.ndarray, name: str) -> None:
    """Raise InputError if a photo cannot give a crop (too small, or one flat colour)."""
    h, w = image.shape[:2]
    if max(h, w) < MIN_PHOTO_SIDE or min(h, w) < MIN_PHOTO_SHORT:
        raise InputError(f"{name}: image too small ({w} x {h} px, need >= {MIN_PHOTO_SIDE} on the long edge and "
                         f">= {MIN_PHOTO_SHORT} on the short)")
    if int(image.max()) - int(image.min()) < 8:
        raise InputError(f"{name}: image is a flat colour, nothing to segment")


@dataclass(frozen=True)
class Refined:
    """One detection refined at crop resolution.

    Attributes:
        mask: n x n bool object mask of `window` (n = its work side).
        window: the square window of the photo it covers (may reach beyond the photo's edge).
        outside: n x n bool, the window's padding beyond the photo's edge.
        grabcut: whether GrabCut's answer was kept.
        image: n x n x 3 uint8, the window's pixels.
    """

    mask: np.ndarray
    window: crops.CropBox
    outside: np.ndarray
    grabcut: bool
    image: np.ndarray
    def framed(self, image: np.ndarray, mask: np.ndarray, settings: Settings, box_mask: np.ndarray | None = None,
               fill: float | None = None) -> tuple[crops.CropBox, np.ndarray, np.ndarray]:
        """The final square crop around `box_mask` (default `mask`; n x n bool in this window): (its box in the
        photo, size x size x 3 uint8 image padded as `crops.cut` with `fill`, `mask` cut to size x size bool)."""
        n = self.mask.shape[0]
        box = crops.mask_box(mask if box_mask is None else box_mask) or (0, 0, n, n)
        k = self.window.side / n  # photo pixels per work pixel
        w = self.window
        final = crops.square_box((w.x0 + box[0] * k, w.y0 + box[1] * k, w.x0 + box[2] * k, w.y0 + box[3] * k),
                                 settings.margin)
        to_final = crops.crop_affine(final, settings.size, 1.0 / k) @ np.vstack(
            [[1, 0, w.x0 / k], [0, 1, w.y0 / k], [0, 0, 1]])
        return final, crops.cut(image, final, settings.size, fill), crops.warp_mask(mask, to_final, settings.size)


def refine_window(found: Detection, settings: Settings) -> tuple[crops.CropBox, int]:
    """The square window of the photo a detection is refined in, and its side in work pixels."""
    fill_margin = 0.5 - (1.0 - 2.0 * settings.margin) / (2.0 * REFINE_PAD)
    return crops.square_box(found.box, fill_margin), int(round(settings.size * REFINE_PAD))


def refine_detection(image: np.ndarray, found: Detection, settings: Settings) -> Refined:
    """GrabCut one detection in a window a little larger than its final crop. The window's padding beyond the
    photo's edge is painted in the backdrop's colour and is never object, so a vessel cut by the frame ends at
    the frame.

    Args:
        image: H x W x 3 uint8 (the decoded photo the detection's box refers to).
        found: a detection in that photo.
        settings: sizes.
    """
    window, work_side = refine_window(found, settings)
    work_img = crops.cut(image, window, work_side)
    outside = crops.outside_mask(window, image.shape, work_side)
    to_work = crops.crop_affine(window, work_side, found.scale)
    rough = crops.warp_mask(found.mask, to_work, work_side)
    sure = None if found.sure is None else crops.warp_mask(found.sure, to_work, work_side)
    backdrop = ~rough & ~outside
    if outside.any() and backdrop.any():
        work_img[outside] = np.median(work_img[backdrop], axis=0).astype(np.uint8)
    mask, used_grabcut = refine(work_img, rough, sure=sure, outside=outside)
    if not mask.any():
        mask = rough & ~outside if (rough & ~outside).any() else ~outside
    bar = find_scale_bar(work_img, mask)  # a scale bar laid against the foot is no part of the vessel
    if bar is not None and (mask & ~bar).any():
        mask = main_component(mask & ~bar)
    return Refined(mask, window, outside, used_grabcut, work_img)


def crop_detection(image: np.ndarray, found: Detection, settings: Settings) -> Crop:
    """Refine one detection at crop resolution and cut the final, scored crop.

    Args:
        image: H x W x 3 uint8 (the decoded photo the detection's box refers to).
        found: a detection in that photo.
        settings: sizes and thresholds.
    """
    refined = refine_detection(image, found, settings)
    final, out_img, out_mask = refined.framed(image, refined.mask, settings)
    scores = score_mask(out_mask, crops.valid_region(final, image.shape, settings.size))
    scores.update(detector=round(found.score, 4), grabcut=refined.grabcut)
    return Crop(out_img, out_mask, final, 1.0, scores, judge(scores, settings.limits))


Detector = Callable[[np.ndarray], list[Detection]]


def process_image(image: np.ndarray, settings: Settings, detector: Detector = detect,
                  name: str = "image") -> list[Crop]:
    """All object crops of one decoded photo (H x W x 3 uint8); InputError if it cannot give any."""
    check_photo(image, name)
    return [crop_detection(image, found, settings) for found in detector(image)]


def process_photo(path: str | Path, settings: Settings, detector: Detector = detect) -> list[Crop]:
    """Load a photo file and return its crops, with crop boxes in the original photo's pixels."""
    image, scale = load_photo(path, min_long_side=max(768, 3 * settings.size))
    found = process_image(image, settings, detector, str(path))
    return [Crop(c.image, c.mask, c.box, scale, c.scores, c.reasons) for c in found]
