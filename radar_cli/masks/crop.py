"""Square crops around an object, sized so it fills the frame like the renderer's vases fill theirs.

The network's camera sees a vase whose half-height is 0.5..0.95 of the half-view; a crop whose side is the
object's extent divided by `fill` (default 0.85) puts a real photo's object in the middle of that range.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

DEFAULT_MARGIN = 0.075  # per side, as a fraction of the crop: the object spans 1 - 2 * margin = 0.85


@dataclass(frozen=True)
class CropBox:
    """A square window of the original photo, in its pixels (may reach outside it; the outside is padded),
    turned by `turn` degrees (counter-clockwise, about the window's centre) where the photo was straightened:
    the crop shows the photo turned by `turn` so that a vessel's tilted axis stands upright."""

    x0: int
    y0: int
    side: int
    turn: float = 0.0

    def to_list(self) -> list[int]:
        return [self.x0, self.y0, self.side]

    def record(self) -> dict:
        """material.json's entries for the window: `crop_box` [x0, y0, side] and, where turned, `crop_turn` (deg)."""
        return {"crop_box": self.to_list(), **({"crop_turn": round(self.turn, 2)} if self.turn else {})}

    @classmethod
    def from_record(cls, record: dict) -> CropBox:
        """The window of a material.json record (`record`'s entries)."""
        x0, y0, side = (int(v) for v in record["crop_box"])
        return cls(x0, y0, side, float(record.get("crop_turn", 0.0)))


def mask_box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    """(x0, y0, x1, y1) half-open bounding box of a bool mask, or None if it is empty."""
    ys, xs = np.nonzero(mask)
    if len(xs) == 0:
        return None
    return int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1


def square_box(box: tuple[float, float, float, float], margin: float = DEFAULT_MARGIN) -> CropBox:
    """The square crop centred on `box` (x0, y0, x1, y1) whose side makes the box's longer extent span
    1 - 2 * margin of it."""
    x0, y0, x1, y1 = box
    fill = 1.0 - 2.0 * margin
    side = max(2, int(round(max(x1 - x0, y1 - y0) / fill)))
    cx, cy = (x0 + x1) / 2.0, (y0 + y1) / 2.0
    return CropBox(int(round(cx - side / 2.0)), int(round(cy - side / 2.0)), side)


def cut(image: np.ndarray, crop: CropBox, size: int, fill: float | None = None) -> np.ndarray:
    """The crop of an H x W (x C) image, resized to size x size; outside the photo the edge is replicated, or
    filled with the value `fill` if given.

    Returns:
        size x size (x C), same dtype.
    """
    if crop.turn:
        return _cut_turned(image, crop, size, fill)
    h, w = image.shape[:2]
    x0, y0, x1, y1 = crop.x0, crop.y0, crop.x0 + crop.side, crop.y0 + crop.side
    pad = (max(0, -y0), max(0, y1 - h), max(0, -x0), max(0, x1 - w))
    window = image[max(0, y0) : min(h, y1), max(0, x0) : min(w, x1)]
    if any(pad):
        window = (cv2.copyMakeBorder(window, *pad, borderType=cv2.BORDER_REPLICATE) if fill is None else
                  cv2.copyMakeBorder(window, *pad, borderType=cv2.BORDER_CONSTANT, value=[fill] * 4))
    interp = cv2.INTER_AREA if crop.side > size else cv2.INTER_LINEAR
    return cv2.resize(window, (size, size), interpolation=interp)


def _cut_turned(image: np.ndarray, crop: CropBox, size: int, fill: float | None) -> np.ndarray:
    """`cut` of a turned window: the photo shrunk by area first where the crop is smaller (as `cut` does), then
    turned and sampled bilinearly."""
    affine = crop_affine(crop, size)
    if size < crop.side:
        image, affine = _shrunk_first(image, affine, size / crop.side)
    border = {"borderMode": cv2.BORDER_REPLICATE} if fill is None else {
        "borderMode": cv2.BORDER_CONSTANT, "borderValue": [fill] * 4}
    return cv2.warpAffine(image, affine, (size, size), flags=cv2.INTER_LINEAR, **border)


def turned_photo(image: np.ndarray, deg: float) -> tuple[np.ndarray, np.ndarray]:
    """An H x W (x C) photo turned by `deg` (counter-clockwise) about its centre onto a canvas that holds all of
    it, the edge replicated into the corners; and the 2 x 3 affine from the photo's pixels to the canvas'."""
    h, w = image.shape[:2]
    c, s = abs(np.cos(np.radians(deg))), abs(np.sin(np.radians(deg)))
    nw, nh = int(np.ceil(w * c + h * s)), int(np.ceil(w * s + h * c))
    affine = cv2.getRotationMatrix2D(((w - 1) / 2.0, (h - 1) / 2.0), deg, 1.0)
    affine[:, 2] += ((nw - w) / 2.0, (nh - h) / 2.0)
    turned = cv2.warpAffine(image, affine, (nw, nh), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return turned, affine


def box_in_photo(box: CropBox, affine: np.ndarray, deg: float) -> CropBox:
    """The window `box` of a turned canvas (`turned_photo`'s affine and angle) as a turned window of the photo."""
    back = cv2.invertAffineTransform(affine)
    cx, cy = back @ np.array([box.x0 + box.side / 2.0 - 0.5, box.y0 + box.side / 2.0 - 0.5, 1.0])
    return CropBox(int(round(cx + 0.5 - box.side / 2.0)), int(round(cy + 0.5 - box.side / 2.0)), box.side, deg)


def reference_iou(located: np.ndarray, reference: np.ndarray, crop: CropBox) -> float:
    """IoU of an object located in a crop with a reference silhouette drawn on the whole photo, in the crop's
    pixels. The reference's pixels that the crop leaves out count as missed: a crop round part of the object
    scores that part as lost, not just the part it shows.

    Args:
        located: S x S bool, the located object in the crop. reference: H x W bool, the object in the photo.
        crop: the crop's window of the photo.
    """
    size = located.shape[0]
    h, w = reference.shape
    seen = cut(reference.astype(np.float32), crop, size, fill=0)
    truth = seen > 0.5
    if crop.turn:  # the reference's share outside the turned window, counted in the crop's pixels
        missed = max(0.0, float(reference.sum()) * (size / crop.side) ** 2 - float(seen.sum()))
    else:
        shown = reference[max(0, crop.y0) : min(h, crop.y0 + crop.side), max(0, crop.x0) : min(w, crop.x0 + crop.side)]
        missed = float(reference.sum() - shown.sum()) * (size / crop.side) ** 2
    union = float(np.logical_or(located, truth).sum()) + missed
    return float(np.logical_and(located, truth).sum()) / union if union else 1.0


def outside_mask(crop: CropBox, image_shape: tuple[int, ...], size: int) -> np.ndarray:
    """size x size bool: True on the crop's padding (beyond the photo's edge), False on real photo pixels."""
    if crop.turn:
        return cut(np.ones(image_shape[:2], np.float32), crop, size, fill=0) < 0.5
    u0, v0, u1, v1 = valid_region(crop, image_shape, size)
    out = np.ones((size, size), bool)
    out[v0:v1, u0:u1] = False
    return out


def cut_edges(mask: np.ndarray, crop: CropBox, image_shape: tuple[int, ...], min_run: float = 0.02,
              band: float = 0.01) -> tuple[str, ...]:
    """The photo edges (`top`, `bottom`, `left`, `right`) that cut the object: where the bool crop mask comes
    within `band` of the crop's side of an edge of the photo along at least `min_run` of the crop's side. Only
    the photo's own edges count: an edge of the crop inside the photo (a crop framed round the symmetric core,
    with handles rising above it) cuts the crop, not the object as photographed.

    Args:
        mask: S x S bool located object in the crop. crop: its window of the photo. image_shape: the photo's.
    """
    size = mask.shape[0]
    h, w = image_shape[:2]
    u0, v0, u1, v1 = valid_region(crop, image_shape, size)
    if u1 - u0 < 2 or v1 - v0 < 2:
        return ()
    inner = mask[v0:v1, u0:u1]
    reach = max(1, int(round(band * size)))
    need = max(1, int(min_run * size))
    lines = {"top": (crop.y0 <= 0, inner[:reach].any(0)),
             "bottom": (crop.y0 + crop.side >= h, inner[-reach:].any(0)),
             "left": (crop.x0 <= 0, inner[:, :reach].any(1)),
             "right": (crop.x0 + crop.side >= w, inner[:, -reach:].any(1))}
    return tuple(name for name, (edge, line) in lines.items() if edge and int(line.sum()) >= need)


def crop_affine(crop: CropBox, size: int, scale: float = 1.0) -> np.ndarray:
    """2 x 3 affine taking pixel centres of an image at `scale` x the original's resolution into the crop's
    size x size pixel grid (turned with the crop)."""
    k = size / crop.side
    if crop.turn:
        centre = (crop.x0 + crop.side / 2.0 - 0.5, crop.y0 + crop.side / 2.0 - 0.5)
        turn = np.vstack([cv2.getRotationMatrix2D(centre, crop.turn, 1.0), [0, 0, 1]])
        unturned = np.vstack([crop_affine(CropBox(crop.x0, crop.y0, crop.side), size, 1.0), [0, 0, 1]])
        to_photo = np.array([[1 / scale, 0, 0.5 / scale - 0.5], [0, 1 / scale, 0.5 / scale - 0.5], [0, 0, 1]])
        return (unturned @ turn @ to_photo)[:2]
    # original x = (x_s + 0.5) / scale - 0.5 ; crop u = (x - x0 + 0.5) * k - 0.5
    a = k / scale
    bx = (0.5 / scale - 0.5 - crop.x0 + 0.5) * k - 0.5
    by = (0.5 / scale - 0.5 - crop.y0 + 0.5) * k - 0.5
    return np.array([[a, 0.0, bx], [0.0, a, by]], np.float64)


def warp_mask(mask: np.ndarray, affine: np.ndarray, size: int) -> np.ndarray:
    """Warp a bool mask by a 2 x 3 affine into a size x size bool mask (bilinear on 0/1, cut at 0.5)."""
    src: np.ndarray = mask.astype(np.float32)
    if affine[0, 0] < 0.5:  # shrinking: average first so thin parts are not lost to point sampling
        src, affine = _shrunk_first(src, affine, affine[0, 0])
    out = cv2.warpAffine(src, affine, (size, size), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    return out > 0.5


def _shrunk_first(image: np.ndarray, affine: np.ndarray, factor: float) -> tuple[np.ndarray, np.ndarray]:
    """An image shrunk by `factor` by area averaging and the 2 x 3 affine that then takes its pixels where
    `affine` took the original's."""
    h, w = image.shape[:2]
    nw, nh = max(1, round(w * factor)), max(1, round(h * factor))
    small = cv2.resize(image, (nw, nh), interpolation=cv2.INTER_AREA)
    pre = np.array([[w / nw, 0, 0.5 * w / nw - 0.5], [0, h / nh, 0.5 * h / nh - 0.5], [0, 0, 1]])
    return small, (np.vstack([affine, [0, 0, 1]]) @ pre)[:2]


def valid_region(crop: CropBox, image_shape: tuple[int, ...], size: int) -> tuple[int, int, int, int]:
    """(u0, v0, u1, v1): the part of the size x size crop that shows real photo pixels (not padding)."""
    h, w = image_shape[:2]
    k = size / crop.side
    u0 = int(np.ceil(max(0, -crop.x0) * k))
    v0 = int(np.ceil(max(0, -crop.y0) * k))
    u1 = int(np.floor(min(crop.side, w - crop.x0) * k))
    v1 = int(np.floor(min(crop.side, h - crop.y0) * k))
    return u0, v0, max(u0, u1), max(v0, v1)
