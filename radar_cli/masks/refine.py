"""GrabCut refinement of a rough object mask at crop resolution, then clean-up: holes, main part, smooth edge."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.detect import fill_holes, main_component

INNER_BAND = 0.05  # probable-foreground band inside the rough mask, as a fraction of the object's size
OUTER_BAND = 0.08  # probable-background band outside it
MAX_HOLE_FRAC = 0.01  # holes up to this fraction of the object are noise and get filled; larger ones are real
GRABCUT_SIDE = 192  # GrabCut runs at most at this side (its cost dominates); edges are snapped at full size
MIN_AGREEMENT = 0.6  # GrabCut results this unlike the rough mask (IoU) are distrusted


def iou(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two bool masks (1.0 if both are empty)."""
    union = np.logical_or(a, b).sum()
    return float(np.logical_and(a, b).sum() / union) if union else 1.0


def _disk(radius: int) -> np.ndarray:
    d = 2 * max(1, radius) + 1
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (d, d))


def trimap(rough: np.ndarray, sure: np.ndarray | None = None, outside: np.ndarray | None = None) -> np.ndarray:
    """GrabCut's 4-level mask from a rough bool mask: definite foreground deep inside (and only where `sure`,
    if given), probable foreground and probable background in bands either side of the outline, definite
    background beyond and in `outside` (padding beyond the photo's edge)."""
    m = rough.astype(np.uint8)
    size = np.sqrt(max(int(m.sum()), 1))
    grown = m if outside is None else (rough | outside).astype(np.uint8)  # the frame's edge is no outline
    inner = (cv2.erode(grown, _disk(round(INNER_BAND * size))) > 0) & rough
    if sure is not None:
        inner &= cv2.erode(sure.astype(np.uint8), _disk(1)) > 0
    outer = cv2.dilate(m, _disk(round(OUTER_BAND * size))) > 0
    tri = np.full(m.shape, cv2.GC_BGD, np.uint8)
    tri[outer] = cv2.GC_PR_BGD
    tri[rough] = cv2.GC_PR_FGD
    tri[inner] = cv2.GC_FGD
    if outside is not None:
        tri[outside] = cv2.GC_BGD
    return tri


def row_extents(mask: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Leftmost and rightmost object column (R int each) of each of `rows` (R) of a bool mask; each row must hold
    object pixels."""
    cols = np.arange(mask.shape[1])
    inside = mask[rows]
    return np.where(inside, cols, mask.shape[1]).min(1), np.where(inside, cols, -1).max(1)


def smooth_boundary(mask: np.ndarray, sigma: float) -> np.ndarray:
    """Blur the 0/1 mask and cut at 0.5: removes pixel staircases and one-pixel spurs, keeps the shape."""
    if sigma <= 0:
        return mask
    return cv2.GaussianBlur(mask.astype(np.float32), (0, 0), sigma) > 0.5


def clean(mask: np.ndarray, sigma: float, outside: np.ndarray | None = None) -> np.ndarray:
    """Fill small holes, keep the main component, smooth the outline (not along `outside`, the padding beyond
    the photo's edge: an object cut by the frame keeps its straight cut)."""
    m = main_component(fill_holes(mask, MAX_HOLE_FRAC))
    if outside is None:
        return main_component(smooth_boundary(m, sigma))
    return main_component(smooth_boundary(m | outside, sigma) & ~outside)


def snap_edges(image: np.ndarray, mask: np.ndarray, band: int = 2, sigma: float = 3.0) -> np.ndarray:
    """Decide the outline pixels by their coverage: GrabCut keeps mixed pixels whole, which puts the outline
    about a pixel outside the true edge. A pixel within `band` px of the outline gets alpha from projecting its
    colour between the local foreground and background means; it is object if alpha > 0.5.

    Args:
        image: S x S x 3 uint8. mask: S x S bool.
    """
    m = mask.astype(np.uint8)
    k = _disk(band)
    inner = cv2.erode(m, k).astype(np.float32)
    outer = (1 - cv2.dilate(m, k)).astype(np.float32)
    ring = (cv2.dilate(m, k) > 0) & ~(inner > 0)
    img = image.astype(np.float32)

    def local_mean(weight: np.ndarray) -> np.ndarray:
        w = cv2.GaussianBlur(weight, (0, 0), sigma)
        return cv2.GaussianBlur(img * weight[..., None], (0, 0), sigma) / np.maximum(w, 1e-3)[..., None]

    fg, bg = local_mean(inner), local_mean(outer)
    span = fg - bg
    alpha = ((img - bg) * span).sum(2) / np.maximum((span * span).sum(2), 1e-3)
    contrast = np.sqrt((span * span).sum(2)) > 12.0  # where fg and bg look alike, keep GrabCut's answer
    out = mask.copy()
    decide = ring & contrast
    out[decide] = alpha[decide] > 0.5
    return out


def refine(image: np.ndarray, rough: np.ndarray, iterations: int = 4, sure: np.ndarray | None = None,
           outside: np.ndarray | None = None) -> tuple[np.ndarray, bool]:
    """Refine a rough mask with GrabCut.

    Args:
        image: S x S x 3 uint8 RGB crop.
        rough: S x S bool rough mask (from the detector, warped into the crop).
        sure: S x S bool, where the detector saw the object itself (not a filled hole); None = everywhere.
        outside: S x S bool, the padding beyond the photo's edge: never object (an object cut by the frame
            ends there); None = none.
        iterations: GrabCut iterations.

    Returns:
        (mask S x S bool, used_grabcut): the cleaned mask; False if GrabCut failed or disagreed with the
        rough mask so much that the rough mask was kept (still cleaned).
    """
    if outside is not None:
        rough = rough & ~outside
    mask, used = _refine(image, rough, iterations, sure, outside)
    return (mask & ~outside if outside is not None else mask), used


def _refine(image: np.ndarray, rough: np.ndarray, iterations: int, sure: np.ndarray | None,
            outside: np.ndarray | None) -> tuple[np.ndarray, bool]:
    """`refine` inside the photo (the caller clips the result to it)."""
    sigma = max(0.6, image.shape[0] / 256.0)
    if rough.sum() < 16:
        return clean(rough, sigma), False
    side = image.shape[0]
    small = min(1.0, GRABCUT_SIDE / side)
    gc_img = cv2.resize(image, None, fx=small, fy=small, interpolation=cv2.INTER_AREA) if small < 1 else image
    gc_rough = cv2.resize(rough.astype(np.uint8), gc_img.shape[1::-1], interpolation=cv2.INTER_NEAREST) > 0
    gc_sure = None if sure is None else cv2.resize(sure.astype(np.uint8), gc_img.shape[1::-1],
                                                  interpolation=cv2.INTER_NEAREST) > 0
    gc_outside = None if outside is None else cv2.resize(outside.astype(np.uint8), gc_img.shape[1::-1],
                                                         interpolation=cv2.INTER_NEAREST) > 0
    tri = trimap(gc_rough, gc_sure, gc_outside)
    if not (tri == cv2.GC_FGD).any() or not (tri == cv2.GC_BGD).any():
        return clean(rough, sigma), False
    bgd, fgd = np.zeros((1, 65), np.float64), np.zeros((1, 65), np.float64)
    cv2.setRNGSeed(0)  # GrabCut's k-means draws from a per-thread generator: the same cut in any thread
    try:
        # OpenCV's stubs want a rectangle; None is what GC_INIT_WITH_MASK takes
        cv2.grabCut(np.ascontiguousarray(gc_img), tri, None, bgd, fgd, iterations,  # type: ignore[call-overload]
                    cv2.GC_INIT_WITH_MASK)
    except cv2.error:
        return clean(rough, sigma), False
    cut = ((tri == cv2.GC_FGD) | (tri == cv2.GC_PR_FGD)).astype(np.float32)
    cut = cv2.resize(cut, (side, side), interpolation=cv2.INTER_LINEAR) > 0.5
    if outside is None:
        cut = snap_edges(image, cut, band=max(2, round(1.5 / small)))
    else:
        cut = snap_edges(image, cut | outside, band=max(2, round(1.5 / small))) & ~outside
    refined = clean(cut, sigma, outside)
    if iou(refined, rough) < MIN_AGREEMENT:
        return clean(rough, sigma), False
    return refined, True
