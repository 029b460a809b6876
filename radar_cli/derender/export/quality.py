"""Which de-rendered objects to trust: scores of one object's result and its status (`ok`, `review`,
`failed`) with the reasons, for material.json's `quality` record and summary.csv."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from radar_cli.catalogue_terms import not_a_whole_vessel
from radar_cli.derender.export.faces import face_score
from radar_cli.derender.export.likeness import (
    colour_shift,
    glaring_highlights,
    highlight_excess,
    mouth_error,
    mouth_support,
    rim_contrast,
    shading_profile,
    shading_range,
)
from radar_cli.derender.export.renders import InputDrawing, ViewRenderer, input_drawing
from radar_cli.derender.run.inputs import Prepared
from radar_cli.derender.run.state import ObjectState
from radar_cli.masks.crop import outside_mask
from radar_cli.masks.locate import PAINT_AREA
from radar_cli.masks.neighbours import BASE_MERGED
from radar_cli.masks.outline import outline_support
from radar_cli.masks.quality import (
    edge_roughness,
    foot_aside,
    foot_asymmetry,
    outline_residual,
    roundness,
    sor_score,
    stem_base,
    top_dome,
)
from radar_cli.masks.refine import iou

STATUSES = ("failed", "review", "ok")  # worst first: the order a curator reads them in


@dataclass(frozen=True)
class QualityLimits:
    """Where a score sends an object to `review` or `failed`."""

    fail_coverage: float = 0.9
    """A located object covering this share of the photo is the backdrop, not an object: failed."""
    fail_iou: float = 0.5
    """Rendered vs located silhouette IoU below this: the solid does not explain the object: failed."""
    min_area: float = 0.02
    """A located silhouette under this share of the crop is too small to de-render: failed."""
    review_iou: float = 0.75
    """Rendered vs located silhouette IoU below this: review."""
    review_symmetry: float = 0.8
    """Solid-of-revolution score of the core below this: review (not a vessel of revolution?)."""
    review_appendage: float = 0.2
    """More than this share of the located object left out as appendage: review."""
    review_psnr: float = 10.0
    """Reconstruction PSNR (dB) inside the silhouette below this: review."""
    review_cut_edges: int = 3
    """An object running into this many photo edges or more: review (the photo may not show all of it)."""
    review_support: float = 0.65
    """Share of the silhouette's outline on an edge of the photo (`outline_support`) below this: review (the
    silhouette does not sit on the object's edge)."""
    review_object_symmetry: float = 0.8
    """Solid-of-revolution score of the whole located object (core and appendages) below this: review (a
    fragment, a figure or lid that is not turned, a neighbour in the silhouette)."""
    review_residual: float = 0.03
    """The solid's outline off the silhouette's by more than this share of its height: review (a broken edge,
    a sherd's outline)."""
    review_foot: float = 0.03
    """The object's lower outline further than this share of its height from mirror-symmetric about the solid's
    axis (`foot_asymmetry`): review (a broken edge or a sherd, not a foot)."""
    review_foot_aside: float = 0.05
    """A part of the foot's side as tall as the foot and larger than this share of the solid's foot, left out
    of the solid (`foot_aside`): review (the other side was lost, so the foot is drawn too narrow)."""
    review_roughness: float = 0.0008
    """The object's lower outline departing from its running median by more than this share of its height
    (`edge_roughness`): review (a jagged break, not a foot)."""
    review_dome: float = 0.13
    """The object's top closing in a dome above a neck over more than this share of the dome's width
    (`top_dome`): review (a head, a stopper or a knob on a lid, not a mouth)."""
    review_base_width: float = 0.24
    """The object's lowest tenth at most this share of its width (`base_width`) ..."""
    review_base_spread: float = 1.1
    """... and spreading less than this from the stem above it (`base_spread`): review (a stem broken off, not a
    foot)."""
    review_roundness: float = 0.9
    """The object's silhouette this close to a filled ellipse or closer, with a lit rim round a dark inside
    (`review_rim`): review (a view into the mouth from above, not a side view)."""
    review_rim: float = 2.0
    """`rim_contrast` at which a round silhouette is read as a view into the mouth."""
    review_shading: float = 0.12
    """Brightness across the object changing by less than this (`shading_range`): review (a flat piece)."""
    review_mouth: float = 0.14
    """The drawn inside of the mouth off the photo by more than this (mean luminance, 0..1): review (a mouth
    drawn where the photo shows the outer wall: the pitch too high, or no vessel) ..."""
    lip_support: float = 0.95
    """... unless the photo shows an edge along at least this share of the drawn mouth's outline
    (`mouth_support`): the mouth is there, its inside lit brighter than the renderer draws an inner wall."""
    review_highlights: float = 0.08
    """More than this share of the object drawn much brighter than the photo: review (invented highlights)."""
    review_glare: float = 0.005
    """More than this share of the object drawn brighter than the photo by GLARING away from its limbs
    (`glaring_highlights`): review (a white spot the photo does not have)."""
    review_colour: float = 15.0
    """The reconstruction's mean chroma further than this from the photo's (CIELAB): review."""
    review_face: float = 0.0
    """A face on the object scoring above this (`face`, the face detector's own threshold): review (a head vase,
    a figure or a lid shaped as a head, which the solid turns into a smooth body)."""
    review_base_off_axis: float = BASE_MERGED
    """More than this share of the located object's lowest rows off its symmetric core (`base_off_axis`):
    review (a neighbouring object, or a card in front of the foot, probably kept with it)."""
    review_painted_fill: float = PAINT_AREA
    """On a greyscale photo, at least this share of the object filled in as paint of the backdrop's grey
    (`painted_fill`): review (where the painting is as grey as the backdrop, the outline is a guess)."""
    review_greyscale_symmetry: float = 0.85
    """On a greyscale photo, the located object less symmetric about an axis than this (`object_symmetry`):
    review (read from brightness alone, its outline may follow painting as grey as the backdrop)."""
    review_above_rim: float = 0.08
    """More of the object than this (its area over the core's) standing above its rim over the mouth, left out of
    the solid (`above_rim`): review (a lid's head, a stopper, a figure or flowers)."""
    review_above_rim_rise: tuple[float, float] = (0.03, 0.3)
    """... or more than the first (area) rising above the rim by more than the second (of the rim's width,
    `above_rim_rise`): review. A volute or a handle's plate seen end-on is thin and low."""
    review_above_rim_aside: tuple[float, float] = (0.03, 0.4)
    """... or more than the first (area) with less than the second of it mirrored about the axis
    (`above_rim_mirrored`): review. Volutes and handles' plates stand in pairs at the rim's ends or end-on in
    its middle; a head set on one side of the rim stands alone."""
    review_views_outline: float = 0.015
    """An object seen in several photos whose shared solid lies off one of their silhouettes by more than this
    share of its height (`views_outline`; at most 0.0073 on the CVA 10 kraters' 20 side views, 0.023 with a
    third krater's photo among two of one): review (photos of different objects in one folder, or a view that
    is not from the side)."""
    review_cut_top: bool = True
    """An object the photo's top edge cuts: review (its rim, and whatever stands on it, is not in the photo)."""
    review_cut_sides: bool = True
    """An object both side edges of the photo cut: review (its widest rows, and so its radius, are not in the
    photo: a tight crop of a cylinder is rebuilt narrower than the vessel)."""


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    """PSNR in dB of two N x 3 uint8 pixel lists (inf if equal)."""
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return math.inf if mse == 0 else 10.0 * math.log10(255.0**2 / mse)


def _round(value: float | None, digits: int = 4) -> float | None:
    return None if value is None or not math.isfinite(value) else round(float(value), digits)


def support(prepared: Prepared) -> float | None:
    """Outline support of the located silhouette (masks.outline) in the photo as photographed at N: readings
    on the crop's padding beyond the photo's edge (where the frame cut the object) and on the appendages are
    left out."""
    sil = prepared.photo_silhouette
    if sil is None or not sil.any():
        return None
    assert prepared.photo_scene is not None  # Prepared sets it
    w, h = prepared.photo_size
    measurable = ~outside_mask(prepared.crop, (h, w), prepared.side)
    if prepared.appendages is not None:
        measurable &= ~prepared.appendages
    return outline_support(prepared.photo_scene, sil, measurable)


def scores(prepared: Prepared, drawing: InputDrawing) -> dict:
    """The numbers of the quality record.

    Args:
        prepared: the input, with its located silhouette (core) and appendages at the output side N.
        drawing: the de-rendered object drawn in the input view at N.
    """
    assert prepared.photo_image is not None  # Prepared sets it
    return {**fit_scores(prepared.photo_image, prepared.photo_silhouette, prepared.appendages, drawing.solid,
                         drawing.recon, drawing.mouth, drawing.highlight),
            "outline_support": _round(support(prepared)),
            "cut_edges": list(prepared.cut_edges),
            "frame_coverage": _round(prepared.frame_coverage),
            "neighbour_cut": prepared.neighbour_cut,
            "base_off_axis": _round(prepared.base_off_axis),
            "painted_fill": _round(prepared.painted_fill),
            "greyscale": prepared.greyscale,
            "above_rim": None if prepared.above_rim is None else _round(prepared.above_rim[0]),
            "above_rim_rise": None if prepared.above_rim is None else _round(prepared.above_rim[1]),
            "above_rim_mirrored": None if prepared.above_rim is None else _round(prepared.above_rim[2])}


def fit_scores(photo: np.ndarray, sil: np.ndarray | None, app: np.ndarray | None, rendered: np.ndarray,
               recon: np.ndarray, mouth: np.ndarray | None = None, highlight: np.ndarray | None = None) -> dict:
    """The scores that compare the silhouette, the solid and the reconstruction (all N x N, as written in an
    object's folder: input.png, silhouette.png, appendages.png, the solid's mask, recon.png,
    specular_rendered.png).

    Args:
        photo: N x N x 3 uint8 input. sil: N x N bool core or None. app: N x N bool appendages or None.
        rendered: N x N bool solid. recon: N x N x 3 uint8. mouth: N x N bool drawn inside of the mouth, or None.
        highlight: N x N uint8, the drawn highlight alone (None: white spots read from the recon alone).
    """
    region = sil if sil is not None else rendered
    whole = None if sil is None else (sil if app is None else sil | app)
    mouth = np.zeros_like(rendered) if mouth is None else mouth
    profile = shading_profile(photo, region, rendered)
    base = None if sil is None else stem_base(sil)
    return {
        "silhouette_iou": None if sil is None else _round(iou(rendered, sil)),
        "symmetry": None if sil is None else _round(sor_score(sil)),
        "object_symmetry": None if whole is None else _round(sor_score(whole)),
        "outline_residual": None if sil is None else _round(outline_residual(sil, rendered)),
        "foot_asymmetry": None if whole is None else _round(foot_asymmetry(whole, rendered)),
        "foot_aside": None if app is None or whole is None else _round(foot_aside(app, whole, rendered)),
        "edge_roughness": None if whole is None else _round(edge_roughness(whole, rendered), 5),
        "top_dome": None if sil is None else _round(top_dome(sil)),
        "base_width": None if base is None else _round(base[0]),
        "base_spread": None if base is None else _round(base[1]),
        "roundness": None if whole is None else _round(roundness(whole)),
        "recon_psnr": _round(psnr(recon[region], photo[region]), 2) if region.any() else None,
        "mouth_error": _round(mouth_error(photo, recon, region & rendered, mouth)),
        "mouth_support": _round(mouth_support(photo, region & rendered, mouth)),
        "highlight_excess": _round(highlight_excess(photo, recon, region & rendered)),
        "glaring_highlights": _round(glaring_highlights(photo, recon, region & rendered, highlight)),
        "colour_shift": _round(colour_shift(photo, recon, region & rendered), 2),
        "face": None if whole is None else _round(face_score(photo, whole), 3),
        "shading_range": _round(shading_range(profile)),
        "rim_contrast": _round(rim_contrast(profile)),
        "appendage_fraction": (None if app is None or whole is None or not whole.any()
                               else _round(float(app.sum()) / whole.sum())),
        "silhouette_area": None if sil is None else _round(float(sil.mean())),
    }


def frame_cut(edges: list[str] | tuple[str, ...], limits: QualityLimits = QualityLimits()) -> str | None:
    """Why the photo's frame keeps the object from being seen whole, from the edges that cut it (three or more,
    the top, or both sides), or None."""
    if len(edges) >= limits.review_cut_edges:
        return f"cut by {len(edges)} photo edges"
    if limits.review_cut_top and "top" in edges:
        return "the photo's frame cuts off the object's top: its rim, and whatever stands on it, is not seen"
    if limits.review_cut_sides and {"left", "right"} <= set(edges):
        return "the photo's frame cuts off both sides of the object: its full width is not seen"
    return None


def into_the_mouth(photo: np.ndarray, region: np.ndarray, solid: np.ndarray,
                   limits: QualityLimits = QualityLimits()) -> bool:
    """Whether a photo looks from above into the mouth, as the `roundness` reason reads it: the silhouette round
    and a lit rim round a dark inside (photo N x N x 3 uint8, region its N x N bool silhouette, solid the fitted
    solid's)."""
    return (roundness(region) >= limits.review_roundness
            and (rim_contrast(shading_profile(photo, region, solid)) or 0.0) >= limits.review_rim)


def judge(record: dict, limits: QualityLimits = QualityLimits()) -> tuple[str, list[str]]:
    """(status, reasons) of a quality record's scores: `failed` if any failing reason, else `review` if any
    reason, else `ok`."""
    failed, review = [], []
    cov, sil_iou = record.get("frame_coverage"), record.get("silhouette_iou")
    area, sym = record.get("silhouette_area"), record.get("symmetry")
    app, rec_psnr = record.get("appendage_fraction"), record.get("recon_psnr")
    outline = record.get("outline_support")
    if cov is not None and cov >= limits.fail_coverage:
        failed.append(f"silhouette covers {cov:.0%} of the photo")
    if area is not None and area < limits.min_area:
        failed.append(f"silhouette only {area:.1%} of the crop")
    if sil_iou is None:
        review.append("no silhouette located (--crop none)")
    elif sil_iou < limits.fail_iou:
        failed.append(f"solid does not fit the silhouette (IoU {sil_iou:.2f})")
    elif sil_iou < limits.review_iou:
        review.append(f"solid fits the silhouette loosely (IoU {sil_iou:.2f})")
    if sym is not None and sym < limits.review_symmetry:
        review.append(f"not symmetric enough for a solid of revolution ({sym:.2f})")
    if app is not None and app > limits.review_appendage:
        review.append(f"{app:.0%} of the object left out as appendage")
    if rec_psnr is not None and rec_psnr < limits.review_psnr:
        review.append(f"reconstruction far from the photo ({rec_psnr:.1f} dB)")
    if outline is not None and outline < limits.review_support:
        review.append(f"silhouette off the object's edge ({outline:.0%} of its outline on an edge)")
    review += likeness_reasons(record, limits)
    cut = frame_cut(record.get("cut_edges", []), limits)
    review += [cut] if cut else []
    review += locating_reasons(record, limits)
    if record.get("catalogue_kind"):
        review.append(f"the catalogue calls it '{record.get('catalogue')}': {record['catalogue_kind']}, not one "
                      "whole turned vessel")
    if failed:
        return "failed", failed + review
    return ("review", review) if review else ("ok", [])


def likeness_reasons(record: dict, limits: QualityLimits = QualityLimits()) -> list[str]:
    """The reasons, in a curator's words, that the photo shows something other than one whole vessel seen
    from the side, or that the reconstruction does not look like the photo."""
    checks = (
        ("object_symmetry", lambda v: v < limits.review_object_symmetry,
         "the object as photographed is not symmetric about an axis ({:.2f}): a fragment, a lid or figure that "
         "is not turned, or a neighbour in the silhouette?"),
        ("outline_residual", lambda v: v > limits.review_residual,
         "the solid's outline is off the silhouette by {:.1%} of the height: a broken edge or a sherd?"),
        ("foot_asymmetry", lambda v: v > limits.review_foot,
         "the lower outline is uneven, not a foot's level arc ({:.1%} of the height off its mirror image): a "
         "broken edge or a sherd?"),
        ("foot_aside", lambda v: v > limits.review_foot_aside,
         "one side of the foot stands beside the solid ({:.2f} of its foot): the other side is lost in the photo "
         "(chipped, restored, or as pale as the backdrop), so the foot is drawn too narrow"),
        ("edge_roughness", lambda v: v > limits.review_roughness,
         "the lower outline is jagged ({:.2%} of the height off its smooth course), not a foot's arc: a break?"),
        ("top_dome", lambda v: v > limits.review_dome,
         "the top closes in a dome above a neck ({:.2f} of its width deep), not an open mouth: a head, a stopper "
         "or a lid's knob - is it turned?"),
        ("base_width", lambda v: v < limits.review_base_width and (
            record.get("base_spread") or 0) < limits.review_base_spread,
         "the object ends below in a narrow stem ({:.2f} of its width) that does not spread into a foot: broken "
         "off, or a toe made for a stand?"),
        ("views_outline", lambda v: v > limits.review_views_outline,
         "one of its photos lies {:.1%} of its height off the solid fitted to them all: are they all side views "
         "of one object?"),
        ("above_rim", lambda v: v > limits.review_above_rim or (v > limits.review_above_rim_rise[0] and (
            record.get("above_rim_rise") or 0) > limits.review_above_rim_rise[1]) or (
            v > limits.review_above_rim_aside[0] and record.get("above_rim_mirrored") is not None
            and record["above_rim_mirrored"] < limits.review_above_rim_aside[1]),
         "something stands on the rim and is left out of the solid ({:.2f} of the vessel's size): a lid, a "
         "stopper, a figure or flowers?"),
        ("roundness", lambda v: v >= limits.review_roundness and (record.get("rim_contrast") or 0) >= limits.review_rim,
         "the silhouette is round ({:.2f}), a lit rim round a dark inside: a view from above into the mouth, "
         "not a side view?"),
        ("shading_range", lambda v: v < limits.review_shading,
         "no shading across the object ({:.2f}): a flat piece, not a vessel?"),
        ("mouth_error", lambda v: v > limits.review_mouth and not (record.get("mouth_support") or 0.0)
            >= limits.lip_support,
         "the reconstruction draws the inside of the mouth where the photo shows something else ({:.2f})"),
        ("highlight_excess", lambda v: v > limits.review_highlights,
         "the reconstruction has highlights the photo does not have ({:.0%} of the object)"),
        ("glaring_highlights", lambda v: v > limits.review_glare,
         "white highlights the photo does not have ({:.1%} of the object drawn far brighter): the albedo may "
         "hold dark blotches where they were taken out"),
        ("colour_shift", lambda v: v > limits.review_colour,
         "the reconstruction's colour is off the photo's ({:.0f})"),
        ("face", lambda v: v > limits.review_face,
         "a face looks out of the object (detector score {:.2f}): a head vase, a figure or a lid shaped as a head, "
         "which the solid turns into a smooth body?"),
    )
    return [words.format(record[key]) for key, bad, words in checks if record.get(key) is not None and bad(record[key])]


def locating_reasons(record: dict, limits: QualityLimits = QualityLimits()) -> list[str]:
    """Review reasons about what the locator had to decide: a neighbouring object was cut away from the located
    object (the cut may run through the vessel), or one was probably kept with it; painting as grey as the
    backdrop was taken for the vessel, or a greyscale photo's outline may follow such painting."""
    reasons = []
    if record.get("neighbour_cut"):
        reasons.append("a neighbouring object was cut away from it: check the outline where they touched")
    off = record.get("base_off_axis")
    if off is not None and off > limits.review_base_off_axis:
        reasons.append(f"another object probably merged into it ({off:.0%} of its lower part off the vessel's axis)")
    painted = record.get("painted_fill")
    if painted is not None and painted >= limits.review_painted_fill:
        reasons.append(f"on this greyscale photo {painted:.0%} of the object is painting as grey as the backdrop, "
                       "taken for the vessel: check the outline")
    symmetry = record.get("object_symmetry")
    if (record.get("greyscale") and symmetry is not None
            and limits.review_object_symmetry <= symmetry < limits.review_greyscale_symmetry):
        reasons.append(f"on this greyscale photo the object as located is not quite symmetric about an axis "
                       f"({symmetry:.2f}): its outline may follow painting as grey as the backdrop")
    return reasons


def assess(prepared: Prepared, state: ObjectState, limits: QualityLimits = QualityLimits()) -> dict:
    """The `quality` record of one de-rendered object, drawing it in the input view first (export_object has
    that view already and calls assess_drawn).

    Args:
        prepared: the input crop and its located silhouette.
        state: the final de-rendered object (whatever prediction or refinement produced it).
        limits: the thresholds.
    """
    view = ViewRenderer(state, prepared.side)
    shading = view.shading()
    return assess_drawn(prepared, input_drawing(view, shading, view.draw(shading)), limits)


def assess_drawn(prepared: Prepared, drawing: InputDrawing, limits: QualityLimits = QualityLimits(),
                 description: str = "", more: dict | None = None) -> dict:
    """The `quality` record from the object drawn in the input view: its scores, status and reasons.

    Args:
        prepared: the input crop and its located silhouette.
        drawing: the final de-rendered object drawn in the input view.
        limits: the thresholds.
        description: the object's catalogue description ('' unknown): `catalogue_kind` where it names something
            other than one whole turned vessel (catalogue_terms.not_a_whole_vessel).
        more: scores from beyond the input view, judged with its own (`views_outline`).
    """
    record = {**scores(prepared, drawing), **(more or {})}
    kind = not_a_whole_vessel(description) if description else None
    if kind is not None:
        record.update(catalogue=description, catalogue_kind=kind)
    status, reasons = judge(record, limits)
    return {"status": status, "reasons": reasons, **record}
