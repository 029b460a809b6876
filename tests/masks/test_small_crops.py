"""Locating a vessel in small, tight, crowded crops (about 200 px): touching three edges of the frame on a grey
sweep close to its colour, a second vessel standing behind it, a plain grey backdrop, a greyscale catalogue
plate. The vessels are drawn here (a painted krater-like body of revolution), so the truth is exact."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from radar_cli.masks import crop as crops
from radar_cli.masks.locate import locate_object

SIZE = 128


def vessel(height: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A dark glazed vessel with a light painted band: (h x w x 3 float RGB, h x w bool silhouette)."""
    t = np.linspace(0.0, 1.0, height)
    radius = 0.32 + 0.12 * np.sin(np.pi * (t * 1.1 + 0.05)) - 0.1 * np.exp(-((t - 0.9) / 0.06) ** 2)
    radius[: max(2, height // 14)] = 0.42  # a rim
    radius[-max(2, height // 12):] = 0.22  # a foot
    radius *= height
    width = int(2 * radius.max()) + 2
    xs = np.arange(width) - width / 2
    mask = np.abs(xs)[None] <= radius[:, None]
    shade = 0.75 + 0.25 * np.cos(np.clip(xs[None] / radius[:, None], -1, 1) * np.pi / 2)
    colour = np.where(((t > 0.35) & (t < 0.5))[:, None, None], [0.75, 0.45, 0.3], [0.18, 0.14, 0.12])
    image = colour * shade[..., None] + rng.normal(0, 0.01, (height, width, 3))
    return image.astype(np.float32), mask


def sweep(h: int, w: int, level: float) -> np.ndarray:
    ramp = level * (1.08 - 0.16 * np.linspace(0, 1, h))[:, None, None]
    return np.broadcast_to(ramp, (h, w, 3)).astype(np.float32).copy()


def place(canvas: np.ndarray, truth: np.ndarray | None, image: np.ndarray, mask: np.ndarray, x: int, y: int) -> None:
    """Paste a vessel at (x, y), clipped to the canvas; `truth` (if given) becomes its silhouette there."""
    H, W = canvas.shape[:2]
    h, w = mask.shape
    xa, ya, xb, yb = max(0, x), max(0, y), min(W, x + w), min(H, y + h)
    m = mask[ya - y : yb - y, xa - x : xb - x]
    canvas[ya:yb, xa:xb][m] = image[ya - y : yb - y, xa - x : xb - x][m]
    if truth is not None:
        truth[ya:yb, xa:xb] |= m


def to_photo(canvas: np.ndarray, quality: int = 85) -> np.ndarray:
    rgb = (np.clip(canvas, 0, 1) * 255 + 0.5).astype(np.uint8)
    ok, data = cv2.imencode(".jpg", rgb, [cv2.IMWRITE_JPEG_QUALITY, quality])
    return cv2.imdecode(data, cv2.IMREAD_UNCHANGED)


def located_iou(photo: np.ndarray, truth: np.ndarray) -> float:
    found = locate_object(photo, SIZE)
    return crops.reference_iou(found.silhouette | found.appendages, truth, found.box)


def test_touching_three_edges_on_a_close_grey_sweep() -> None:
    image, mask = vessel(230, np.random.default_rng(1))
    h, w = mask.shape
    canvas = sweep(h, w - 16, 0.32)  # the frame cuts both flanks and the foot, a margin above
    truth = np.zeros(canvas.shape[:2], bool)
    place(canvas, truth, image, mask, -8, 20)
    assert {"left", "right", "bottom"} <= set(locate_object(to_photo(canvas), SIZE).cut_edges)
    assert located_iou(to_photo(canvas), truth) >= 0.9


def test_a_second_vessel_behind_is_not_merged() -> None:
    rng = np.random.default_rng(2)
    image, mask = vessel(180, rng)
    other, other_mask = vessel(150, rng)
    h, w = mask.shape
    canvas = sweep(h + 30, w + 90, 0.6)
    truth = np.zeros(canvas.shape[:2], bool)
    place(canvas, None, other * 0.8, other_mask, 20 + w - 15, 40)  # behind it, overlapping its flank
    place(canvas, truth, image, mask, 20, 20)
    score = located_iou(to_photo(canvas), truth)
    assert score >= 0.9, score


def on_plain_grey(image: np.ndarray, mask: np.ndarray, level: float, margin: int) -> tuple[np.ndarray, np.ndarray]:
    """The vessel on a flat grey of `level` with `margin` px all round: (canvas H x W x 3, its true silhouette)."""
    h, w = mask.shape
    canvas = np.full((h + 2 * margin, w + 2 * margin, 3), level, np.float32)
    truth = np.zeros(canvas.shape[:2], bool)
    place(canvas, truth, image, mask, margin, margin)
    return canvas, truth


def test_a_plain_grey_backdrop_is_located() -> None:
    image, mask = vessel(190, np.random.default_rng(3))
    canvas, truth = on_plain_grey(image, mask, 0.3, 5)
    found = locate_object(to_photo(canvas), SIZE)
    assert found.frame_coverage < 0.9
    assert located_iou(to_photo(canvas), truth) >= 0.9


def test_a_black_glazed_vessel_on_a_plain_grey_close_to_it_is_located_whole() -> None:
    """A neutral black glaze is the grey backdrop darkened (a shade's ratio, no colour of its own): read with
    shading forgiven only the painted band stands out."""
    image, mask = vessel(200, np.random.default_rng(6))
    glaze = np.abs(image - np.array([0.18, 0.14, 0.12])).sum(axis=2) < 0.1
    image[glaze] = image[glaze].mean(axis=1, keepdims=True) * 0.9
    canvas, truth = on_plain_grey(image, mask, 0.25, 6)
    score = located_iou(to_photo(canvas), truth)
    assert score >= 0.9, score


@pytest.mark.parametrize("seed,level,painted,blur,noise", [(6, 0.25, 0.5, 1.0, 0.02), (7, 0.25, 0.55, 2.0, 0.02),
                                                          (6, 0.3, 0.5, 1.5, 0.03)])
def test_a_black_body_under_a_painted_upper_half_on_a_dark_sweep_is_located_whole(
        seed: int, level: float, painted: float, blur: float, noise: float) -> None:
    """The upper half painted, the lower half a neutral black glaze on a dark grey close to it: read with shading
    forgiven the painted half alone stands out, with its outline on edges all round (as the whole vessel's is
    read strictly); the strict reading's object, nearly twice as large, is the vessel."""
    rng = np.random.default_rng(seed)
    image, mask = vessel(200, rng)
    glaze = np.abs(image - np.array([0.18, 0.14, 0.12])).sum(axis=2) < 0.1
    image[glaze] = image[glaze].mean(axis=1, keepdims=True) * 0.9
    paint = (np.arange(mask.shape[0]) < painted * mask.shape[0])[:, None] & mask
    image[paint] = np.array([0.75, 0.45, 0.3]) * (0.9 + 0.1 * rng.random((int(paint.sum()), 1)))
    canvas, truth = on_plain_grey(image, mask, level, 8)
    canvas = cv2.GaussianBlur(canvas, (0, 0), blur) + rng.normal(0, noise, canvas.shape).astype(np.float32)
    score = located_iou(to_photo(canvas), truth)
    assert score >= 0.9, score


@pytest.mark.parametrize("seed", [9, 10, 11])
def test_a_black_foot_and_lower_body_on_a_dark_grey_are_kept(seed: int) -> None:
    """The vessel painted but for its lowest fifth, a neutral black glaze on a dark grey close to it, small in the
    frame: read with shading forgiven the black part passes for shade; the strict reading's object, a fifth
    larger and as symmetric about an axis, is the vessel (0.86-0.87 without that rule, 0.906 with it: the foot's
    lowest rows are still lost, and the crop framed on what was found leaves them out)."""
    rng = np.random.default_rng(seed)
    image, mask = vessel(200, rng)
    glaze = np.abs(image - np.array([0.18, 0.14, 0.12])).sum(axis=2) < 0.1
    image[glaze] = image[glaze].mean(axis=1, keepdims=True) * 0.9
    paint = (np.arange(mask.shape[0]) < 0.8 * mask.shape[0])[:, None] & mask
    image[paint] = np.array([0.75, 0.45, 0.3]) * (0.9 + 0.1 * rng.random((int(paint.sum()), 1)))
    canvas, truth = on_plain_grey(image, mask, 0.22, 110)
    canvas = cv2.GaussianBlur(canvas, (0, 0), 1.0) + rng.normal(0, 0.02, canvas.shape).astype(np.float32)
    score = located_iou(to_photo(canvas), truth)
    assert score >= 0.9, score


def test_a_shadow_cast_beside_a_vessel_in_a_colour_photo_is_left_out() -> None:
    """A soft shadow beside the vessel on a light warm grey: the strict reading's object is larger but lopsided,
    so the forgiving reading stands."""
    image, mask = vessel(180, np.random.default_rng(5))
    h, w = mask.shape
    canvas = sweep(h + 40, w + 140, 0.8) * np.array([1.0, 0.96, 0.9], np.float32)
    yy, xx = np.mgrid[0 : h + 40, 0 : w + 140]
    shadow = np.exp(-(((xx - (w + 40)) / 45.0) ** 2 + ((yy - (h - 20)) / 60.0) ** 2))
    canvas *= (1.0 - 0.3 * shadow)[..., None]
    truth = np.zeros(canvas.shape[:2], bool)
    place(canvas, truth, image, mask, 20, 20)
    assert located_iou(to_photo(canvas), truth) >= 0.9


def test_a_greyscale_catalogue_plate_cut_at_top_and_bottom() -> None:
    image, mask = vessel(200, np.random.default_rng(4))
    h, w = mask.shape
    canvas = sweep(h, w + 24, 0.6)
    truth = np.zeros(canvas.shape[:2], bool)
    place(canvas, truth, image, mask, 12, 0)
    grey = canvas.mean(axis=2, keepdims=True)
    grey = 0.5 + (grey - grey.mean()) * 0.5  # low contrast
    photo = to_photo(np.repeat(grey, 3, axis=2), quality=30)
    assert located_iou(photo, truth) >= 0.9


def greyscale_with_shadow() -> tuple[np.ndarray, np.ndarray]:
    """A greyscale photo of the vessel on a light grey backdrop with a soft shadow cast beside it: (photo,
    truth)."""
    image, mask = vessel(180, np.random.default_rng(5))
    h, w = mask.shape
    canvas = sweep(h + 40, w + 140, 0.8)
    yy, xx = np.mgrid[0 : h + 40, 0 : w + 140]
    shadow = np.exp(-(((xx - (w + 40)) / 45.0) ** 2 + ((yy - (h - 20)) / 60.0) ** 2))
    canvas *= (1.0 - 0.18 * shadow)[..., None]  # a soft pool of shade: 0.82 of the backdrop at its middle
    truth = np.zeros(canvas.shape[:2], bool)
    place(canvas, truth, image, mask, 20, 20)
    grey = canvas.mean(axis=2, keepdims=True)
    return to_photo(np.repeat(grey, 3, axis=2)), truth


def test_a_soft_shadow_beside_a_vessel_in_a_greyscale_photo_is_left_out() -> None:
    photo, truth = greyscale_with_shadow()
    assert located_iou(photo, truth) >= 0.9
