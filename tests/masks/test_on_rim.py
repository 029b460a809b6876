"""Flowers standing in a vessel's mouth are cut off the located object; a lid's knob, volutes rising at the rim's
ends and a plain vessel are left whole. The masks are drawn here."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.on_rim import cut_on_rim
from radar_cli.masks.refine import iou

N = 256


def krater(top: int = 90) -> np.ndarray:
    """N x N bool silhouette of a krater: a wide rim, a neck, a round body, a foot (axis at column 128)."""
    y, x = np.mgrid[0:N, 0:N].astype(np.float64)
    t = (y - top) / (N - 20 - top)  # 0 at the rim, 1 under the foot
    body = 0.5 * np.sqrt(np.clip(1 - ((t - 0.5) / 0.42) ** 2, 0, 1))
    radius = 150 * np.maximum.reduce([body, np.where(t < 0.06, 0.45, 0.0), np.where((t >= 0.06) & (t < 0.2), 0.36, 0.0),
                                      np.where((t >= 0.9) & (t <= 1.0), 0.22, 0.0)])
    return (np.abs(x - 128) <= radius) & (t >= 0) & (t <= 1)


def test_flowers_in_the_mouth_are_cut_off() -> None:
    vessel = krater()
    flowers = np.zeros((N, N), np.uint8)
    for x_tip, y_tip in [(70, 20), (110, 10), (150, 15), (190, 25), (128, 35)]:
        cv2.line(flowers, (128 + (x_tip - 128) // 4, 92), (x_tip, y_tip), 1, 3)
        cv2.circle(flowers, (x_tip, y_tip), 9, 1, -1)
    cv2.fillPoly(flowers, [np.array([[112, 92], [144, 92], [128, 60]])], 1)  # the backdrop between the stems, filled
    cut, removed = cut_on_rim(vessel | (flowers > 0))
    assert removed and iou(cut, vessel) >= 0.98


def test_a_bunch_as_wide_as_half_the_mouth_is_cut_at_the_rims_sloping_top() -> None:
    """The rim's top edge slopes over two rows into a filled bunch of stems 0.45 as wide as the rim, which then
    narrows slowly: no row's run is under half the one below it, but it is under half the rim's. The stems lean
    unevenly, as a bunch's do (not mirror images of each other about the axis, as a neck and lip are)."""
    vessel = krater()
    rim = vessel.copy()
    rim[89, 128 - 50 : 128 + 51] = True  # the rim's back arc
    flowers = np.zeros((N, N), np.uint8)
    wedge = [[128 - 30, 88], [128 + 30, 88], [128 + 8, 60], [128 - 8, 60]]
    cv2.fillPoly(flowers, [np.array(wedge)], 1)  # the backdrop between the stems, filled
    for x_tip, y_tip in [(62, 16), (96, 8), (141, 12), (168, 26)]:
        cv2.line(flowers, (128 + (x_tip - 128) // 8, 62), (x_tip, y_tip), 1, 3)
        cv2.circle(flowers, (x_tip, y_tip), 9, 1, -1)
    cut, removed = cut_on_rim(rim | (flowers > 0))
    assert removed and iou(cut, rim) >= 0.98


def test_a_knob_volutes_and_a_plain_vessel_stay() -> None:
    vessel = krater()
    knob = vessel.copy()
    cv2.ellipse(knob.view(np.uint8), (128, 90), (18, 22), 0, 180, 360, 1, -1)  # a lid's knob on the mouth
    volutes = vessel.copy()
    for cx in (66, 190):  # curls rising above the rim's ends
        cv2.circle(volutes.view(np.uint8), (cx, 78), 12, 1, -1)
    for mask in (vessel, knob, volutes):
        kept, removed = cut_on_rim(mask)
        assert not removed and (kept == mask).all()


def test_a_narrow_neck_under_a_wide_lip_found_in_part_stays() -> None:
    """A jug's body, a neck a third of its width under a lip three times the neck's width, the neck found only in
    part (a glass neck as grey as the backdrop): its foot only along its middle, so the shoulder ends in a step as
    a rim does, and the neck with its lip fills under half its box, as stems do; but it is its own mirror image
    about the axis, and stays."""
    jug = np.zeros((N, N), np.uint8)
    cv2.ellipse(jug, (128, 165), (62, 70), 0, 0, 360, 1, -1)  # the body, its shoulder's top at row 95
    cv2.rectangle(jug, (128 - 24, 230), (128 + 24, 240), 1, -1)  # the foot
    cv2.rectangle(jug, (128 - 11, 50), (128 + 11, 100), 1, -1)  # the neck
    cv2.rectangle(jug, (128 - 30, 44), (128 + 30, 52), 1, -1)  # the lip
    jug[86:101, 128 - 11 : 128 - 4] = 0  # the neck's foot found only along its middle
    jug[86:101, 128 + 5 : 128 + 12] = 0
    jug[70:80, 128 - 11 : 128 - 6] = 0  # a bite out of one flank ...
    jug[58:64, 128 + 7 : 128 + 12] = 0  # ... and one out of the other, higher
    kept, removed = cut_on_rim(jug > 0)
    assert not removed and (kept == (jug > 0)).all()


def test_a_dense_bunch_leaning_to_one_side_is_cut_on_a_colour_photo() -> None:
    """Leaves and blossoms filled in between, 0.6 of their box and leaning to one side (IoU 0.24 with their mirror
    image): too dense to be stems, too lopsided to be a lid's head. Cut on a colour photo; on a greyscale one,
    where the vessel's own rim can come out so, only sparse parts are cut."""
    vessel = krater()
    bunch = np.zeros((N, N), np.uint8)
    cv2.fillPoly(bunch, [np.array([[112, 92], [150, 92], [196, 40], [180, 22], [140, 16], [118, 34]])], 1)
    for cx, cy in [(120, 24), (170, 14), (200, 34)]:
        cv2.circle(bunch, (cx, cy), 10, 1, -1)
    cut, removed = cut_on_rim(vessel | (bunch > 0))
    assert removed and iou(cut, vessel) >= 0.98
    kept, removed = cut_on_rim(vessel | (bunch > 0), greyscale=True)
    assert not removed


def test_a_head_turned_aside_on_the_rim_stays() -> None:
    """A lid shaped as a head in profile: a round head with a beak to one side sits on the mouth, off the axis.
    Lopsided (IoU 0.07 with its mirror image) and 0.57 of its box, as a leaning bunch is, but its outline is convex
    all round but the beak (0.91 of its hull): it stays, for `appendages.above_rim` to measure."""
    vessel = krater()
    head = vessel.copy().view(np.uint8)
    cv2.circle(head, (150, 58), 30, 1, -1)
    cv2.fillPoly(head, [np.array([[172, 40], [215, 55], [175, 70]])], 1)  # the beak
    kept, removed = cut_on_rim(head.astype(bool))
    assert not removed and kept.sum() == head.sum()
