"""A second vessel standing behind the located one (partly hidden by it, standing higher) is cut off; a lone vessel, a
one-handled jug, a tilted vessel and a neighbour standing level beside it are left to the rest of the locator; one
standing beside it is split off at the valley (the larger part kept, though a taller neighbour's columns peak
higher), but not the halves of a vessel that its painting carved; one cut by the photo's side edge is cut off where
it meets the frame, but not a vessel that the frame itself cuts. A card in front of the foot is cut off the located
object; a vessel's own handles are not, nor a strip down its flank that rises into its upper half. The photos and
masks are drawn here."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks import crop as crops
from radar_cli.masks.locate import locate_object
from radar_cli.masks.neighbours import cut_at_frame, cut_base, cut_behind, split_neighbour
from radar_cli.masks.refine import iou

H, W = 240, 220


def vessel(cx: float, top: float, height: float, width: float) -> np.ndarray:
    """H x W bool silhouette of an amphora-like vessel: rim, neck, a round body, a foot."""
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    t = (y - top) / height  # 0 at the rim, 1 under the foot
    body = 0.5 * np.sqrt(np.clip(1 - ((t - 0.55) / 0.4) ** 2, 0, 1))
    neck = np.where((t >= 0.05) & (t < 0.25), 0.22, 0.0)
    rim = np.where(t < 0.05, 0.3, 0.0)
    foot = np.where((t >= 0.9) & (t <= 1.0), 0.2, 0.0)
    radius = width * np.maximum.reduce([body, neck, rim, foot])
    return (np.abs(x - cx) <= radius) & (t >= 0) & (t <= 1)


def test_a_neighbour_behind_is_cut_at_the_mirror_of_the_other_side() -> None:
    main = vessel(95, 20, 200, 120)
    behind = vessel(165, 40, 160, 110)  # smaller, standing higher, a third of the main width hidden
    cut, removed = cut_behind(main | behind)
    assert removed and iou(cut, main) >= 0.95 and not (cut & ~(main | behind)).any()
    alone, removed = cut_behind(main)
    assert not removed and (alone == main).all()


def test_vessels_of_their_own_shape_are_left_whole() -> None:
    main = vessel(110, 20, 200, 120)
    y, x = np.mgrid[0:H, 0:W]
    ring = ((x - 175) / 22.0) ** 2 + ((y - 85) / 50.0) ** 2
    jug = main | ((ring <= 1) & (ring >= 0.45) & (x > 150))  # a handle loop down to the body's widest rows
    assert not cut_behind(jug)[1]
    for deg in (6.0, 10.0, -10.0):  # a vessel photographed off upright: one flank sticks out past the other
        turn = cv2.getRotationMatrix2D((110, 120), deg, 1.0)
        tilted = cv2.warpAffine(main.astype(np.uint8), turn, (W, H), flags=cv2.INTER_NEAREST) > 0
        assert not cut_behind(tilted)[1], deg
    beside = vessel(85, 20, 200, 110) | vessel(170, 20, 200, 110)  # standing level: no clean foot below it
    assert not cut_behind(beside)[1]


def test_a_neighbour_beside_is_split_off_and_a_vessel_carved_by_its_painting_is_not() -> None:
    """Two vessels standing level side by side are parted at the valley between them; a vessel whose light
    painted figure was cut out of it from the rim down (a slit that leaves a valley in its lower columns) stays
    whole: its half alone is far less a solid of revolution."""
    main, other = vessel(75, 20, 200, 120), vessel(170, 60, 160, 90)
    kept, split = split_neighbour(main | other)
    assert split and iou(kept, main) >= 0.9
    carved = vessel(110, 20, 200, 130)
    carved[:160, 104:116] = False  # the figure, as light as the backdrop, open to the mouth
    kept, split = split_neighbour(carved)
    assert not split and (kept == carved).all()


def test_a_taller_narrower_neighbour_beside_is_the_one_split_off() -> None:
    """The lower columns peak in a tall cylinder (an albarello) standing beside a wide krater; the krater, the
    larger part, is kept."""
    y, x = np.mgrid[0:H, 0:W]
    main = vessel(130, 20, 200, 150)
    tall = (np.abs(x - 28) <= 22) & (y >= 10) & (y <= 225)
    bridge = (y >= 150) & (y <= 160) & (x >= 40) & (x <= 80)  # where the two touch in the photo
    kept, split = split_neighbour(main | tall | bridge)
    assert split and iou(kept, main) >= 0.95


def test_a_neighbour_cut_by_the_frame_is_cut_off_and_a_vessel_cut_by_it_is_not() -> None:
    """A vessel standing beside the main one, cut by the photo's right edge, joins it from the shoulder to the
    floor (no valley, no clean foot below it): it meets the frame in a straight line and is cut off. The main
    vessel alone, or cut by the frame itself (narrower on that side than its mirror image), is left whole; so is
    the joined pair where the photo goes on past it (nothing meets the frame), and a wide jar that the frame cuts
    at both sides (no outline of either flank seen there to mirror)."""
    main = vessel(95, 20, 200, 120)
    neighbour = vessel(205, 50, 170, 150)  # overlapping its flank down to the floor, past the right edge
    joined = main | neighbour
    assert not split_neighbour(joined)[1] and not cut_behind(joined)[1]
    outside = np.zeros((H, W), bool)
    cut, removed = cut_at_frame(joined, outside)
    assert removed and iou(cut, main) >= 0.95 and not (cut & ~joined).any()
    for whole in (main, main & (np.arange(W) < 140)[None, :]):  # alone; its right flank cut by the frame
        kept, removed = cut_at_frame(whole, outside)
        assert not removed and (kept == whole).all()
    jar = vessel(90, 20, 200, 320)  # a wide jar off the crop's middle, its body cut by both side edges
    kept, removed = cut_at_frame(jar, outside)
    assert not removed and (kept == jar).all()
    padded = np.zeros((H, W + 120), bool)  # the same pair with the photo's edge far off: nothing meets it
    padded[:, :W] = joined
    padded[:, :W] |= vessel(205, 50, 170, 150)
    kept, removed = cut_at_frame(padded, np.zeros_like(padded))
    assert not removed and (kept == padded).all()


def test_a_vessel_in_front_of_another_is_located_without_it() -> None:
    main, behind = vessel(95, 20, 200, 120), vessel(165, 40, 160, 110)
    photo = np.full((H, W, 3), 150, np.uint8)
    photo[behind] = (70, 45, 35)
    photo[main] = (40, 30, 25)  # a black-glazed vessel in front of a darker brown one
    noise = np.random.default_rng(0).normal(0, 2, photo.shape)
    photo = np.clip(photo + noise, 0, 255).astype(np.uint8)
    found = locate_object(photo, 128)
    assert found.neighbour_removed and crops.reference_iou(found.silhouette | found.appendages, main, found.box) >= 0.9


def test_a_card_in_front_of_the_foot_is_cut_off_and_handles_stay() -> None:
    main = vessel(100, 20, 200, 120)
    y, x = np.mgrid[0:H, 0:W]
    card = (x >= 110) & (x < 200) & (y >= 175) & (y < 215)  # a label standing against the foot's right side
    cut, removed = cut_base(main | card, main)
    assert removed and iou(cut, main) >= 0.98
    ring = ((x - 165) / 22.0) ** 2 + ((y - 85) / 50.0) ** 2
    handles = main | ((ring <= 1) & (ring >= 0.45) & (x > 140))
    kept, removed = cut_base(handles, main)
    assert not removed and (kept == handles).all()


def test_a_strip_down_the_flank_stays_when_a_card_before_the_foot_is_cut() -> None:
    """Off a narrow core (the other flank lost on a low-contrast plate) a strip of the vessel's own flank reaches the
    base rows; it rises into the upper half, which nothing standing before the foot does."""
    main = vessel(100, 20, 200, 120)
    y, x = np.mgrid[0:H, 0:W]
    card = (x >= 110) & (x < 200) & (y >= 175) & (y < 215)
    wider = cv2.dilate(main.astype(np.uint8), np.ones((1, 9), np.uint8)) > 0
    strip = wider & ~main & (x < 100) & (y >= 70)  # 4 px down the left flank, from the upper body to the foot
    cut, removed = cut_base(main | card | strip, main)
    assert removed and not (cut & card & ~main).any()
    assert (cut & strip).sum() == strip.sum()
