"""Quality scores of a crop's silhouette and the thresholds that accept or reject it.

The solid-of-revolution score replaces the paper's manual filtering: a solid of revolution seen from the side
(pitch 0..20 deg, small roll) has a silhouette that is its own mirror image about the projected axis, and each
row of it is one interval centred on that axis. Spouts and figurines break the mirror; handles leave gaps that a
per-row half-width profile cannot explain.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

SCORE_SIDE = 96  # scores are computed on the mask resized to this side: fast and resolution-independent
TILTS_DEG = (-12.0, -8.0, -4.0, 0.0, 4.0, 8.0, 12.0)  # axis tilts searched (the network's roll is +-10 deg)


@dataclass(frozen=True)
class Thresholds:
    """Acceptance limits of a crop (a crop failing any one is rejected with that reason)."""

    min_area: float = 0.08
    """Smallest mask area as a fraction of the crop."""
    max_area: float = 0.85
    """Largest mask area: beyond it the 'object' is probably the backdrop."""
    min_solidity: float = 0.6
    """Mask area over its convex hull's area."""
    min_symmetry: float = 0.8
    """Solid-of-revolution score (see `sor_score`)."""
    allow_border: bool = False
    """Accept objects cut off by the photo's edge."""


def solidity(mask: np.ndarray) -> float:
    """Area of a bool mask over the area of its convex hull (0 for an empty mask)."""
    pts = cv2.findNonZero(mask.astype(np.uint8))
    if pts is None:
        return 0.0
    hull = cv2.convexHull(pts)
    hull_area = cv2.contourArea(hull) + 0.5 * cv2.arcLength(hull, True) + 1.0  # pixel areas, not polygon
    return float(min(1.0, mask.sum() / hull_area))


def touches(mask: np.ndarray, region: tuple[int, int, int, int]) -> bool:
    """True if the mask reaches the edge of `region` (u0, v0, u1, v1) where that edge is the photo's edge."""
    u0, v0, u1, v1 = region
    if u1 <= u0 or v1 <= v0:
        return bool(mask.any())
    inner = mask[v0:v1, u0:u1]
    return bool(inner[0].any() or inner[-1].any() or inner[:, 0].any() or inner[:, -1].any())


def _rotate(mask: np.ndarray, deg: float) -> np.ndarray:
    if deg == 0:
        return mask
    h, w = mask.shape
    ys, xs = np.nonzero(mask)
    centre = (float(xs.mean()), float(ys.mean()))
    rot = cv2.getRotationMatrix2D(centre, deg, 1.0)
    return cv2.warpAffine(mask.astype(np.uint8), rot, (w, h), flags=cv2.INTER_NEAREST) > 0


def mirror_agreement(mask: np.ndarray) -> tuple[float, float]:
    """Best IoU of a bool mask with its mirror image about a vertical axis (searched at half-pixel steps).

    Returns:
        (iou, axis x in pixels).
    """
    area = int(mask.sum())
    if area == 0:
        return 0.0, 0.0
    w = mask.shape[1]
    cols = mask.sum(0).astype(np.float64)
    centre = float((cols * np.arange(w)).sum() / area)
    flipped = mask[:, ::-1]
    best, best_axis = 0.0, centre
    # mirror about x = a maps x to 2a - x; flipped[x] = mask[w-1-x], so shift k = round(2a - (w - 1))
    k0 = int(round(2 * centre - (w - 1)))
    for k in range(k0 - 4, k0 + 5):
        shifted = np.zeros_like(mask)
        if k >= 0:
            shifted[:, k:] = flipped[:, : w - k]
        else:
            shifted[:, :k] = flipped[:, -k:]
        inter = np.logical_and(mask, shifted).sum()
        score = inter / (2 * area - inter)
        if score > best:
            best, best_axis = float(score), (k + w - 1) / 2.0
    return best, best_axis


def mirror_iou(mask: np.ndarray, axis: float) -> float:
    """IoU of an n x n bool mask with its mirror image about the given column `axis` (not searched, as
    `mirror_agreement` does: whether a part is symmetric about the vessel's own axis); what the mirror image
    throws past the frame counts as missing."""
    cols = np.arange(mask.shape[1])
    source = np.round(2 * axis - cols).astype(int)
    inside = (source >= 0) & (source < mask.shape[1])
    mirrored = np.zeros_like(mask)
    mirrored[:, inside] = mask[:, source[inside]]
    return float((mask & mirrored).sum() / max(1, (mask | mirrored).sum()))


def profile_agreement(mask: np.ndarray, axis: float) -> float:
    """IoU of a bool mask with the solid it implies: each row filled symmetrically about `axis` out to the row's
    mean extent. Gaps within a row (handles) and lopsided rows lower it."""
    xs = np.arange(mask.shape[1])
    rows = np.nonzero(mask.any(1))[0]
    implied = np.zeros_like(mask)
    for y in rows:
        cols = xs[mask[y]]
        half = 0.5 * ((axis - cols.min()) + (cols.max() - axis))
        implied[y] = np.abs(xs - axis) <= max(half, 0.5)
    inter = np.logical_and(mask, implied).sum()
    union = np.logical_or(mask, implied).sum()
    return float(inter / union) if union else 0.0


def sor_score(mask: np.ndarray) -> float:
    """Solid-of-revolution score in [0, 1]: the product of mirror and profile agreement about the best
    vertical axis, the best over small axis tilts."""
    m = cv2.resize(mask.astype(np.uint8), (SCORE_SIDE, SCORE_SIDE), interpolation=cv2.INTER_AREA) > 0
    if m.sum() < 10:
        return 0.0
    best = 0.0
    for deg in TILTS_DEG:
        r = _rotate(m, deg)
        mirror, axis = mirror_agreement(r)
        if mirror <= best:
            continue
        best = max(best, mirror * profile_agreement(r, axis))
    return best


def _ends(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row of a bool mask its first and last column (NaN on empty rows)."""
    filled = mask.any(1)
    first = np.where(filled, mask.argmax(1), np.nan)
    last = np.where(filled, mask.shape[1] - 1 - mask[:, ::-1].argmax(1), np.nan)
    return first, last


def outline_residual(silhouette: np.ndarray, solid: np.ndarray) -> float | None:
    """How far a fitted solid's outline departs from a silhouette's, as a share of the silhouette's height:
    the mean distance of their row ends (left and right, per row) and column ends (top and bottom, per
    column), over the lines both cross. A solid of revolution follows a vessel's outline to a pixel or two; a
    broken edge, a sherd's outline or a lid that is not turned leaves it off by several percent of the height.

    Args:
        silhouette, solid: H x W bool masks in the same view. Returns None if they share no line.
    """
    rows = np.nonzero(silhouette.any(1))[0]
    if rows.size == 0:
        return None
    gaps = []
    for a, b in ((silhouette, solid), (silhouette.T, solid.T)):
        (a0, a1), (b0, b1) = _ends(a), _ends(b)
        both = ~np.isnan(a0) & ~np.isnan(b0)
        gaps += [np.abs(a0 - b0)[both], np.abs(a1 - b1)[both]]
    gap = np.concatenate(gaps)
    return float(gap.mean() / (rows[-1] - rows[0] + 1)) if gap.size else None


def foot_asymmetry(obj: np.ndarray, solid: np.ndarray) -> float | None:
    """How far the object's lower outline is from the mirror image of itself about the fitted solid's axis, as a
    share of the object's height. Per column the object's lowest pixel is taken relative to the solid's; that
    offset, compared with the column's mirror about the axis, averaged over the columns within 90 % of the
    solid's half-width. A vessel stands on a foot whose outline is a level ellipse arc, the same on both sides
    (under 0.025 on the vessels measured, however well the solid follows it); a break, a sherd's edge or a
    jagged lower rim runs off it on one side more than on the other (0.033-0.084 on the broken pieces measured).

    Args:
        obj: H x W bool whole located object (core and appendages). solid: H x W bool fitted solid, same view.
        Returns None if either is empty or they share no mirrored column pair.
    """
    rows, cols = np.nonzero(obj.any(1))[0], np.nonzero(solid.any(0))[0]
    if rows.size == 0 or cols.size < 5:
        return None
    gap = _ends(obj.T)[1] - _ends(solid.T)[1]  # W: the object's bottom end below the solid's (NaN: none)
    axis = (cols[0] + cols[-1]) / 2.0
    d = np.arange(1, int(0.9 * (cols[-1] - cols[0]) / 2.0))
    right, left = gap[np.round(axis + d).astype(int)], gap[np.round(axis - d).astype(int)]
    both = ~np.isnan(right) & ~np.isnan(left)
    if not both.any():
        return None
    return float(np.abs(right - left)[both].mean() / (rows[-1] - rows[0] + 1))


FOOT_BAND = 0.15  # `foot_aside` reads this lowest share of the object's rows
FOOT_PART_ROWS = 0.4  # ... the parts left out of the core that span at least this share of those rows
FOOT_REACH = 0.35  # ... and reach beyond the solid by at most this share of its half-width (median over rows)


def foot_aside(appendages: np.ndarray, whole: np.ndarray, solid: np.ndarray) -> float:
    """How much of the foot stands beside the fitted solid, left out of the symmetric core: of the appendages'
    connected parts that span at least FOOT_PART_ROWS of the object's lowest FOOT_BAND rows and reach out
    beyond the solid by at most FOOT_REACH of its half-width there (the foot's own side continued), the largest
    one's pixels in those rows over the solid's there (0 where there is none, at most 1). Handles sit higher, a
    shadow on the floor is a flat sliver and a card or label beside the foot stands far out; a block beside the
    foot as tall as the foot is its own side, cut off because the other side was lost (a chip, a restoration or
    a pale edge of the backdrop's tone), so the solid's foot is drawn too narrow (0.055-0.066 on the CVA 10 views
    whose foot came out 13-16 % narrow, reaching out 0.18-0.25 of the half-width; labels beside a foot 0.46-0.63).

    Args:
        appendages: H x W bool, the located object's parts left out of its core. whole: H x W bool, the core and
            those parts. solid: H x W bool, the fitted solid in the same view.
    """
    rows = np.nonzero(whole.any(1))[0]
    if rows.size < 2 or not appendages.any():
        return 0.0
    low = int(rows[-1]) - int(FOOT_BAND * (rows[-1] - rows[0] + 1))
    count, labels = cv2.connectedComponents(appendages[low:].astype(np.uint8), connectivity=8)
    first, last = _ends(solid[low:])
    base = max(int(solid[low:].sum()), 1)
    best = 0.0
    for k in range(1, count):
        part = labels == k
        left, right = _ends(part)
        spanned = np.nonzero(~np.isnan(left))[0]
        if spanned[-1] - spanned[0] + 1 < FOOT_PART_ROWS * (rows[-1] - low + 1):
            continue
        reach = np.maximum(np.maximum(right - last, first - left), 0) / np.maximum((last - first + 1) / 2, 1)
        reach = reach[~np.isnan(reach)]
        if reach.size and float(np.median(reach)) <= FOOT_REACH:
            best = max(best, float(part.sum()) / base)
    return min(best, 1.0)


def edge_roughness(obj: np.ndarray, solid: np.ndarray, window: float = 0.08) -> float | None:
    """How jagged the object's lower outline is, as a share of its height: per column (within 90 % of the
    fitted solid's half-width) the object's lowest pixel, its departure from the running median over `window`
    of the solid's width, averaged. A foot's outline is a smooth arc, whatever its shape: its pixel steps
    follow the median (under 0.0005 on the vessels measured); a break drawn along a jagged line departs from
    it at every scale (0.0006-0.0046 on the generated broken vases), even where it runs level or as evenly on
    both sides as a foot (which `foot_asymmetry` reads).

    Args:
        obj: H x W bool whole located object. solid: H x W bool fitted solid, same view.
        Returns None if either is empty or fewer than 10 columns are measured.
    """
    rows, cols = np.nonzero(obj.any(1))[0], np.nonzero(solid.any(0))[0]
    if rows.size == 0 or cols.size < 5:
        return None
    centre, half = (cols[0] + cols[-1]) / 2.0, 0.9 * (cols[-1] - cols[0]) / 2.0
    bottom = _ends(obj.T)[1][int(np.ceil(centre - half)):int(centre + half) + 1]
    bottom = bottom[~np.isnan(bottom)]
    if bottom.size < 10:
        return None
    k = max(3, int(window * (cols[-1] - cols[0])) | 1)  # odd
    runs = np.lib.stride_tricks.sliding_window_view(np.pad(bottom, k // 2, mode="edge"), k)
    return float(np.abs(bottom - np.median(runs, axis=1)).mean() / (rows[-1] - rows[0] + 1))


def _row_widths(core: np.ndarray, min_rows: int = 20) -> np.ndarray | None:
    """Per row of a bool mask, from its top row to its bottom one, the span from its first to its last pixel
    (0 on an empty row); None if under `min_rows` rows."""
    rows = np.nonzero(core.any(1))[0]
    if rows.size < min_rows:
        return None
    first, last = _ends(core[rows[0]:rows[-1] + 1])
    return np.nan_to_num(last - first + 1)


def top_dome(core: np.ndarray, neck: float = 0.8, reach: float = 0.7) -> float | None:
    """How far the object's top is a closed dome above a neck rather than a mouth: for each neck (a row in the
    upper 5-45 % of the object at most `neck` of the widest row above it, with a row at least 1 / `neck` of its
    width below it), the rows from the top down to the first one `reach` of the widest row above the neck,
    over that widest row's width; the largest. An open mouth's rim seen from the side or a little from above
    is an ellipse cut level: about 0.14 sin(pitch), under 0.09 on the vessels measured; a head, a stopper or a
    hemispherical knob rounds over a height like its width: 0.18-0.80 on the generated lids. 0 without a neck.

    Args:
        core: H x W bool symmetric core of the located object (its appendages left out). None if empty.
    """
    width = _row_widths(core)
    if width is None:
        return None
    height = width.size
    widest_above = np.maximum.accumulate(width)
    widest_below = np.maximum.accumulate(width[::-1])[::-1]
    best = 0.0
    for n in range(max(1, int(0.05 * height)), int(0.45 * height)):
        bulb = widest_above[n - 1]
        if width[n] <= neck * bulb and widest_below[n] * neck >= width[n]:
            best = max(best, float(np.argmax(width >= reach * bulb)) / bulb)
    return best


def stem_base(core: np.ndarray, foot: float = 0.1,
              stem: tuple[float, float] = (0.6, 0.9)) -> tuple[float, float] | None:
    """How wide the object ends below, and whether it spreads into a foot there: (the widest row of the lowest
    `foot` of its height over its widest row; that over the narrowest row between `stem` of the height from its
    top). A vessel stands on a foot or a base: its lowest tenth is at least 0.29 of its width on the vessels
    measured (0.455 on the photographed ones), and a narrow foot spreads from the stem above it. A vessel broken
    off across a narrow stem ends in the stem itself: narrow and not spreading (0.16 and 0.20 of the width,
    spreading 0.98-1.00, on the generated broken vases whose `foot_asymmetry` and `edge_roughness` read the
    short break as a foot's).

    Args:
        core: H x W bool symmetric core of the located object. Returns None if under 20 rows.
    """
    width = _row_widths(core)
    if width is None:
        return None
    height = width.size
    base = float(width[int((1.0 - foot) * height):].max())
    narrowest = float(width[int(stem[0] * height):max(int(stem[1] * height), int(stem[0] * height) + 1)].min())
    return base / float(width.max()), base / max(narrowest, 1.0)


def roundness(mask: np.ndarray) -> float:
    """How nearly a bool mask is a filled ellipse (1 = exactly): the IoU of the mask with the ellipse of the
    same second moments. A vessel seen from the side has a rim and a foot that cut its outline straight; a
    view from above into the mouth (or a round dish face on) is an ellipse."""
    m = mask.astype(np.uint8)
    moments = cv2.moments(m, binaryImage=True)
    if moments["m00"] < 10:
        return 0.0
    cx, cy = moments["m10"] / moments["m00"], moments["m01"] / moments["m00"]
    cov = np.array([[moments["mu20"], moments["mu11"]], [moments["mu11"], moments["mu02"]]]) / moments["m00"]
    values, vectors = np.linalg.eigh(cov)
    axes = 2.0 * np.sqrt(np.maximum(values, 1e-9))  # a filled ellipse's semi-axes from its variances
    angle = float(np.degrees(np.arctan2(vectors[1, 1], vectors[0, 1])))
    ellipse = np.zeros_like(m)
    cv2.ellipse(ellipse, (int(round(cx)), int(round(cy))), (int(round(axes[1])), int(round(axes[0]))), angle, 0,
                360, 1, -1)
    inter = np.logical_and(m, ellipse).sum()
    return float(inter / max(np.logical_or(m, ellipse).sum(), 1))


def score_mask(mask: np.ndarray, region: tuple[int, int, int, int] | None = None) -> dict[str, float | bool]:
    """All quality scores of a crop's bool mask; `region` is the part of the crop inside the photo."""
    region = region or (0, 0, mask.shape[1], mask.shape[0])
    return {
        "area": round(float(mask.mean()), 4),
        "touches_border": touches(mask, region),
        "solidity": round(solidity(mask), 4),
        "symmetry": round(sor_score(mask), 4),
    }


def judge(scores: dict, limits: Thresholds) -> list[str]:
    """The reasons a crop is rejected (empty list = accepted)."""
    reasons = []
    if scores["area"] < limits.min_area:
        reasons.append(f"area {scores['area']:.3f} < {limits.min_area}")
    if scores["area"] > limits.max_area:
        reasons.append(f"area {scores['area']:.3f} > {limits.max_area}")
    if scores["touches_border"] and not limits.allow_border:
        reasons.append("border: object touches the photo's edge")
    if scores["solidity"] < limits.min_solidity:
        reasons.append(f"solidity {scores['solidity']:.2f} < {limits.min_solidity}")
    if scores["symmetry"] < limits.min_symmetry:
        reasons.append(f"symmetry {scores['symmetry']:.2f} < {limits.min_symmetry}")
    return reasons
