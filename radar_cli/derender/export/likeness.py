"""Does the reconstruction look like the photograph? Scores of recon.png against the photo inside the located
silhouette, each aimed at one way a de-rendering goes wrong on real photographs: a mouth drawn where the photo
shows the outer wall (a pitch too high, a flat object rebuilt as an open vessel), highlights the photo does not
have, a colour shift."""

from __future__ import annotations

import cv2
import numpy as np

from radar_cli.masks.outline import CONTRAST, MIN_OUTLINE, edge_contrast

BRIGHTER = 0.15
"""A recon pixel this much brighter than the photo's (luminance, 0..1) is a highlight the photo does not have."""
GLARING = 0.3
"""... and this much brighter, a white spot on the paint: on black glaze a highlight the photo shows at most as a
grey sheen (the lighting fit's lobe drawn where one paint varies, and divided out of the albedo as a dark
blotch that every relit view repeats)."""
LIMB = 0.025
"""White spots are not counted this close to the outline (share of the object's width): the drawn and the
photographed outline part there by a pixel or two, and a glaze reflects the studio most at its limbs."""
MIN_MOUTH_SHARE = 0.08
"""A drawn mouth covering less of the silhouette than this is not scored (a narrow neck's mouth, a sliver at a
level pitch)."""
LUMA = np.array([0.299, 0.587, 0.114])


def luminance(image: np.ndarray) -> np.ndarray:
    """H x W luminance in 0..1 of an H x W x 3 uint8 image."""
    return (image.astype(np.float64) / 255.0) @ LUMA


def mouth_error(photo: np.ndarray, recon: np.ndarray, region: np.ndarray, mouth: np.ndarray) -> float | None:
    """Mean absolute luminance difference (0..1) between the reconstruction and the photo where the
    reconstruction shows the inside of the vessel through its mouth; None where the drawn mouth covers less
    than MIN_MOUTH_SHARE of the region.

    Args:
        photo, recon: H x W x 3 uint8. region: H x W bool (the silhouette). mouth: H x W bool, the pixels where
            the solid's inside is seen (raycast `Hits.inner`).
    """
    inside = _scored_mouth(region, mouth)
    return None if inside is None else float(np.abs(luminance(recon)[inside] - luminance(photo)[inside]).mean())


def _scored_mouth(region: np.ndarray, mouth: np.ndarray) -> np.ndarray | None:
    """The drawn mouth within the region (H x W bool), or None where it covers less than MIN_MOUTH_SHARE of it."""
    inside = region & mouth
    return inside if region.any() and inside.sum() >= MIN_MOUTH_SHARE * region.sum() else None


def mouth_support(photo: np.ndarray, region: np.ndarray, mouth: np.ndarray) -> float | None:
    """Share of the drawn mouth's outline inside the region where the photo shows an edge (the colour across it,
    read within the region, differing by over masks.outline.CONTRAST): an open mouth the photo shows has its lip
    there, all round (0.99-1.0 on the generated vases seen into their mouths and a Met jar seen from 15 deg above,
    whose insides the photos show lit), where a mouth drawn over the outer wall of a vessel photographed level
    crosses its painting in part (0.16-0.83 on five CVA 10 views drawn at 15-20 deg). None where the drawn mouth
    covers less than MIN_MOUTH_SHARE of the region.

    Args:
        photo: H x W x 3 uint8. region: H x W bool (the silhouette). mouth: H x W bool, the drawn inside.
    """
    inside = _scored_mouth(region, mouth)
    if inside is None:
        return None
    diff = edge_contrast(photo, inside, region)
    return float((diff > CONTRAST).mean()) if len(diff) >= MIN_OUTLINE else None


def highlight_excess(photo: np.ndarray, recon: np.ndarray, region: np.ndarray) -> float | None:
    """Share of the region where the reconstruction is BRIGHTER than the photo: highlights the fitted lighting
    draws and the photo does not show (None for an empty region)."""
    if not region.any():
        return None
    return float(((luminance(recon) - luminance(photo))[region] > BRIGHTER).mean())


def glaring_highlights(photo: np.ndarray, recon: np.ndarray, region: np.ndarray,
                       highlight: np.ndarray | None = None) -> float | None:
    """Share of the region where the reconstruction is GLARING brighter than the photo, further than LIMB of the
    region's width inside its outline, and (given the drawn highlight alone, H x W uint8 as specular_rendered.png,
    or H x W x 3) where that highlight is GLARING bright itself: white spots the photo does not have, not paint
    drawn a little off its place (None for an empty region)."""
    if not region.any():
        return None
    reach = max(1, round(LIMB * int(region.any(0).sum())))
    inner = cv2.erode(region.astype(np.uint8), np.ones((2 * reach + 1, 2 * reach + 1), np.uint8)) > 0
    spots = (luminance(recon) - luminance(photo) > GLARING) & inner
    if highlight is not None:
        spots &= (luminance(highlight) if highlight.ndim == 3 else highlight / 255.0) > GLARING
    return float(spots.sum() / region.sum())


def colour_shift(photo: np.ndarray, recon: np.ndarray, region: np.ndarray) -> float | None:
    """Distance of the chroma (CIELAB a*, b*) of the reconstruction's mean colour inside the region from the
    photo's: about 2 is invisible, above 10 the reconstruction is another colour (None for an empty region)."""
    if not region.any():
        return None
    means = np.stack([im[region].astype(np.float32).mean(0) / 255.0 for im in (photo, recon)])[None]  # 1 x 2 x 3
    lab = cv2.cvtColor(means, cv2.COLOR_RGB2LAB)[0]
    return float(np.linalg.norm(lab[0, 1:] - lab[1, 1:]))


def _row_ends(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row of a bool mask its first and last column (-1 on empty rows)."""
    filled = mask.any(1)
    return (np.where(filled, mask.argmax(1), -1),
            np.where(filled, mask.shape[1] - 1 - mask[:, ::-1].argmax(1), -1))


def shading_range(profile: np.ndarray | None) -> float | None:
    """How much the photo's brightness changes across the object: the range (max - min) of its `shading_profile`.
    Paint changes from row to row and averages out; a curved wall is darker or brighter towards its edges (0.17
    to 4 on the vessels measured), a flat piece is not (under 0.05 on a painted slab)."""
    return None if profile is None else float(profile.max() - profile.min())


def rim_contrast(profile: np.ndarray | None) -> float | None:
    """The outer strips of the `shading_profile` over its darkest middle strip: a view from above into the mouth
    is a lit rim round a dark inside (2.9-10 on the top views measured), a round body seen from the side is not
    (0.8-1.5)."""
    if profile is None:
        return None
    return float((profile[0] + profile[-1]) / 2 / max(float(profile[3:-3].min()), 1e-3))


def shading_profile(photo: np.ndarray, region: np.ndarray, solid: np.ndarray, bins: int = 10) -> np.ndarray | None:
    """The photo's brightness across the object: each row (the middle 80 % of the rows) is cut into `bins` strips
    across the fitted solid's width and each strip's mean luminance taken relative to the row's median; the
    median of each strip over the rows (`bins` values, left to right). None with too few rows.

    Args:
        photo: H x W x 3 uint8. region: H x W bool silhouette. solid: H x W bool fitted solid (its row ends
            give each row's width and axis).
    """
    lum = luminance(photo)
    left, right = _row_ends(solid)
    rows = np.nonzero(region.any(1) & (right - left >= 10))[0]
    rows = rows[int(0.1 * rows.size):int(0.9 * rows.size)]
    if rows.size < 5:
        return None
    lo, hi = left[rows, None], right[rows, None]
    u = (2 * np.arange(photo.shape[1])[None] - lo - hi) / (hi - lo)  # R x W: -1..1 across the solid
    inside = region[rows] & (np.abs(u) <= 1)
    values = np.where(inside, lum[rows], np.nan)
    median = np.nanmedian(np.where(inside.any(1, keepdims=True), values, 0.0), axis=1)  # R
    which = np.minimum(((u + 1) / 2 * bins).astype(int), bins - 1).clip(0)
    index = (np.arange(rows.size)[:, None] * bins + which)[inside]
    sums = np.bincount(index, lum[rows][inside], rows.size * bins).reshape(-1, bins)
    counts = np.bincount(index, minlength=rows.size * bins).reshape(-1, bins)
    strips = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan) / (median[:, None] + 1e-3)
    if np.isnan(strips).all(0).any():
        return None
    return np.nanmedian(strips, 0)
