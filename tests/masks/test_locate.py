"""Locating a vessel in hard framings (tight crops, frame-filling backdrops, cut-outs, labels, stands) and
splitting off its appendages, on rendered vases pasted over backdrops (the truth is known)."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest

from radar_cli.errors import InputError
from radar_cli.masks import crop as crops
from radar_cli.masks import detect
from radar_cli.masks.appendages import fine_tilt, symmetric_core
from radar_cli.masks.locate import (
    STRAIGHTEN,
    fill_painted_holes,
    locate_object,
    open_gaps,
    remove_stand,
    stands_upright,
)
from radar_cli.masks.refine import iou
from radar_cli.masks.synthetic import composite, render_vases
from radar_cli.masks.variants import KINDS, Variant, make_variant, with_handles

SIZE = 128


@pytest.fixture(scope="module")
def sources() -> list[tuple[np.ndarray, np.ndarray]]:
    """Two rendered vases pasted over a gradient studio backdrop: (photo, truth)."""
    vases, alpha, masks = render_vases(2, 160, seed=3)
    rng = np.random.default_rng(4)
    return [composite(vases[i], alpha[i], masks[i], "gradient", rng, shape=(360, 300)) for i in range(2)]


def located_iou(variant: Variant) -> tuple[float, object]:
    found = locate_object(variant.image, SIZE)
    return crops.reference_iou(found.silhouette | found.appendages, variant.truth, found.box), found


@pytest.mark.parametrize("kind", KINDS)
def test_every_framing_is_located(sources: list, kind: str) -> None:
    rng = np.random.default_rng(7)
    for n, (photo, truth) in enumerate(sources):
        score, found = located_iou(make_variant(kind, photo, truth, rng, index=n))
        assert score >= 0.9, (kind, n, score)
        assert found.frame_coverage < 0.9


def test_tight_crop_records_the_cut_edges_and_pads_white(sources: list) -> None:
    photo, truth = sources[0]
    variant = make_variant("tight", photo, truth, np.random.default_rng(1))
    _, found = located_iou(variant)
    assert {"top", "bottom"} <= set(found.cut_edges) and not {"left", "right"} & set(found.cut_edges)
    ys = np.nonzero(found.silhouette.any(1))[0]
    assert ys.min() > 2 and ys.max() < SIZE - 3  # the crop shows the whole object with a margin, not streaks


def test_rgba_cut_out_uses_its_alpha(sources: list) -> None:
    photo, truth = sources[1]
    variant = make_variant("rgba", photo, truth, np.random.default_rng(2))
    assert variant.image.shape[2] == 4
    score, found = located_iou(variant)
    assert score >= 0.97 and found.image[0, 0].tolist() == [255, 255, 255]


def test_stand_is_cut_off() -> None:
    mask = np.zeros((100, 100), bool)
    yy, xx = np.mgrid[0:100, 0:100]
    mask |= ((xx - 50) / 20.0) ** 2 + ((yy - 45) / 30.0) ** 2 < 1  # the vessel, rows 15..75
    mask[66:76, 35:65] = True  # its foot ring, 30 px wide
    mask[76:, 33:67] = True  # a plinth to the bottom edge, a little wider than the foot (13 %)
    image = np.full((100, 100, 3), 60, np.uint8)
    image[76:] = 200
    cut, removed = remove_stand(mask, image)
    assert removed and not cut[80:].any() and cut[40].sum() == mask[40].sum() and cut[70].any()
    assert not remove_stand(mask, np.full_like(image, 60))[1]  # the vessel's own colour and a small step: kept
    band = np.full_like(image, 60)
    band[76:] = 95  # a foot ring of a lighter clay or glaze band: another shade, but the vessel's own
    assert not remove_stand(mask, band)[1]
    wide = mask.copy()
    wide[76:, 20:80] = True  # a much wider plinth goes whatever its colour
    assert remove_stand(wide, np.full_like(image, 60))[1]
    narrow = mask.copy()
    narrow[76:] = False
    narrow[76:, 42:58] = True  # a base much narrower than the foot above it, of the vessel's colour: its own
    assert not remove_stand(narrow, np.full_like(image, 60))[1]
    cylinder = np.zeros_like(mask)
    cylinder[20:, 35:65] = True  # a straight-sided vessel cut by the frame is not a stand
    assert not remove_stand(cylinder, image)[1]


def test_handles_are_left_out_of_the_core(sources: list) -> None:
    rng = np.random.default_rng(5)
    for photo, truth in sources:
        image, handled = with_handles(photo, truth, rng)
        found = locate_object(image, SIZE)
        assert crops.reference_iou(found.silhouette, truth, found.box) >= 0.9
        assert found.appendage_fraction > 0.03


def _hugging_handles(gap_colour: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 200 x 200 vessel with two loop handles that hug the body over half its height, the thin gap between
    them filled in the located mask (as GrabCut closes it): (mask, image, the body's own silhouette)."""
    yy, xx = np.mgrid[0:200, 0:200]
    body = ((xx - 100) / 45.0) ** 2 + ((yy - 100) / 80.0) ** 2 < 1
    loop = ((xx - 100) / 56.0) ** 2 + ((yy - 95) / 45.0) ** 2
    handles = (loop < 1) & (loop > 0.8) & (yy > 60) & (yy < 130)
    filled = (loop < 1) & (yy > 60) & (yy < 130)
    image = np.full((200, 200, 3), 200, np.uint8)  # the backdrop
    image[filled] = gap_colour
    image[body | handles] = (90, 50, 30)
    return body | filled, image, body


def test_backdrop_between_a_hugging_handle_and_the_body_is_opened() -> None:
    mask, image, body = _hugging_handles(200)
    assert iou(symmetric_core(mask).core, body) < 0.93  # filled, the handles widen the core over a long span
    opened = open_gaps(mask, image)
    assert not (opened & ~mask).any() and opened[body].all()
    assert iou(symmetric_core(opened).core, body) >= 0.97
    mask, image, _ = _hugging_handles(208)  # the backdrop seen through the gap, a little lighter: opened
    assert iou(symmetric_core(open_gaps(mask, image)).core, body) >= 0.97
    outside = np.zeros_like(mask)
    outside[:, 185:] = True  # the window's padding beyond the photo's edge, another grey: not backdrop
    image[outside] = 120
    assert iou(symmetric_core(open_gaps(mask, image, outside)).core, body) >= 0.97
    mask, image, _ = _hugging_handles(120)  # no backdrop between them: nothing is opened
    assert (open_gaps(mask, image) == mask).all()
    decorated = image.copy()
    decorated[90:110, 90:110] = 200  # a backdrop-coloured patch on the axis is the vessel's own
    assert open_gaps(body, decorated)[90:110, 90:110].all()


def test_a_black_glaze_near_a_dark_backdrops_grey_is_no_gap_but_the_backdrop_past_its_handle_is() -> None:
    mask, image, body = _hugging_handles(60)
    image[mask] = np.where(image[mask] == 60, 60, 30)  # a black krater on a dark grey sweep
    image[~mask] = 60
    yy, xx = np.mgrid[0:200, 0:200]
    sheen = body & (xx < 70) & (yy > 140) & (yy < 170)  # a grey reflection on the glaze near the flank
    image[sheen] = 50  # 17 levels from the backdrop (a candidate), 35 from the glaze around it
    opened = open_gaps(mask, image)
    assert opened[sheen].all()  # closer to the glaze than GAP_CONTRAST times its distance to the backdrop
    assert iou(symmetric_core(opened).core, body) >= 0.97  # the gaps past the handles are open
    assert open_gaps(mask, image, kept=mask)[mask].all()  # what was given back on purpose stays


def test_paint_of_the_backdrops_colour_deep_inside_is_filled_and_a_handles_loop_is_not() -> None:
    y, x = np.mgrid[0:256, 0:256]
    body = ((x - 128) / 70.0) ** 2 + ((y - 140) / 90.0) ** 2 <= 1  # 140 px wide
    figure = (np.abs(x - 128) <= 15) & (np.abs(y - 140) <= 40)  # a light figure GrabCut took for backdrop
    assert (fill_painted_holes(body & ~figure) == body).all()
    loop = (np.hypot(x - 205, y - 140) <= 22) & ~(np.hypot(x - 205, y - 140) <= 12)  # a ring handle on the flank
    hole = np.hypot(x - 205, y - 140) <= 12
    with_handle = (body | loop) & ~hole
    assert (fill_painted_holes(with_handle) == with_handle).all()  # backdrop seen through, near the outline
    near = (np.abs(x - 68) <= 4) & (np.abs(y - 140) <= 20)  # a patch 6 px inside the flank: not filled
    assert (fill_painted_holes(body & ~near) == (body & ~near)).all()


def test_a_hole_near_the_flank_is_paint_where_the_outline_beside_it_is_the_bodys_and_kept_beside_a_handle() -> None:
    """A light object painted near the flank of a greyscale vase, GrabCut's mask holding a thin rim of glaze
    beyond it: the outline there runs on as the body's, and the hole is filled. A loop handle on the same flank
    stands out of the body beside the backdrop seen through it: that hole stays, and so does one beside the
    neck, near the rim, where the body's outline is no parabola."""
    y, x = np.mgrid[0:256, 0:256]
    body = ((x - 128) / 70.0) ** 2 + ((y - 128) / 100.0) ** 2 <= 1  # rows 28-228, 140 px wide
    inside = ((x - 128) / 66.0) ** 2 + ((y - 128) / 100.0) ** 2 <= 1  # 4 px of glaze along the flank
    hole = inside & (x >= 185) & (np.abs(y - 128) <= 12)
    assert (fill_painted_holes(body & ~hole) == body).all()
    loop = ((x - 196) / 20.0) ** 2 + ((y - 128) / 26.0) ** 2
    gap = (loop <= 0.45) & (x >= 192)  # the backdrop seen through the handle, between it and the body
    with_handle = (body | ((loop <= 1) & (x >= 190))) & ~gap
    assert gap.any() and (fill_painted_holes(with_handle) == with_handle).all()
    high = inside & (x >= 150) & (np.abs(y - 45) <= 8) & ~(((x - 128) / 62.0) ** 2 + ((y - 128) / 100.0) ** 2 <= 1)
    assert high.any() and (fill_painted_holes(body & ~high) == (body & ~high)).all()


def test_a_large_figure_of_the_backdrops_grey_on_a_greyscale_plate_is_paint_and_a_handles_gap_is_not() -> None:
    y, x = np.mgrid[0:256, 0:256]
    body = ((x - 128) / 90.0) ** 2 + ((y - 140) / 100.0) ** 2 <= 1  # 180 px wide
    figure = (np.abs(x - 75) <= 18) & (np.abs(y - 140) <= 45)  # off the axis, 3 px inside the flank
    assert figure.sum() >= 0.07 * (body & ~figure).sum()
    assert (fill_painted_holes(body & ~figure, greyscale=True) == body).all()
    assert (fill_painted_holes(body & ~figure) == (body & ~figure)).all()  # in colour, GrabCut is trusted
    gap = (np.abs(x - 50) <= 5) & (np.abs(y - 110) <= 25)  # a handle's gap: 2 % of the object
    assert (fill_painted_holes(body & ~gap, greyscale=True) == (body & ~gap)).all()
    image = np.full((256, 256, 3), 150, np.uint8)  # the backdrop's grey
    image[body] = 60
    image[figure] = 150  # the figure's paint, as grey as the backdrop, GrabCut's mask holding it
    assert open_gaps(body, image, greyscale=True)[figure].all()
    assert not open_gaps(body, image)[figure].any()  # in colour it is taken for backdrop seen through
    assert open_gaps(body, image, kept=figure)[figure].all()  # unless filled as paint already


def test_a_pale_vessel_filling_the_width_is_located_whole_not_as_the_panel_painted_on_it(monkeypatch) -> None:
    """A pale vessel filling a greyscale plate's width with a darker panel painted on it, the backdrop seen only in
    thin margins either side: GrabCut's colour models drift until the panel alone is kept (the whole-photo cut
    gives the vessel's ground to the backdrop); its strong evidence, whose outline lies on the vessel's edges,
    stands instead."""
    rng = np.random.default_rng(0)
    height, width, margin = 320, 140, 8
    truth = np.zeros((height, width), bool)
    truth[:, margin : width - margin] = True  # cut by the top and bottom edges, like an albarello's plate
    plate = np.where(truth, 175.0, 128.0)
    plate[40:280, 30:110] = 122  # the panel, about the backdrop's grey
    plate[60:250, 40:70] = 150
    plate = cv2.GaussianBlur(plate + rng.normal(0, 4, plate.shape), (0, 0), 0.8)
    image = np.repeat(np.clip(plate, 0, 255).astype(np.uint8)[..., None], 3, axis=2)

    def found() -> float:
        mask = detect.detect(image, thorough=True)[0].mask
        return float((mask & truth).sum() / (mask | truth).sum())

    assert found() > 0.9
    monkeypatch.setattr(detect, "DRIFT_SHARE", 1.0)  # GrabCut's cut, however much strong evidence it drops
    assert found() < 0.6
    monkeypatch.setattr(detect, "DRIFT_SHARE", 0.25)
    monkeypatch.setattr(detect, "DRIFT_SUPPORT", 1.01)  # nor the evidence, however well its outline lies on edges
    assert found() < 0.6


def test_a_plain_solid_has_no_appendages(sources: list) -> None:
    for _, truth in sources:
        split = symmetric_core(truth)
        assert split.appendage_fraction < 0.02 and split.symmetry > 0.85


def test_a_slender_vessels_thumbnail_under_64_px_wide_is_located() -> None:
    """A tall slender vessel cut close, as a web thumbnail gives it (60 x 190 px): under 64 px across, still a
    photo to locate; a photo under 64 px on its long edge is not."""
    y, x = np.mgrid[0:190, 0:60]
    half = 22 - 8 * np.exp(-(((y - 30) / 12.0) ** 2))  # a neck under a flaring rim
    truth = (np.abs(x - 30) <= half) & (y >= 8) & (y <= 182)
    image = np.where(truth[..., None], np.array([150, 95, 60]), np.array([205, 205, 200])).astype(np.uint8)
    found = locate_object(image, SIZE)
    assert crops.reference_iou(found.silhouette | found.appendages, truth, found.box) > 0.85
    with pytest.raises(InputError, match="too small"):
        locate_object(image[:60], SIZE)


def test_blank_photo_is_one_clear_error() -> None:
    with pytest.raises(InputError, match="blank.png"):
        locate_object(np.full((120, 90, 3), 200, np.uint8), SIZE, "blank.png")


def test_a_vessel_under_a_hundredth_of_the_photo_is_one_clear_error(sources: list) -> None:
    """A vessel filling under 1 % of a wide shot is taken for dust: the error says so and how to get past it."""
    photo, truth = sources[0]
    small, inside = photo[::2, ::2], truth[::2, ::2]
    h, w = inside.shape
    wide = np.full((1500, 2000, 3), 128, np.uint8)
    wide[1000:1000 + h, 1400:1400 + w][inside] = small[inside]
    assert inside.sum() < 0.01 * 1500 * 2000
    with pytest.raises(InputError, match=r"wide.png: .*under 1% of the photo.*crop the photo around it"):
        locate_object(wide, SIZE, "wide.png")
    found = locate_object(wide[900:1300, 1300:1800], SIZE, "cropped.png")  # cropped around it: found
    assert found.silhouette.sum() > 0.1 * SIZE * SIZE


def _axis_lean_deg(silhouette: np.ndarray) -> float:
    """The lean (deg) of the line through a bool silhouette's row midpoints."""
    rows = np.nonzero(silhouette.any(1))[0]
    mids = [np.nonzero(silhouette[y])[0].mean() for y in rows]
    return float(np.degrees(np.arctan(np.polyfit(rows, mids, 1)[0])))


def test_a_vessel_stands_upright_by_its_core_whatever_stands_on_one_side_of_its_rim(sources: list) -> None:
    """A head perched on one end of the rim tilts the mirror axis of all that was located, not the core's: a
    straightened photo whose crop also holds such a part is still read as upright."""
    found = locate_object(sources[0][0], SIZE)
    assert stands_upright(found)
    rows, cols = np.nonzero(found.silhouette)
    head = np.zeros(found.silhouette.shape, np.uint8)
    r = max(4, int(0.25 * (cols.max() - cols.min())))  # a lid's head, half the rim wide
    cv2.circle(head, (int(cols[rows == rows.min()].max()), max(int(rows.min()) - r + 2, r)), r, 1, -1)
    whole = found.silhouette | found.appendages | (head > 0)
    assert abs(fine_tilt(whole, 0.0)[0]) >= STRAIGHTEN[0]  # read on the whole, it leans
    assert stands_upright(replace(found, appendages=whole & ~found.silhouette))
    assert not stands_upright(replace(found, cut_edges=("left",)))


def test_a_photo_turned_a_few_degrees_is_straightened_and_its_crop_maps_back_to_the_photo(sources: list) -> None:
    photo, truth = sources[0]
    as_drawn = locate_object(photo, SIZE)  # the rendered vase leans a little itself (its camera's roll)
    h, w = truth.shape
    # turned so that it leans 4 deg the other way (counter-clockwise: a camera off level)
    turn = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), as_drawn.box.turn + 4.0, 1.0)
    tilted = cv2.warpAffine(photo, turn, (w, h), borderMode=cv2.BORDER_REPLICATE)
    tilted_truth = cv2.warpAffine(truth.astype(np.float32), turn, (w, h)) > 0.5
    found = locate_object(tilted, SIZE)
    assert abs(found.box.turn + 4.0) <= 0.75, (found.box.turn, as_drawn.box.turn)
    assert abs(_axis_lean_deg(found.silhouette)) < 1.0  # upright in the crop
    assert crops.reference_iou(found.silhouette | found.appendages, tilted_truth, found.box) >= 0.93
    unturned = crops.CropBox(found.box.x0, found.box.y0, found.box.side)
    assert crops.reference_iou(found.silhouette | found.appendages, tilted_truth, unturned) < 0.93
