"""A black-and-white scale bar laid against a vessel's foot is found and left out of the located object; painted
bands of alternating colour are not taken for one."""

from __future__ import annotations

import numpy as np
import pytest

from radar_cli.masks import crop as crops
from radar_cli.masks.locate import locate_object
from radar_cli.masks.scale_bar import find_scale_bar
from radar_cli.masks.synthetic import composite, render_vases

N = 256


def _vessel() -> tuple[np.ndarray, np.ndarray]:
    """N x N x 3 uint8 grey backdrop with a brown vessel (body ellipse over a foot), and its bool mask."""
    yy, xx = np.mgrid[0:N, 0:N]
    body = ((xx - 128) / 70.0) ** 2 + ((yy - 110) / 80.0) ** 2 <= 1
    foot = (np.abs(xx - 128) <= 40) & (yy >= 185) & (yy <= 205)
    mask = body | foot
    image = np.full((N, N, 3), 170, np.uint8)
    image[mask] = (120, 70, 40)
    return image, mask


def _bar(image: np.ndarray, mask: np.ndarray | None, x: int, y: int, segments: int = 10, length: int = 12,
         height: int = 6, checkered: bool = False) -> None:
    """A bar of black and white segments drawn in place (its black segments added to `mask`, as a cut takes
    them in)."""
    for k in range(segments):
        for half in range(2 if checkered else 1):
            rows = slice(y + half * height // 2, y + (half + 1) * height // 2) if checkered else slice(y, y + height)
            black = (k + half) % 2 == 0
            cols = slice(x + k * length, x + (k + 1) * length)
            image[rows, cols] = 10 if black else 245
            if black and mask is not None:
                mask[rows, cols] = True


@pytest.mark.parametrize("checkered", [False, True])
def test_a_bar_against_the_foot_is_found(checkered: bool) -> None:
    image, vessel = _vessel()
    mask = vessel.copy()
    _bar(image, mask, 68, 203, checkered=checkered)  # overlaps the foot's lowest rows, wider than it
    bar = find_scale_bar(image, mask)
    assert bar is not None
    ys, xs = np.nonzero(bar)
    assert ys.min() <= 203 and ys.max() >= 208 and xs.min() <= 68 and xs.max() >= 187
    assert not bar[:195].any()  # the body and the foot above the bar stay


def test_a_bar_apart_from_the_object_is_left_to_the_neighbour_cuts() -> None:
    image, mask = _vessel()
    _bar(image, None, 10, 240, length=8)
    assert find_scale_bar(image, mask) is None


@pytest.mark.parametrize("light", [(200, 120, 60), (140, 140, 140), (215, 200, 150), (240, 238, 232)])
def test_painted_bands_are_no_bar(light: tuple[int, int, int]) -> None:
    """Black rays on orange clay, a greyscale plate's bands, a cream slip: alternating, but not black and white;
    black on a white ground: the foot stands below it."""
    image, mask = _vessel()
    for k in range(10):  # over the lower body, the foot below (paint lies on the vessel)
        columns = slice(78 + 10 * k, 88 + 10 * k)
        image[165:181, columns][mask[165:181, columns]] = (15, 12, 10) if k % 2 == 0 else light
    assert find_scale_bar(image, mask) is None


@pytest.mark.parametrize("offset", [0.0, 0.25])
def test_located_without_the_bar(offset: float) -> None:
    """A rendered vase on a grey sweep with a bar laid over its foot's lowest rows, centred or off to one side:
    the located object ends where the vase does (merged, the bar drew it 5-9 px lower at 256 px)."""
    vases, alpha, masks = render_vases(1, 320, seed=12)
    photo, truth = composite(vases[0], alpha[0], masks[0], "gradient", np.random.default_rng(2), shape=(720, 600))
    rows, cols = np.nonzero(truth.any(1))[0], np.nonzero(truth.any(0))[0]
    width = int(cols[-1] - cols[0] + 1)
    length = int(0.08 * width)
    _bar(photo, None, int(cols[0] + width * (0.5 + offset) - 5 * length), int(rows[-1]) - 4, length=length, height=14)
    found = locate_object(photo, 256)
    whole = found.silhouette | found.appendages
    seen = crops.cut(truth.astype(np.float32), found.box, 256, fill=0) > 0.5
    assert np.nonzero(whole.any(1))[0][-1] <= np.nonzero(seen.any(1))[0][-1] + 1
    assert crops.reference_iou(whole, truth, found.box) >= 0.95
