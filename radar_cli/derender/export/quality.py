"""Which de-rendered objects to trust: scores of one object's result and its status (`ok`, `review`,
`failed`) with the reasons, for material.json's `quality` record and summary.csv."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from radar_cli.derender.export.renders import ViewRenderer
from radar_cli.derender.run.inputs import Prepared
from radar_cli.derender.run.state import ObjectState
from radar_cli.masks.crop import outside_mask
from radar_cli.masks.outline import outline_support
from radar_cli.masks.quality import sor_score
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


def scores(prepared: Prepared, rendered: np.ndarray, recon: np.ndarray) -> dict:
    """The numbers of the quality record.

    Args:
        prepared: the input, with its located silhouette (core) and appendages at the output side N.
        rendered: N x N bool silhouette of the de-rendered solid in the input view.
        recon: N x N x 3 uint8 reconstruction of the input (over white).
    """
    sil = prepared.photo_silhouette
    assert prepared.photo_image is not None  # Prepared sets it
    region = sil if sil is not None else rendered
    app = prepared.appendages
    whole = None if sil is None else int(sil.sum()) + (0 if app is None else int(app.sum()))
    return {
        "silhouette_iou": None if sil is None else _round(iou(rendered, sil)),
        "symmetry": None if sil is None else _round(sor_score(sil)),
        "recon_psnr": _round(psnr(recon[region], prepared.photo_image[region]), 2) if region.any() else None,
        "appendage_fraction": None if app is None or not whole else _round(float(app.sum()) / whole),
        "outline_support": _round(support(prepared)),
        "cut_edges": list(prepared.cut_edges),
        "frame_coverage": _round(prepared.frame_coverage),
        "silhouette_area": None if sil is None else _round(float(sil.mean())),
    }


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
    if len(record.get("cut_edges", [])) >= limits.review_cut_edges:
        review.append(f"cut by {len(record['cut_edges'])} photo edges")
    if failed:
        return "failed", failed + review
    return ("review", review) if review else ("ok", [])


def assess(prepared: Prepared, state: ObjectState, limits: QualityLimits = QualityLimits()) -> dict:
    """The `quality` record of one de-rendered object, drawing it in the input view first (export_object has
    that view already and calls assess_drawn).

    Args:
        prepared: the input crop and its located silhouette.
        state: the final de-rendered object (whatever prediction or refinement produced it).
        limits: the thresholds.
    """
    view = ViewRenderer(state, prepared.side)
    return assess_drawn(prepared, view.hits.mask[0].numpy(), view.draw(view.shading()), limits)


def assess_drawn(prepared: Prepared, rendered: np.ndarray, recon: np.ndarray,
                 limits: QualityLimits = QualityLimits()) -> dict:
    """The `quality` record from the object drawn in the input view: its scores, status and reasons.

    Args:
        prepared: the input crop and its located silhouette.
        rendered: N x N bool silhouette of the final de-rendered solid; recon: N x N x 3 uint8 over white.
        limits: the thresholds.
    """
    record = scores(prepared, rendered, recon)
    status, reasons = judge(record, limits)
    return {"status": status, "reasons": reasons, **record}
