"""Which parts of the border show the backdrop: a vignette or sweep however steep is all backdrop, an object
running into the frame is not (a dark rim cut by the top edge above a lit floor neither, nor the soft rim and
foot of a greyscale catalogue plate), a label standing in the band does not cut the backdrop beyond it off, and a
flat frame round the picture is found. The pictures are drawn here."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from radar_cli.masks import crop as crops
from radar_cli.masks.border import PAD_SMEAR, backdrop_band, border_band, frame_inset, frame_padding
from radar_cli.masks.locate import locate_object
from radar_cli.masks.neighbours import base_off_axis

H, W = 300, 240


def vignette(dark: float = 0.35) -> np.ndarray:
    """H x W x 3 float: a studio backdrop lit from the lower right, falling off to `dark` at the upper left."""
    y, x = np.mgrid[0:H, 0:W]
    light = 1.0 - (1.0 - dark) * np.clip(((W - x) / W) ** 2 + ((H - y) / H) ** 2, 0, 1)
    return np.repeat((0.85 * light)[..., None], 3, axis=2)


def to_uint8(image: np.ndarray, seed: int = 0) -> np.ndarray:
    noise = np.random.default_rng(seed).normal(0, 0.004, image.shape)
    return (np.clip(image + noise, 0, 1) * 255 + 0.5).astype(np.uint8)


def ellipse(cx: float, cy: float, rx: float, ry: float) -> np.ndarray:
    y, x = np.mgrid[0:H, 0:W]
    return ((x - cx) / rx) ** 2 + ((y - cy) / ry) ** 2 <= 1


def test_a_steep_vignette_is_all_backdrop() -> None:
    image = vignette()
    image[ellipse(120, 150, 60, 90)] = [0.55, 0.3, 0.2]  # a vessel with a margin all round
    photo = to_uint8(image)
    assert int(photo[..., 0].max()) - int(photo[..., 0].min()) > 120  # the backdrop alone spans that much
    assert (backdrop_band(photo) == border_band(photo.shape[:2])).all()


def test_an_object_running_into_the_frame_is_left_out() -> None:
    image = vignette(0.7)
    vessel = ellipse(120, 250, 70, 110)  # cut by the bottom edge
    image[vessel] = [0.2, 0.15, 0.12]
    photo = to_uint8(image)
    band, kept = border_band(photo.shape[:2]), backdrop_band(photo)
    assert kept[band & vessel].mean() < 0.05  # (its slanting flanks cross the band's pixel rows unevenly)
    assert kept[band & ~vessel].mean() > 0.97  # the rest of the band is kept


def test_a_label_in_the_band_does_not_cut_off_the_floor_beyond_it() -> None:
    image = vignette(0.3)[:, ::-1]  # lit from above: the floor is even, the walls are not
    image[:] = image[:, W // 2 : W // 2 + 1]
    image[ellipse(120, 140, 55, 80)] = [0.55, 0.3, 0.2]
    label = np.zeros((H, W), bool)
    label[275:, 150:200] = True  # a white card standing on the bottom edge
    image[label] = 1.0
    chart = np.zeros((H, W), bool)
    chart[280:, 10:60] = True  # a colour chart in the other corner
    image[chart] = [0.1, 0.6, 0.2]
    photo = to_uint8(image)
    kept = backdrop_band(photo)
    floor = border_band(photo.shape[:2]) & ~label & ~chart
    band = border_band(photo.shape[:2])
    assert kept[band & (label | chart)].mean() < 0.05
    assert kept[floor].mean() > 0.95


@pytest.mark.parametrize("floor, power", [(0.6, 2.0), (0.75, 1.0), (0.88, 0.5)])
def test_a_rim_cut_by_the_top_edge_is_not_taken_for_the_backdrop(floor: float, power: float) -> None:
    """A tight crop: the dark rim runs past the top edge and the handles past both sides, on a sweep whose floor is
    lit brighter than its wall. A steep gradient from the dark top to the light floor explains the rim and part of
    the backdrop's run; the wall and floor, one run without a sharp step, are the backdrop, and the rim is not
    (the wall and the rim are neighbours across an outline, so not both backdrop)."""
    y = np.mgrid[0:H, 0:W][0] / H
    grey = 0.48 + 0.14 * np.clip((y - floor) / (1 - floor), 0, 1) ** power
    image = np.repeat(grey[..., None], 3, axis=2)
    vessel = ellipse(120, 150, 105, 120)
    vessel[:60, 20 : W - 20] = True  # the rim cut by the top edge
    vessel[:45, :30] = vessel[:45, -30:] = True  # the handles cut by the side edges
    image[vessel] = [0.11, 0.1, 0.09]
    photo = to_uint8(image)
    band, kept = border_band(photo.shape[:2]), backdrop_band(photo)
    assert kept[band & vessel].mean() < 0.05
    assert kept[band & ~vessel].mean() > 0.97


def grey_plate(ground: float = 0.62, vessel: float = 0.5, sigma: float = 5.0) -> tuple[np.ndarray, np.ndarray]:
    """(H x W x 3 uint8 photo, H x W bool vessel): an older catalogue's greyscale plate, the vessel cut by the top
    edge at its wide rim and by the bottom edge at its foot, 30 levels darker than the ground and soft (no step
    along the border is sharper than 17 levels over 4 px)."""
    vessel_mask = ellipse(120, 150, 100, 120)
    vessel_mask[:28, 22 : W - 22] = True  # the rim, over four fifths of the top edge
    vessel_mask[H - 22 :, 78:162] = True  # the foot
    grey = cv2.GaussianBlur(np.where(vessel_mask, vessel, ground), (0, 0), sigma)
    return to_uint8(np.repeat(grey[..., None], 3, axis=2)), vessel_mask


def test_the_soft_rim_and_foot_of_a_grey_plate_are_not_backdrop() -> None:
    """The rim's run is long and within LONG_TOLERANCE of the ground, and the foot parts the ground's run in two:
    read by sharp steps alone, the whole band was backdrop (with "long" measured against the longest backdrop
    run, 70 % of the rim and foot) and the backdrop model went dark at the top. The vessel is then located whole."""
    photo, vessel = grey_plate()
    band, kept = border_band(photo.shape[:2]), backdrop_band(photo)
    assert kept[band & vessel].mean() < 0.05
    assert kept[band & ~vessel].mean() > 0.97
    found = locate_object(photo, 128)  # whole: 0.82 when the rim was backdrop and the upper body went with it
    assert crops.reference_iou(found.silhouette | found.appendages, vessel, found.box) >= 0.9


def test_a_flat_frame_round_the_picture_is_found_and_a_plain_backdrop_is_not() -> None:
    image = vignette()
    image[ellipse(120, 150, 60, 90)] = [0.55, 0.3, 0.2]
    framed = np.zeros_like(image)
    framed[6:-6, 6:-6] = image[6:-6, 6:-6]
    pad = frame_padding(to_uint8(framed))
    assert pad[:6].all() and pad[:, :6].all() and pad[-6:].all() and pad[:, -6:].all()
    assert not pad[20:-20, 20:-20].any()
    assert frame_inset(to_uint8(framed)) == (6 + PAD_SMEAR,) * 4
    stood = framed.copy()
    stood[-20:, 40:200] = [0.6, 0.45, 0.3]  # a plinth over most of the bottom edge: found from the other sides
    assert frame_inset(to_uint8(stood))[1] == 6 + PAD_SMEAR
    plain = np.full((H, W, 3), 0.5)
    plain[ellipse(120, 150, 60, 90)] = [0.55, 0.3, 0.2]
    assert not frame_padding(to_uint8(plain)).any() and frame_inset(to_uint8(plain)) == (0, 0, 0, 0)


def test_a_neighbour_kept_beside_the_base_is_off_the_axis() -> None:
    vessel = ellipse(100, 150, 50, 100)
    assert base_off_axis(vessel, vessel) == 0.0
    neighbour = ellipse(170, 190, 40, 60)  # standing behind, overlapping its flank
    assert base_off_axis(vessel | neighbour, vessel) > 0.1
