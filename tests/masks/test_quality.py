"""The whole-object scores of masks.quality: how far a solid's outline is off a silhouette, how round a
silhouette is, how uneven or jagged its lower outline is, whether its top closes in a dome, how much of it
stands on the rim left out of the core, how much of its foot stands beside the solid, how narrow it ends below."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.appendages import above_rim
from radar_cli.masks.quality import (
    edge_roughness,
    foot_aside,
    foot_asymmetry,
    outline_residual,
    roundness,
    stem_base,
    top_dome,
)


def _box(shift: int = 0) -> np.ndarray:
    mask = np.zeros((200, 200), bool)
    mask[40:160, 60 + shift:140 + shift] = True
    return mask


def test_outline_residual_is_the_ends_distance_over_the_height() -> None:
    assert outline_residual(_box(), _box()) == 0.0
    # shifted 6 px sideways: rows' ends off by 6, columns' ends (top and bottom) off only where one mask lacks them
    assert abs(outline_residual(_box(), _box(6)) - 6 * 240 / (240 + 2 * 74) / 120) < 0.02
    assert outline_residual(np.zeros((10, 10), bool), _box()) is None


def test_a_disc_is_round_and_a_vase_outline_is_not() -> None:
    disc = np.zeros((200, 200), np.uint8)
    cv2.ellipse(disc, (100, 100), (70, 55), 10, 0, 360, 1, -1)
    assert roundness(disc > 0) > 0.97
    assert roundness(_box()) < 0.85  # straight rim and foot: a side view


def _vase(foot: int = 30) -> np.ndarray:
    """A vessel's outline: a bellied body on a foot whose lower edge is a level ellipse arc (seen a little from
    above), `foot` px in half-width."""
    mask = np.zeros((200, 200), np.uint8)
    for y in range(30, 170):
        half = int(30 + 35 * np.sin(np.pi * (y - 30) / 150))
        mask[y, 100 - half:100 + half + 1] = 1
    cv2.rectangle(mask, (100 - foot, 160), (100 + foot, 170), 1, -1)
    cv2.ellipse(mask, (100, 170), (foot, 6), 0, 0, 180, 1, -1)
    return mask > 0


def test_a_foot_is_symmetric_even_where_the_solid_misses_it() -> None:
    assert foot_asymmetry(_vase(), _vase()) == 0.0
    assert foot_asymmetry(_vase(36), _vase(26)) < 0.005  # a solid drawing the foot too narrow, on both sides
    assert foot_asymmetry(np.zeros((10, 10), bool), _vase()) is None


def test_a_foot_side_left_out_of_the_core_is_measured_and_a_shadow_is_not() -> None:
    """The foot's left side lost in the photo (a restoration of the backdrop's tone): the core keeps each row's
    shorter side, so the foot's right side is left out as an appendage as tall as the foot. A shadow on the floor
    is a flat sliver, a label beside the foot stands far out, a handle sits higher."""
    whole = np.zeros((200, 200), np.uint8)
    cv2.ellipse(whole, (100, 90), (60, 60), 0, 0, 360, 1, -1)  # the body, rows 30-150
    whole[150:158, 85:116] = 1  # a stem
    whole[158:177, 65:136] = 1  # the foot, 71 px wide
    whole = whole > 0
    whole[158:177, 65:71] = False  # its left end lost
    core = whole.copy()
    core[158:177, 130:] = False  # ... so the core's foot ends as short on the right
    app = whole & ~core
    assert 0.05 < foot_aside(app, whole, core) < 0.15
    shadow = np.zeros_like(whole)
    shadow[175:177, 130:160] = True  # 2 rows of the foot's 18
    assert foot_aside(shadow, _vase() | shadow, _vase()) == 0.0
    label = np.zeros_like(whole)
    label[160:177, 136:170] = True  # a card beside the foot, reaching out as far as the foot's half-width
    assert foot_aside(label, _vase() | label, _vase()) == 0.0
    handle = np.zeros_like(whole)
    handle[50:110, 160:170] = True
    assert foot_aside(handle, _vase() | handle, _vase()) == 0.0
    assert foot_aside(np.zeros_like(whole), _vase(), _vase()) == 0.0


def _broken(line: np.ndarray) -> float | None:
    """foot_asymmetry of the vessel's upper part above a break along `line` (a row per column), the solid
    following the unbroken part, cut level at the break's highest point."""
    rows = np.arange(200)[:, None]
    return foot_asymmetry(_vase() & (rows <= line[None]), _vase() & (rows <= line[30:170].min()))


def test_a_broken_lower_edge_is_not_a_foot() -> None:
    """A straight slanted break (a sherd's edge) and jagged ones (a random walk of 12 px, as
    experiments.status_cases draws them): a jagged break is caught where it is uneven enough, which a random walk
    is not always (0.023-0.054 on the five below: two stay under the limit of 0.03)."""
    cols = np.arange(200)
    assert _broken(100 + 0.3 * (cols - 100)) > 0.1
    jagged = []
    for seed in range(5):
        walk = np.cumsum(np.random.default_rng(seed).normal(0, 1, 200))
        walk -= np.interp(cols, [0, 199], [walk[0], walk[-1]])
        jagged.append(_broken(110 + 12 * walk / np.abs(walk).max()))
    assert min(jagged) > 0.02 and sum(v > 0.03 for v in jagged) >= 3, jagged


def test_a_jagged_break_is_rough_where_a_foot_is_smooth() -> None:
    """The random-walk breaks above, nearly level or as uneven on both sides as a foot (where foot_asymmetry
    stays under its limit), are all rough; a foot's arc is smooth whether or not the solid follows it."""
    assert edge_roughness(_vase(), _vase()) == 0.0
    assert edge_roughness(_vase(36), _vase(26)) == 0.0
    cols, rows = np.arange(200), np.arange(200)[:, None]
    for seed in range(8):
        walk = np.cumsum(np.random.default_rng(seed).normal(0, 1, 200))
        walk -= np.interp(cols, [0, 199], [walk[0], walk[-1]])
        piece = _vase() & (rows <= (110 + 12 * walk / np.abs(walk).max())[None])
        assert edge_roughness(piece, _vase() & (rows <= 98)) > 0.004, seed
    assert edge_roughness(np.zeros((10, 10), bool), _vase()) is None


def _flask(top: str, size: float) -> np.ndarray:
    """A flask: a bellied body, a neck of half-width 12 and on top either an open mouth's lip (half-width 26, its
    rim an ellipse seen `size` deg from the side) or a head (an ellipse of half-width 22, `size` x that tall)."""
    mask = np.zeros((240, 200), np.uint8)
    for y in range(110, 231):
        half = int(20 + 50 * np.sin(np.pi * (y - 100) / 140))
        mask[y, 100 - half:100 + half + 1] = 1
    cv2.rectangle(mask, (88, 60), (112, 112), 1, -1)
    if top == "mouth":
        cv2.rectangle(mask, (74, 50), (126, 60), 1, -1)
        cv2.ellipse(mask, (100, 50), (26, max(1, round(26 * np.sin(np.radians(size))))), 0, 0, 360, 1, -1)
    else:
        cv2.ellipse(mask, (100, 64 - round(22 * size)), (22, round(22 * size)), 0, 0, 360, 1, -1)
    return mask > 0


def test_a_head_on_a_neck_is_a_dome_and_an_open_mouth_is_not() -> None:
    """An open mouth seen from the side up to 45 deg from above reads about 0.14 sin(pitch); a head as tall as
    the generated lids' (1.25 x its half-width) 0.18, a flatter knob less."""
    mouths = [top_dome(_flask("mouth", pitch)) for pitch in (0, 10, 20, 30, 45)]
    assert mouths[0] == 0.0 and max(mouths) < 0.12, mouths
    assert top_dome(_flask("head", 1.25)) > 0.16
    assert top_dome(_flask("head", 0.6)) < 0.1
    assert top_dome(_vase()) == 0.0  # no neck: the widest rows are the body's


def _bowl_on_stem(foot: int) -> np.ndarray:
    """A wide bowl (half-width 80) on a stem of half-width 12 that ends below in a foot of half-width `foot`
    (12: the stem broken off, no foot)."""
    mask = np.zeros((200, 200), np.uint8)
    cv2.ellipse(mask, (100, 40), (80, 70), 0, 0, 180, 1, -1)
    cv2.rectangle(mask, (88, 100), (112, 170), 1, -1)
    cv2.ellipse(mask, (100, 170), (foot, 4), 0, 0, 360, 1, -1)
    mask[:40] = 0
    return mask > 0


def test_a_stem_broken_off_ends_narrow_and_a_foot_spreads() -> None:
    broken = stem_base(_bowl_on_stem(12))
    assert broken is not None and broken[0] < 0.2 and broken[1] < 1.1, broken
    footed = stem_base(_bowl_on_stem(40))
    assert footed is not None and footed[0] >= 0.45 and footed[1] > 2.0, footed  # a spreading foot
    vase = stem_base(_vase())
    assert vase is not None and vase[0] > 0.4, vase  # a bellied vase on its foot
    disc = np.zeros((200, 200), np.uint8)
    cv2.circle(disc, (100, 100), 70, 1, -1)
    round_bottom = stem_base(disc > 0)
    assert round_bottom is not None and round_bottom[0] > 0.5, round_bottom  # an aryballos's round bottom
    assert stem_base(np.zeros((10, 10), bool)) is None


def test_what_stands_on_the_rim_is_measured_against_the_vessel() -> None:
    """A head on a lid, left out of the core, is a large share of the vessel above its rim; a thin handle's top
    rising above the rim is a small one; a plain vessel has none. A pair of volutes at the rim's ends, or a head
    in its middle, is mirrored about the axis; a head set on one end of the rim is not."""
    core = np.zeros((200, 200), bool)
    core[80:190, 60:140] = True  # the vessel, its rim at row 80, its axis at column 99.5
    head = core.astype(np.uint8)
    cv2.circle(head, (105, 55), 28, 1, -1)
    share, rise, mirrored = above_rim(head > 0, core)
    assert share > 0.12 and abs(rise - 53 / 80) < 0.02  # the circle's top at row 27: 53 rows over an 80 px rim
    assert mirrored > 0.7  # 5 px off the axis: most of it mirrored
    handle = core.copy()
    handle[65:80, 62:70] = True  # a volute's end, thin, at the rim's end
    share, rise, mirrored = above_rim(handle, core)
    assert 0 < share < 0.03 and abs(rise - 15 / 80) < 0.01 and mirrored == 0.0
    handle[65:80, 130:138] = True  # and its pair at the other end
    assert above_rim(handle, core)[2] == 1.0
    aside = core.astype(np.uint8)
    cv2.circle(aside, (125, 60), 22, 1, -1)  # a head perched on the right end of the rim
    share, _, mirrored = above_rim(aside > 0, core)
    assert share > 0.03 and mirrored < 0.2
    assert above_rim(core, core) == (0.0, 0.0, 1.0)
