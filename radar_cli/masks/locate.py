"""Find the one vessel of a photograph in any framing and cut its network crop: the object may touch the
frame, the backdrop may fill it, the photo may be a cut-out (on white, or transparent), carry a label or colour
chart, or show the vessel on a stand. The silhouette is split into its symmetric core and its appendages.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import cv2
import numpy as np

from radar_cli.errors import InputError
from radar_cli.masks import crop as crops
from radar_cli.masks.appendages import Core, above_rim, find_axis, fine_tilt, symmetric_core, upright_rotation
from radar_cli.masks.border import frame_inset
from radar_cli.masks.detect import (
    MIN_AREA_FRAC,
    WORK_SIDE,
    Detection,
    detect,
    downscale,
    fill_holes,
    fit_backdrop,
    is_greyscale,
)
from radar_cli.masks.neighbours import base_off_axis, cut_at_frame, cut_base, cut_behind, split_neighbour
from radar_cli.masks.on_rim import cut_on_rim
from radar_cli.masks.pipeline import (
    Refined,
    Settings,
    check_photo,
    refine_detection,
    refine_window,
)
from radar_cli.masks.refine import main_component, row_extents
from radar_cli.masks.sheen import grow_sheen

CUTOUT_MIN_CLEAR = 0.01  # an alpha channel with at least this share of clear pixels is a cut-out's silhouette
STAND_MIN, STAND_MAX = 0.03, 0.6  # a stand's height as a fraction of the located height
STAND_STEP = 0.08  # ... whose width differs from the vessel's foot above it by at least this fraction
STAND_TOLERANCE = 0.015  # straight sides: the stand's edges move less than this fraction of the window per row
STAND_COLOUR_STEP = 75.0  # ... and whose mean colour is this far (RGB levels) from the vessel's above it ...
STAND_BIG_STEP = 0.25  # ... unless it is wider than the foot by this share of its own width
GAP_RING = (0.02, 0.06)  # the backdrop around the object is modelled from this ring (fraction of the window)
GAP_DISTANCE = 3.0  # object pixels this close to the backdrop model (in its noise units) may be backdrop ...
GAP_LEVELS = 20.0  # ... or this close in RGB levels, Euclidean (a gap seen through the vessel is lit otherwise) ...
GAP_MIN = 0.002  # ... seen through the object where they form a patch of at least this share of it ...
GAP_DEPTH = 0.08  # ... that comes this close (fraction of the object's width) to its outline ...
GAP_CONTRAST = 3.0  # ... and lies this many times as far from the object's own colour around it as from the backdrop
GAP_AROUND = 0.05  # the object's own colour: of its pixels within this share of the window, backdrop-like ones left out
STRAIGHTEN = (1.5, 6.0)  # an axis leaning this many degrees (at least, at most) is straightened; steeper: no camera
STRAIGHT_AGREEMENT = 0.93  # ... where the object turned upright agrees with its mirror image this well (a solid) ...
STRAIGHT_GAIN = 0.025  # ... and this much better than as it stands
PAINT_AREA = 0.07  # on a greyscale photo a hole this large (share of the object) is paint, wherever it lies
FLUSH = 0.01  # a hole beside which the outline sticks out of the body by at most this share of the width is paint ...
BODY_BAND = (0.3, 0.85)  # ... where it and the rows it is judged by lie within this band of the height (from the top)


@dataclass(frozen=True)
class Located:
    """One vessel located in a photo and cut to the network's square crop.

    Attributes:
        image: S x S x 3 uint8 RGB crop (cut-outs composited on white).
        silhouette: S x S bool, the symmetric core (what the network is asked to explain).
        appendages: S x S bool, the rest of the located object (handles, spouts, knobs).
        box: the crop's square window of the photo (may reach beyond the photo's edge), turned where the photo
            was straightened (`CropBox.turn`).
        cut_edges: the photo edges the object runs into (`top`, `bottom`, `left`, `right`).
        frame_coverage: share of the photo the located object covers.
        symmetry: solid-of-revolution score of the core.
        stand_removed: whether a stand under the vessel was cut off.
        neighbour_removed: whether a neighbouring object merged into the vessel was cut off.
        base_off_axis: share of the lowest rows of the located object off its symmetric core (a neighbour
            probably kept with it where large; `neighbours.base_off_axis`).
        above_rim: what of the object stands above its rim over the mouth, left out of the core (a lid's head,
            a stopper, flowers; `appendages.above_rim`): its area over the core's, its rise over the rim's width,
            the share of it mirrored about the axis.
        painted_fill: on a greyscale photo, the share of the object filled in as paint of the backdrop's grey
            (`fill_painted_holes`): where large, the outline is a guess (0 on colour photos).
        greyscale: whether the photo is greyscale (`detect.is_greyscale` of the refinement window): the outline
            was read from brightness alone.
    """

    image: np.ndarray
    silhouette: np.ndarray
    appendages: np.ndarray
    box: crops.CropBox
    cut_edges: tuple[str, ...]
    frame_coverage: float
    symmetry: float
    stand_removed: bool = False
    neighbour_removed: bool = False
    base_off_axis: float = 0.0
    above_rim: tuple[float, float, float] = (0.0, 0.0, 1.0)
    painted_fill: float = 0.0
    greyscale: bool = False

    @property
    def appendage_fraction(self) -> float:
        total = int(self.silhouette.sum()) + int(self.appendages.sum())
        return float(self.appendages.sum() / total) if total else 0.0


def split_alpha(photo: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """H x W x 3 RGB on white and the H x W bool opaque mask of a cut-out (H x W x 4 with clear pixels), else
    the photo and None."""
    if photo.ndim != 3 or photo.shape[2] != 4:
        return photo, None
    alpha = photo[..., 3]
    if (alpha < 128).mean() < CUTOUT_MIN_CLEAR or not (alpha >= 128).any():
        return np.ascontiguousarray(photo[..., :3]), None
    a = alpha[..., None].astype(np.float32) / 255.0
    rgb = (photo[..., :3] * a + 255.0 * (1 - a) + 0.5).astype(np.uint8)
    return rgb, alpha >= 128


def alpha_detection(opaque: np.ndarray) -> Detection:
    """The cut-out's largest opaque part as a detection at detection scale."""
    small, scale = downscale(np.dstack([opaque.astype(np.uint8) * 255] * 3), WORK_SIDE)
    mask = main_component(small[..., 0] > 127)
    ys, xs = np.nonzero(mask)
    if len(xs) == 0:
        mask, (ys, xs) = small[..., 0] > 0, np.nonzero(small[..., 0] > 0)
    box = (xs.min() / scale, ys.min() / scale, (xs.max() + 1) / scale, (ys.max() + 1) / scale)
    return Detection(mask, box, 1.0, scale)


def alpha_refined(rgb: np.ndarray, opaque: np.ndarray, found: Detection, settings: Settings) -> Refined:
    """The cut-out's own silhouette in the refinement window (no GrabCut: the alpha channel is the answer)."""
    window, work_side = refine_window(found, settings)
    mask = main_component(crops.warp_mask(opaque, crops.crop_affine(window, work_side), work_side))
    return Refined(mask, window, crops.outside_mask(window, opaque.shape, work_side), False,
                   crops.cut(rgb, window, work_side))


def remove_stand(mask: np.ndarray, image: np.ndarray) -> tuple[np.ndarray, bool]:
    """Cut a stand off the bottom of a located object: the bottom rows with straight sides, a few percent to
    under two thirds of the object's height, clearly wider or narrower than the vessel's foot above them and of
    another colour (a white card, a grey or wooden plinth: STAND_COLOUR_STEP), unless much wider than the foot (a
    plinth of the vessel's own colour). A vessel's own foot, ring or base is of its clay, glaze or glass, a few
    tens of levels from what is above it even where a reserved band or thicker glass darkens or lightens it;
    a straight vessel cut by the frame has no step.

    Args:
        mask: n x n bool located object. image: n x n x 3 uint8, the pixels it was located in.

    Returns:
        (mask without the stand, whether one was removed).
    """
    rows = np.nonzero(mask.any(1))[0]
    if len(rows) < 10:
        return mask, False
    height = rows.max() - rows.min() + 1
    left, right = row_extents(mask, rows)
    widths = right - left + 1
    while len(rows) > 10 and widths[-1] < 0.5 * np.median(widths[-10:]):  # a ragged sliver under the stand
        rows, left, right, widths = rows[:-1], left[:-1], right[:-1], widths[:-1]
    tol = max(1.5, STAND_TOLERANCE * mask.shape[0])
    k = len(rows) - 1
    while k > 0 and abs(left[k - 1] - left[-1]) <= tol and abs(right[k - 1] - right[-1]) <= tol:
        k -= 1
    span = len(rows) - k
    if not (STAND_MIN * height <= span <= STAND_MAX * height) or k < 4:
        return mask, False
    stand_w = right[-1] - left[-1] + 1
    foot_w = float(np.mean(right[k - 4 : k] - left[k - 4 : k] + 1))
    stand, above = mask.copy(), mask.copy()
    stand[: rows[k]] = False
    above[: rows[max(0, k - span)]] = False
    above[rows[k]:] = False
    colour_step = np.linalg.norm(image[stand].mean(0) - image[above].mean(0))
    step = (foot_w - stand_w) / stand_w  # < 0: the stand is the wider
    if abs(step) < STAND_STEP or (colour_step < STAND_COLOUR_STEP and step > -STAND_BIG_STEP):
        return mask, False
    return main_component(mask & ~stand), True


def across_axis(part: np.ndarray, turn: np.ndarray, axis: float) -> bool:
    """Whether a part (n x n bool) of an object spans its axis: the column `axis` of the object turned upright by
    `turn` (2 x 3 affine, `upright_rotation`) lies within the part's upright columns."""
    py, px = np.nonzero(part)
    upright_x = turn[0, 0] * px + turn[0, 1] * py + turn[0, 2]
    return bool(upright_x.min() <= axis + 0.5 <= upright_x.max() + 1)


def fill_painted_holes(mask: np.ndarray, greyscale: bool = False) -> np.ndarray:
    """Fill the holes of a located object that lie deep inside it, across its axis: backdrop is seen through a
    vessel only between a handle and the body, off the axis (a thick handle's loop can lie deep inside the
    outline) or near the outline (a handle arching over the mouth). A hole the axis crosses whose every pixel
    is at least GAP_DEPTH of the object's width inside its outer outline is paint of the backdrop's colour (a
    light figure on a greyscale plate), which GrabCut took for backdrop. On a greyscale photo, where brightness
    is GrabCut's only cue, so is a hole of PAINT_AREA of the object or more wherever it lies (a figure off the
    axis, reaching close to the outline): the backdrop seen between a handle and the body is a few percent of
    the object (at most 0.06 on the CVA 10 kraters, the Met photographs and the small crops; a figure 0.08-0.12).
    Nor is a hole beside which no handle stands out of the body (`_flush_beyond`).

    Args:
        mask: n x n bool located object.
        greyscale: whether the photo is greyscale (detect.is_greyscale).

    Returns:
        n x n bool mask with those holes filled.
    """
    cols = np.nonzero(mask.any(0))[0]
    if len(cols) < 10:
        return mask
    solid = fill_holes(mask)
    holes = solid & ~mask
    if not holes.any():
        return mask
    depth = cv2.distanceTransform(np.pad(solid, 1).astype(np.uint8), cv2.DIST_L2, 3)[1:-1, 1:-1]
    tilt, axis = find_axis(solid)
    turn = upright_rotation(solid, tilt)
    count, labels = cv2.connectedComponents(holes.astype(np.uint8), connectivity=4)
    filled = mask.copy()
    large = PAINT_AREA * mask.sum() if greyscale else np.inf
    width = cols[-1] - cols[0] + 1
    for i in range(1, count):
        part = labels == i
        if part.sum() >= large:
            filled |= part
        elif depth[part].min() >= GAP_DEPTH * width and across_axis(part, turn, axis):
            filled |= part
        elif _flush_beyond(part, solid, axis, width):
            filled |= part
    return filled


def _flush_beyond(part: np.ndarray, solid: np.ndarray, axis: float, width: int) -> bool:
    """Whether the object's outline beside a hole (n x n bool `part` of the n x n bool `solid`, holes filled;
    `axis` its axis' column, `width` its width in px) runs on as the body's own, sticking out of it by at most
    FLUSH of that width: the body's outline there is a parabola through the outline over as many rows above and
    below the hole as it spans, all of them within BODY_BAND of the height. A handle stands out of the body
    beside the backdrop seen through it; a light figure or an object painted near the flank, which GrabCut took
    for backdrop on a greyscale photo, leaves the outline where it was (Met `DP117199` in grey: 0.0015 of the
    width; a handle on the body, `DP250469`: 0.11-0.16)."""
    rows = np.nonzero(solid.any(1))[0]
    top, height = rows[0], rows[-1] - rows[0] + 1
    spans = np.nonzero(part.any(1))[0]
    first, last = spans[0], spans[-1]
    reach = max(last - first + 1, 5)
    if first - reach < top + BODY_BAND[0] * height or last + reach > top + BODY_BAND[1] * height:
        return False  # near the rim or the foot (a handle's root, a plate), the body's outline is no parabola
    span = np.arange(first - reach, last + reach + 1)  # the hole's rows and those it is judged by
    left, right = row_extents(solid, span)
    outer = (right if np.nonzero(part)[1].mean() > axis else -left).astype(np.float64)  # outward: larger
    beside = np.r_[0:reach, span.size - reach : span.size]
    body = np.polyval(np.polyfit(span[beside], outer[beside], 2), span[reach:-reach])
    return bool((outer[reach:-reach] - body).max() <= FLUSH * width)


def open_gaps(mask: np.ndarray, image: np.ndarray, outside: np.ndarray | None = None,
              kept: np.ndarray | None = None, greyscale: bool = False) -> np.ndarray:
    """Take out of a located object the backdrop seen between a handle and the body: patches of the object
    whose colour the backdrop around it explains, near its outline and beside the vessel's axis (a patch of
    the body's own decoration that matches the backdrop is rarely all three), and whose colour lies GAP_CONTRAST
    times as far from the object's own colour around it as from the backdrop's (a black glaze on a dark grey
    sweep is close to the backdrop too, but closer to the glaze beside it). The located mask has them filled
    (GrabCut closes a thin gap); open, they let the handle part from the body.

    Args:
        mask: n x n bool located object. image: n x n x 3 uint8, the pixels it was located in.
        outside: n x n bool, the padding beyond the photo's edge (no backdrop to model there), if any.
        kept: n x n bool, what the locator gave back to the object on purpose (the glaze's band along the
            flanks, `sheen.grow_sheen`; paint filled in, `fill_painted_holes`), if any: never a gap.
        greyscale: whether the photo is greyscale: a patch of PAINT_AREA of the object or more is then paint
            of the backdrop's grey, never a gap.

    Returns:
        n x n bool mask without the gaps (its largest part).
    """
    cols = np.nonzero(mask.any(0))[0]
    if len(cols) < 10:
        return mask
    n = mask.shape[0]
    near = cv2.dilate(mask.astype(np.uint8), np.ones((3, 3), np.uint8), iterations=max(1, int(GAP_RING[0] * n)))
    far = cv2.dilate(mask.astype(np.uint8), np.ones((3, 3), np.uint8), iterations=max(2, int(GAP_RING[1] * n)))
    ring = (far > 0) & ~(near > 0)
    if outside is not None:
        ring &= ~outside
    if ring.sum() < 50:
        return mask
    pixels = image.astype(np.float32)
    model, noise = fit_backdrop(pixels, ring)
    dist = np.sqrt((((pixels - model) / np.maximum(noise, GAP_LEVELS / GAP_DISTANCE)) ** 2).sum(axis=2))
    candidate = (mask & (dist < GAP_DISTANCE) & (True if kept is None else ~kept)).astype(np.uint8)
    count, labels, stats, _ = cv2.connectedComponentsWithStats(candidate, connectivity=4)
    if count <= 1:
        return mask
    own = mask & (dist >= GAP_DISTANCE)  # the object's pixels unlike the backdrop
    reach = max(1, round(GAP_AROUND * n))
    depth = cv2.distanceTransform(np.pad(mask, 1).astype(np.uint8), cv2.DIST_L2, 3)[1:-1, 1:-1]
    tilt, axis = find_axis(mask)
    turn = upright_rotation(mask, tilt)
    width = cols.max() - cols.min() + 1
    gaps = np.zeros_like(mask)
    large = PAINT_AREA * mask.sum() if greyscale else np.inf
    for i in range(1, count):
        if not GAP_MIN * mask.sum() <= stats[i, cv2.CC_STAT_AREA] < large:
            continue
        part = labels == i
        if depth[part].min() > GAP_DEPTH * width:
            continue
        if across_axis(part, turn, axis):
            continue
        around = (cv2.dilate(part.astype(np.uint8), np.ones((3, 3), np.uint8), iterations=reach) > 0) & own
        if around.sum() >= 10:
            to_object = np.linalg.norm(pixels[part] - np.median(pixels[around], axis=0), axis=1).mean()
            to_backdrop = np.linalg.norm(pixels[part] - model[part], axis=1).mean()
            if to_object < GAP_CONTRAST * to_backdrop:
                continue
        gaps |= part
    return main_component(mask & ~gaps) if gaps.any() else mask


def stands_upright(found: Located) -> bool:
    """Whether a located vessel stands clear of the frame with its symmetric core's mirror axis within
    STRAIGHTEN[0] of vertical in its crop. Read on the core, not on all that was located: a part on one side only
    (a head perched on one end of the rim) tilts the whole's mirror axis."""
    return not found.cut_edges and abs(fine_tilt(found.silhouette, 0.0)[0]) < STRAIGHTEN[0]


def locate_object(photo: np.ndarray, size: int, name: str = "image", margin: float = crops.DEFAULT_MARGIN) -> Located:
    """Locate the vessel of a photo and cut its square crop around the symmetric core. A vessel whose axis
    leans by STRAIGHTEN degrees (a camera not quite level, a scan turned on the glass), standing clear of the
    frame and clearly more symmetric upright (STRAIGHT_AGREEMENT, STRAIGHT_GAIN), is located again on the photo
    turned upright: its crop is straightened (`box.turn`) where the vessel located there stands upright
    (`stands_upright`).

    Args:
        photo: H x W x 3 uint8 RGB, or H x W x 4 RGBA (a transparent cut-out's alpha is its silhouette).
        size: S, the crop side.
        name: the file, for messages.
        margin: per-side margin of the crop around the core.

    Returns:
        Located; InputError if nothing stands out from the backdrop.
    """
    rgb, opaque = split_alpha(photo)
    check_photo(rgb, name)
    top, bottom, left, right = (0, 0, 0, 0) if opaque is not None else frame_inset(rgb)
    rgb = rgb[top : rgb.shape[0] - bottom, left : rgb.shape[1] - right]  # a flat frame round it is no part
    settings = Settings(size=size, margin=margin)
    found, (tilt, upright_agreement, level_agreement) = _locate(rgb, opaque, settings, name)
    leans = STRAIGHTEN[0] <= abs(tilt) <= STRAIGHTEN[1]
    solid = upright_agreement >= max(STRAIGHT_AGREEMENT, level_agreement + STRAIGHT_GAIN)
    if leans and solid and not found.cut_edges and opaque is None:
        turned, affine = crops.turned_photo(rgb, tilt)
        upright, _ = _locate(turned, None, settings, name)
        if stands_upright(upright):  # the same vessel, now upright
            scale = turned.shape[0] * turned.shape[1] / (rgb.shape[0] * rgb.shape[1])
            found = replace(upright, box=crops.box_in_photo(upright.box, affine, tilt),
                            frame_coverage=min(1.0, upright.frame_coverage * scale))
    box = found.box
    return replace(found, box=replace(box, x0=box.x0 + left, y0=box.y0 + top))  # in the photo with its frame


def _locate(rgb: np.ndarray, opaque: np.ndarray | None, settings: Settings, name: str
            ) -> tuple[Located, tuple[float, float, float]]:
    """`locate_object` on a photo without its frame (H x W x 3 RGB; a cut-out's H x W bool opaque pixels), as
    it is; and the tilt (deg) of the located object's axis with its mirror agreements (`appendages.fine_tilt`)."""
    greyscale, kept, painted = False, None, 0.0
    if opaque is not None:
        found = alpha_detection(opaque)
        refined = alpha_refined(rgb, opaque, found, settings)
    else:
        detections = detect(rgb, thorough=True)
        if not detections:
            raise InputError(f"{name}: no object stands out from the backdrop (one covering under "
                             f"{MIN_AREA_FRAC:.0%} of the photo is taken for dust); crop the photo around it, or "
                             "use --crop none")
        found = detections[0]
        refined = refine_detection(rgb, found, settings)
        # the glaze's band along the flanks given back, paint of the backdrop's colour filled in
        greyscale = is_greyscale(refined.image)
        grown = grow_sheen(refined.mask, refined.image, refined.outside)
        filled = fill_painted_holes(grown, greyscale)
        painted = float((filled & ~grown).sum() / filled.sum()) if greyscale else 0.0
        kept = filled & ~refined.mask  # given back on purpose: never taken out again as a gap
        refined = replace(refined, mask=filled)
    mask, neighbour = cut_behind(refined.mask)
    if not neighbour:
        mask, neighbour = split_neighbour(mask)
    mask, stand = remove_stand(open_gaps(mask, refined.image, refined.outside, kept, greyscale), refined.image)
    mask, _ = cut_on_rim(mask, greyscale)  # flowers, stems
    mask, framed = cut_at_frame(mask, refined.outside)  # after the stand: a plinth cut by the frame is no neighbour
    neighbour = neighbour or framed
    split: Core = symmetric_core(mask)
    mask, card = cut_base(mask, split.core)
    neighbour = neighbour or card
    final, image, core = refined.framed(rgb, split.core, settings, fill=255)  # beyond the frame: white
    _, _, whole = refined.framed(rgb, mask, settings, box_mask=split.core)
    k = refined.window.side / mask.shape[0]
    coverage = float(mask.sum() * k * k / (rgb.shape[0] * rgb.shape[1]))
    located = Located(image, core, whole & ~core, final, crops.cut_edges(whole, final, rgb.shape),
                      min(1.0, coverage), split.symmetry, stand, neighbour, base_off_axis(mask, split.core),
                      above_rim(mask, split.core), painted, greyscale)
    return located, fine_tilt(mask, split.tilt)
