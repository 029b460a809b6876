"""The symmetric core of a column-krater: seen from the front, the handle plates are the handles', not the rim;
seen from a handle's side, the plate standing on the rim is left out and the rim under it kept whole."""

from __future__ import annotations

import numpy as np
import pytest

from radar_cli.masks.appendages import symmetric_core

AXIS = 200  # the silhouette's axis lies between columns AXIS - 1 and AXIS
RIM = 110  # the rim's half-width, in pixels


def column_krater(left_plate: int, right_plate: int) -> np.ndarray:
    """420 x 400 bool silhouette: a rim, a neck, a belly and a foot about AXIS; on each side a column past a gap
    from the neck, its outer edge under the rim's edge, carrying a plate level with the rim that reaches
    `left_plate` / `right_plate` pixels beyond it."""
    half = np.zeros(420)
    half[60:72] = RIM  # the rim's face
    half[72:110] = np.linspace(84, 78, 38)  # the neck
    half[110:330] = 70 + 55 * np.sin(np.pi * (0.2 + 0.8 * np.linspace(0, 1, 220)))  # shoulder and belly
    half[330:345], half[345:360] = 45, 62  # the stem, the foot
    xs = np.arange(400) + 0.5 - AXIS
    mask = np.abs(xs)[None, :] <= half[:, None]
    mask[60:150, AXIS - RIM : AXIS - 96] = mask[60:150, AXIS + 96 : AXIS + RIM] = True  # the columns
    mask[60:72, AXIS - RIM - left_plate : AXIS - RIM] = True
    mask[60:72, AXIS + RIM : AXIS + RIM + right_plate] = True
    return mask


def rim_extents(core: np.ndarray) -> tuple[int, int]:
    """How far the core's rim rows reach left and right of the axis, in pixels."""
    cols = np.nonzero(core[60:72].any(0))[0]
    return AXIS - int(cols.min()), int(cols.max()) + 1 - AXIS


@pytest.mark.parametrize("right_plate", [16, 30])
def test_plates_of_unequal_reach_are_both_left_out_of_the_rim(right_plate: int) -> None:
    # the right plate as long as the left or 14 px (5 % of the width) longer, as two plates of one krater differ
    # in a photo: neither is read as the rim, on either side
    split = symmetric_core(column_krater(16, right_plate))
    assert rim_extents(split.core) == (RIM, RIM)
    assert split.appendages[60:72, : AXIS - RIM].any() and split.appendages[60:72, AXIS + RIM :].any()


def side_view(plate_rows: int) -> np.ndarray:
    """420 x 400 bool silhouette of the same krater seen from a handle's side: the handle's plate, seen face on
    over the axis, stands `plate_rows` above the rim (a strip of backdrop between them at the sides)."""
    half = np.zeros(420)
    half[60:72] = RIM
    half[72:110] = np.linspace(84, 78, 38)
    half[110:330] = 70 + 55 * np.sin(np.pi * (0.2 + 0.8 * np.linspace(0, 1, 220)))
    half[330:345], half[345:360] = 45, 62
    xs = np.arange(400) + 0.5 - AXIS
    mask = np.abs(xs)[None, :] <= half[:, None]
    mask[60 - plate_rows : 60, AXIS - 26 : AXIS + 26] = True  # the plate, over the column in front of the neck
    mask[60:150, AXIS - 14 : AXIS + 14] = True  # the column
    return mask


@pytest.mark.parametrize("plate_rows", [20, 40])
def test_the_rim_under_a_plate_standing_on_it_is_kept_whole(plate_rows: int) -> None:
    """The rim is the solid's top though the plate stands higher: it is not cut down to the neck as a bump
    between body rows would be (a handle's attachment), which read the rims of the CVA kraters' side views
    narrow."""
    split = symmetric_core(side_view(plate_rows))
    assert rim_extents(split.core) == (RIM, RIM)
    assert not split.core[: 60 - 2].any()  # the plate is left out
