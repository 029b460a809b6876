"""Classical object detector for studio photographs: the background is modelled from the image border.

Museum photographs are mostly taken against plain or gradient backdrops. A low-order (quadratic) colour model is
fitted robustly to a band along the image border; a pixel's distance from that model, in units of the border's
own noise, says how unlike the backdrop it is. Edges and spectral-residual saliency (opencv-contrib) add
evidence where the object's colour is close to the backdrop. Connected components that are large enough become
instances, one per object.

Where the object fills much of the frame (a tight crop, a vessel touching the top and bottom edges) the border
model is extrapolated over a backdrop it has barely seen; a GrabCut pass over the whole downscaled photo,
seeded by that evidence (border pixels that fit the model are sure backdrop), learns the backdrop's colours from
all of it and decides the object's pixels.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numpy as np

from radar_cli.masks.border import backdrop_band, frame_padding
from radar_cli.masks.outline import outline_support
from radar_cli.masks.quality import sor_score

WORK_SIDE = 320  # detection runs at this long edge; refinement happens later at crop resolution
MIN_AREA_FRAC = 0.01  # components smaller than this fraction of the image are noise (labels, dust)
MIN_REL_AREA = 0.2  # ... and components smaller than this fraction of the largest one are dropped too
GROUP_GAP = 0.03  # components whose boxes come this close (fraction of the long edge) are one object ...
GROUP_OVERLAP = 0.5  # ... if they also share this fraction of the narrower one's width (a label beside it: not)
COARSE_ITERATIONS = 4  # GrabCut iterations of the whole-photo pass
DRIFT_EVIDENCE = 0.9  # evidence this strong inside the seed is object, whatever GrabCut's colour models say ...
DRIFT_SHARE = 0.25  # ... and a cut that gives more than this share of it to the backdrop has drifted, ...
DRIFT_SUPPORT = 0.6  # ... where the evidence's own outline lies this much on the photo's edges (`_support`)
RING = 0.03  # the second backdrop model leaves out this much (fraction of the long edge) around the object
SEED_SHARE = 0.5  # the backdrop's colour surface is refitted to this best-fitting share of the border band ...
SEED_ROUNDS = 3  # ... this many times
SEED_MIN_TOLERANCE = 8.0  # band pixels this close (RGB levels) to that surface are backdrop whatever its spread
LIGHT_RANGE = (0.2, 1.6)  # brightness ratios to the backdrop model that shading of the backdrop can explain
GREY_SPREAD = 4.0  # a photo whose channels differ by less than this (levels) almost everywhere is greyscale
READING_SHARE = 0.25  # a reading whose largest object is under this share of another reading's does not count
SHADING_LEAD = 0.05  # on a colour photo the reading that forgives shading wins unless beaten by this much support
GROWTH = 1.5  # ... or unless the other reading's object is this many times as large ...
GROWTH_SLACK = 0.02  # ... with its outline on the photo's edges nearly as well (support at most this much lower)
SYMMETRIC_GROWTH = 1.03  # ... or unless the other reading's object is this many times as large and as symmetric
SYMMETRY_SLACK = 0.01  # ... about an axis (its solid-of-revolution score at most this much lower) ...
SYMMETRY_SUPPORT_SLACK = 0.08  # ... with its outline on the photo's edges nearly as well (support at most this lower)


@dataclass(frozen=True)
class Detection:
    """One object found in a photograph.

    Attributes:
        mask: h x w bool at detection scale (the photo resized so its long edge is `WORK_SIDE`).
        box: (x0, y0, x1, y1) in the ORIGINAL photo's pixels, half-open.
        score: mean foreground evidence inside the mask, in [0, 1] (higher = more clearly not backdrop).
        scale: detection pixels per original pixel.
        sure: h x w bool, the pixels of `mask` with direct evidence (not just enclosed by the object's outline:
            a hole filled there may be backdrop seen through a handle), or None if all of `mask` is sure.
    """

    mask: np.ndarray
    box: tuple[float, float, float, float]
    score: float
    scale: float
    sure: np.ndarray | None = None


def downscale(image: np.ndarray, long_side: int = WORK_SIDE) -> tuple[np.ndarray, float]:
    """Resize an H x W x 3 uint8 image so its long edge is `long_side` (never enlarge much); return it and the
    scale factor (work pixels per original pixel)."""
    scale = long_side / max(image.shape[:2])
    if abs(scale - 1.0) < 1e-3:
        return image, 1.0
    h, w = (max(1, round(s * scale)) for s in image.shape[:2])
    interp = cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR
    return cv2.resize(image, (w, h), interpolation=interp), scale


def _design(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """N x 6 quadratic design matrix of normalised coordinates in [-1, 1]."""
    return np.stack([np.ones_like(xs), xs, ys, xs * ys, xs * xs, ys * ys], axis=1)


def fit_backdrop(image: np.ndarray, band: np.ndarray, rounds: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Model the backdrop colour everywhere from the border band.

    A quadratic colour surface per channel is fitted to the band with iterated trimming (labels, objects that
    touch the border are outliers); what the quadratic misses along the border (sweeps, vignetting) is carried
    inward by harmonic interpolation of the inlier residuals.

    Args:
        image: H x W x C float32.
        band: H x W bool, the pixels assumed to be mostly backdrop.

    Returns:
        model: H x W x C backdrop colour; noise: C robust std of the band's pixel-to-pixel variation (>= 1.5).
    """
    h, w, c = image.shape
    gy, gx = np.mgrid[0:h, 0:w].astype(np.float32)
    gx, gy = gx / max(w - 1, 1) * 2 - 1, gy / max(h - 1, 1) * 2 - 1
    ys, xs = np.nonzero(band)
    a_all = _design(gx[ys, xs], gy[ys, xs])  # N x 6
    values = image[ys, xs]  # N x C
    keep = np.ones(len(ys), bool)
    sample = np.zeros(len(ys), bool)
    sample[:: max(1, len(ys) // 4000)] = True  # a few thousand border pixels pin six coefficients down
    for _ in range(rounds):
        fit = keep & sample
        a, b = a_all[fit].astype(np.float64), values[fit].astype(np.float64)
        coef = np.linalg.solve(a.T @ a + 1e-6 * np.eye(6), a.T @ b)  # 6 x C (normal equations: 6 unknowns)
        resid = np.linalg.norm(values - a_all @ coef, axis=1)
        cut = max(3.0 * 1.4826 * np.median(resid[keep]), 6.0)
        keep = resid < cut
        if keep.sum() < 12:
            keep = resid <= np.median(resid)
    quad = (_design(gx.ravel(), gy.ravel()) @ coef).reshape(h, w, c).astype(np.float32)
    resid_img = np.zeros((h, w, c), np.float32)
    known = np.zeros((h, w), bool)
    resid_img[ys[keep], xs[keep]] = (values - a_all @ coef)[keep]
    known[ys[keep], xs[keep]] = True
    model = quad + harmonic_fill(resid_img, known)
    local = image - cv2.blur(image, (3, 3))
    noise = np.maximum(1.4826 * np.median(np.abs(local[ys[keep], xs[keep]]), axis=0) * 3.0, 1.5)
    return model, noise.astype(np.float32)


def harmonic_fill(values: np.ndarray, known: np.ndarray, grid: int = 40, iterations: int = 200) -> np.ndarray:
    """Smoothly interpolate H x W x C `values` from the `known` pixels to all others (Laplace equation solved
    by Jacobi iterations on a coarse grid, then upsampled)."""
    h, w = known.shape
    gh, gw = max(2, round(grid * h / max(h, w))), max(2, round(grid * w / max(h, w)))
    weight = cv2.resize(known.astype(np.float32), (gw, gh), interpolation=cv2.INTER_AREA)
    vals = cv2.resize(values * known[..., None], (gw, gh), interpolation=cv2.INTER_AREA).reshape(gh, gw, -1)
    fixed = weight > 0.25
    vals[fixed] /= weight[fixed][:, None]
    field = np.where(fixed[..., None], vals, 0.0).astype(np.float32)
    for _ in range(iterations):
        avg = cv2.blur(field, (3, 3), borderType=cv2.BORDER_REPLICATE).reshape(gh, gw, -1)
        field = np.where(fixed[..., None], vals, avg)
    out = cv2.resize(field, (w, h), interpolation=cv2.INTER_LINEAR)
    return out.reshape(h, w, -1)


def backdrop_distance(image: np.ndarray, band: np.ndarray, shading: bool = True) -> np.ndarray:
    """H x W distance of each pixel from the fitted backdrop, in units of the border noise.

    Shadows and light pools on the backdrop scale its colour by a common factor and carry no texture: where the
    brightness ratio is in `LIGHT_RANGE`, the distance counted is the departure from the scaled backdrop colour
    (chroma) plus the local texture, not the brightness change itself.

    Args:
        image: H x W x 3 uint8 RGB (detection scale).
        band: H x W bool border band.
        shading: forgive shading so; without, every brightness change counts (a greyscale photo of a vessel a
            little darker than its backdrop, which would pass for its shadow).
    """
    smooth = cv2.GaussianBlur(image, (0, 0), 1.2).astype(np.float32)
    model, noise = fit_backdrop(smooth, band)
    dist = np.sqrt((((smooth - model) / noise) ** 2).sum(axis=2))
    ratio = (smooth * model).sum(2) / np.maximum((model * model).sum(2), 1.0)
    chroma = np.sqrt((((smooth - ratio[..., None] * model) / noise) ** 2).sum(axis=2))
    grey = smooth.mean(axis=2)
    # band-pass detail: object outlines and surface texture have it, soft shadow edges and light pools do not
    texture = cv2.GaussianBlur(np.abs(grey - cv2.GaussianBlur(grey, (0, 0), 1.5)), (0, 0), 2.0) / noise.mean()
    lighting = (ratio > LIGHT_RANGE[0]) & (ratio < LIGHT_RANGE[1])
    if not shading:
        return dist
    return np.where(lighting, np.minimum(dist, 1.5 * chroma + 3.0 * texture), dist)


def edge_map(image: np.ndarray) -> np.ndarray:
    """H x W float edge strength in [0, 1] (Canny on the grey image, auto thresholds from the median)."""
    grey = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    grey = cv2.GaussianBlur(grey, (0, 0), 1.0)
    med = float(np.median(grey))
    edges = cv2.Canny(grey, max(5.0, 0.4 * med), max(15.0, 0.8 * med))
    return cv2.GaussianBlur(edges.astype(np.float32) / 255.0, (0, 0), 1.5).clip(0, 1) * 2.0


def saliency_map(image: np.ndarray) -> np.ndarray:
    """H x W spectral-residual saliency in [0, 1] (opencv-contrib); zeros if the module is missing."""
    sal = getattr(cv2, "saliency", None)
    if sal is None:
        return np.zeros(image.shape[:2], np.float32)
    ok, smap = sal.StaticSaliencySpectralResidual_create().computeSaliency(image)
    if not ok:
        return np.zeros(image.shape[:2], np.float32)
    smap = smap.astype(np.float32)
    return smap / max(float(smap.max()), 1e-6)


def is_greyscale(image: np.ndarray) -> bool:
    """Whether an H x W x 3 uint8 photo's channels differ by less than GREY_SPREAD almost everywhere."""
    smooth = cv2.GaussianBlur(image, (0, 0), 1.2)
    r, g, b = smooth[..., 0], smooth[..., 1], smooth[..., 2]
    spread = np.maximum(np.maximum(r, g), b) - np.minimum(np.minimum(r, g), b)  # np.ptp(axis=2), 10x as fast
    return bool(np.quantile(spread, 0.98) < GREY_SPREAD)


def foreground_evidence(image: np.ndarray, band: np.ndarray | None = None, shading: bool = True) -> np.ndarray:
    """H x W evidence in [0, 1] that a pixel is not backdrop: colour distance, plus edges and saliency near the
    threshold (they can lift a low-contrast pixel over it, never create an object alone).

    Args:
        image: H x W x 3 uint8 RGB.
        band: H x W bool, the pixels the backdrop is modelled from (default: the border pixels that show
            backdrop, `backdrop_band`).
        shading: forgive the backdrop's shading (`backdrop_distance`).
    """
    band = backdrop_band(image) if band is None else band
    dist = backdrop_distance(image, band, shading)
    colour = 1.0 - np.exp(-((dist / 6.0) ** 2))  # ~0.63 at 6 sigma
    extra = 0.25 * edge_map(image).clip(0, 1) + 0.15 * saliency_map(image)
    return np.clip(colour + extra * (colour > 0.15), 0.0, 1.0)


def coarse_grabcut(image: np.ndarray, evidence: np.ndarray, threshold: float,
                   band: np.ndarray | None = None, cuts: dict[bytes, np.ndarray] | None = None) -> np.ndarray:
    """H x W bool object pixels of a detection-scale photo: GrabCut over the whole image, started from the
    evidence (above `threshold`, holes filled: probable object; a thin ring around it: probable backdrop; beyond
    it and `backdrop_seeds` in the border band: sure backdrop). Falls back to the thresholded evidence if
    GrabCut cannot run or breaks the object up; and to it less the sure backdrop if the cut gives more than
    DRIFT_SHARE of the seed's strongest evidence (above DRIFT_EVIDENCE) to the backdrop while the evidence's own
    outline lies on the photo's edges (`_support` at least DRIFT_SUPPORT): GrabCut's colour models have drifted
    (a pale vessel filling the frame's width with a panel painted on it, the backdrop seen only in thin margins:
    GrabCut keeps the panel and gives the vessel's ground, far from the backdrop's colour, to the backdrop). Where
    the evidence's outline runs through the backdrop instead (a mottled or shaded backdrop that the evidence
    took in part), GrabCut's cut stands.

    Args:
        image: H x W x 3 uint8 RGB. evidence: H x W in [0, 1] (`foreground_evidence`).
        band: H x W bool, the border pixels that show backdrop (default: `backdrop_band`).
        cuts: GrabCut's labels by the labels it started from, for calls on the same image: a cut is a function
            of the image and its start (fresh colour models, the generator seeded), so two readings that start
            alike (a clean backdrop, read with its shading forgiven or not) share one.
    """
    raw = evidence > threshold
    if not raw.any():
        return raw
    seed = _clean(raw)  # holes filled: a flat object seen only by its outline is object inside
    reach = cv2.dilate(seed.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
    tri = np.full(raw.shape, cv2.GC_BGD, np.uint8)  # GrabCut trims what the evidence took, it never adds
    tri[reach] = cv2.GC_PR_BGD
    tri[seed] = cv2.GC_PR_FGD
    sure = backdrop_seeds(image, band)
    tri[sure] = cv2.GC_BGD
    start = tri.tobytes()
    if cuts is not None and start in cuts:
        tri = cuts[start].copy()
    else:
        bgd, fgd = np.zeros((1, 65), np.float64), np.zeros((1, 65), np.float64)
        cv2.setRNGSeed(0)  # GrabCut's k-means draws from a per-thread generator: the same cut in any thread
        try:
            # OpenCV's stubs want a rectangle; None is what GC_INIT_WITH_MASK takes
            cv2.grabCut(np.ascontiguousarray(image), tri, None, bgd, fgd,  # type: ignore[call-overload]
                        COARSE_ITERATIONS, cv2.GC_INIT_WITH_MASK)
        except cv2.error:
            return raw
        if cuts is not None:
            cuts[start] = tri.copy()
    cut = (tri == cv2.GC_FGD) | (tri == cv2.GC_PR_FGD)
    # GrabCut trims backdrop that the evidence took for object; if it breaks a modest object up instead (a flat
    # object seen only by its outline), the evidence stands
    broken = _largest_area(_clean(cut)) < 0.5 * _largest_area(seed) and seed.mean() < 0.5
    if broken:
        return raw
    strong = seed & (evidence > DRIFT_EVIDENCE)
    if (strong & ~cut).sum() > DRIFT_SHARE * strong.sum():
        kept = raw & ~sure
        if _support(image, _clean(kept)) >= DRIFT_SUPPORT:
            return kept
    return cut


def backdrop_seeds(image: np.ndarray, band: np.ndarray | None = None) -> np.ndarray:
    """H x W bool border-band pixels that are surely backdrop: those that a quadratic colour surface, fitted to
    the band's best-fitting half, explains. An object running into the band is the minority there and is left
    out, even where the border model (which carries the whole band's residuals inwards) took it for backdrop.

    Args:
        image: H x W x 3 uint8 RGB. band: H x W bool, the border pixels that show backdrop (default:
            `backdrop_band`).
    """
    band = backdrop_band(image) if band is None else band
    h, w = band.shape
    ys, xs = np.nonzero(band)
    a = _design(xs / max(w - 1, 1) * 2 - 1.0, ys / max(h - 1, 1) * 2 - 1.0).astype(np.float64)  # N x 6
    values = image[ys, xs].astype(np.float64)  # N x 3
    sample = np.arange(0, len(ys), max(1, len(ys) // 3000))  # a few thousand pixels pin six coefficients down
    keep = sample
    for _ in range(SEED_ROUNDS):
        fit_a, fit_b = a[keep], values[keep]
        coef = np.linalg.solve(fit_a.T @ fit_a + 1e-6 * np.eye(6), fit_a.T @ fit_b)  # 6 x 3 (normal equations)
        resid = np.linalg.norm(values[sample] - a[sample] @ coef, axis=1)
        keep = sample[resid <= np.quantile(resid, SEED_SHARE)]
    resid = np.linalg.norm(values - a @ coef, axis=1)
    fits = resid <= max(3.0 * 1.4826 * float(np.median(resid[keep])), SEED_MIN_TOLERANCE)
    seeds = np.zeros(band.shape, bool)
    seeds[ys[fits], xs[fits]] = True
    return seeds


def _square(side: float) -> np.ndarray:
    k = max(3, int(round(side)) | 1)
    return np.ones((k, k), np.uint8)


def _largest_area(mask: np.ndarray) -> int:
    """Pixels in the largest 8-connected component of a bool mask (0 if empty)."""
    n, _, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    return int(stats[1:, cv2.CC_STAT_AREA].max()) if n > 1 else 0


def main_component(mask: np.ndarray) -> np.ndarray:
    """The largest 8-connected component of a bool mask."""
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    if n <= 2:
        return mask.astype(bool)
    return labels == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))


def _clean(mask: np.ndarray) -> np.ndarray:
    """Close small gaps, fill holes (flood from the border), open away specks."""
    side = max(mask.shape)
    k = max(3, (side // 80) | 1)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))
    m = cv2.morphologyEx(mask.astype(np.uint8), cv2.MORPH_CLOSE, kernel)
    m = fill_holes(m > 0).astype(np.uint8)
    return cv2.morphologyEx(m, cv2.MORPH_OPEN, kernel) > 0


def fill_holes(mask: np.ndarray, max_hole_frac: float = 1.0) -> np.ndarray:
    """Fill the holes of a bool mask that are at most `max_hole_frac` of the mask's area."""
    m = mask.astype(np.uint8)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(1 - m, connectivity=4)
    h, w = m.shape
    out = mask.copy()
    limit = max_hole_frac * max(int(m.sum()), 1)
    for i in range(1, n):
        x, y, bw, bh, area = stats[i]
        touches = x == 0 or y == 0 or x + bw == w or y + bh == h
        if not touches and area <= limit:
            out[labels == i] = True
    return out


def _groups(boxes: list[tuple[int, int, int, int]], gap: float) -> list[list[int]]:
    """Indices of boxes (x0, y0, x1, y1) grouped transitively when they come within `gap` px of each other
    vertically and share most of the narrower one's width: the pieces of one object that the threshold split
    apart (a label or colour chart beside the object stays apart)."""
    group = list(range(len(boxes)))

    def root(i: int) -> int:
        while group[i] != i:
            i = group[i]
        return i

    for i, a in enumerate(boxes):
        for j in range(i):
            b = boxes[j]
            shared = min(a[2], b[2]) - max(a[0], b[0])
            narrower = max(1, min(a[2] - a[0], b[2] - b[0]))
            if (shared >= GROUP_OVERLAP * narrower and a[1] - gap < b[3] and b[1] - gap < a[3]):
                group[root(i)] = root(j)
    out: dict[int, list[int]] = {}
    for i in range(len(boxes)):
        out.setdefault(root(i), []).append(i)
    return list(out.values())


def _cut(small: np.ndarray, band: np.ndarray, padding: np.ndarray, threshold: float, thorough: bool,
         shading: bool, *, first: np.ndarray | None = None,
         cuts: dict[bytes, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(evidence, object pixels) of a detection-scale photo (see `detect`); `first`: its first evidence, from the
    border band, if already known; `cuts` as coarse_grabcut's."""
    evidence = foreground_evidence(small, band, shading) if first is None else first
    raw = coarse_grabcut(small, evidence, threshold, band, cuts) & ~padding
    if thorough and raw.any():  # model the backdrop again from all round the object, not only the border
        # (vignettes, light pools, a stand's surroundings), and cut again
        clear = ~(cv2.dilate(_clean(raw).astype(np.uint8), _square(RING * max(raw.shape))) > 0)
        if clear.mean() > RING:
            evidence = foreground_evidence(small, (clear | band) & ~padding, shading)
            raw = coarse_grabcut(small, evidence, threshold, band, cuts) & ~padding
    return evidence, raw


def _support(small: np.ndarray, mask: np.ndarray) -> float:
    """Outline support (`masks.outline`) of a detection-scale object mask; -1 if it is under MIN_AREA_FRAC."""
    return (outline_support(small, mask) or 0.0) if mask.mean() >= MIN_AREA_FRAC else -1.0


def _scored(small: np.ndarray, raw: np.ndarray) -> tuple[np.ndarray, int, float]:
    """(cleaned object, its largest component's pixels, its `_support`) of one reading's object pixels."""
    cleaned = _clean(raw)
    return cleaned, _largest_area(cleaned), _support(small, cleaned)


def _best_reading(small: np.ndarray, read: Callable[[bool], tuple[np.ndarray, np.ndarray]], lead: float,
                  glance: Callable[[], np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(evidence, object pixels, cleaned object) of the reading whose outline lies most on the photo's edges:
    `read(True)` forgives the backdrop's shading and scores its `_support` plus `lead`, `read(False)` does not and
    scores its `_support`; a reading whose largest object is under READING_SHARE of the other's found only specks
    of the object (a low-contrast vessel taken for the backdrop's shading) and does not count; a tie goes to the
    forgiving reading. The strict reading also wins where its object is GROWTH times as large and its support
    at most GROWTH_SLACK lower: shade does not add half again to an object and keep its outline on sharp edges;
    a black body on a dark sweep, or a white one on a pale backdrop, that the forgiving reading took for shade
    does. And it wins where its object is SYMMETRIC_GROWTH times as large and its largest part at most
    SYMMETRY_SLACK less symmetric about an axis (`quality.sor_score`) and its support at most
    SYMMETRY_SUPPORT_SLACK lower: a shadow cast beside the vessel makes the object lopsided, a neighbour taken in
    as well; the vessel's own dark lower body does not. A pool of light on the floor, centred under the vessel,
    is as symmetric, but its soft edge is no edge in the photo (a greyscale photo, where the vessel's pale foot
    and the lit floor are one grey: the strict reading takes the floor in, its support 0.12-0.24 lower).

    The second reading is made only if it could win: not where the first one's object covers READING_SHARE of
    the photo (so it counts however large the other's is), its score reaches 1 (the most the other can score)
    and `glance()`, the object the strict evidence shows before any cut (H x W bool, a tenth of a reading's
    cost), is under GROWTH times as large.
    """
    forgiving = read(True)
    cleaned, area, support = _scored(small, forgiving[1])
    if area >= READING_SHARE * cleaned.size and support + lead >= 1.0 and _largest_area(glance()) < GROWTH * area:
        return (*forgiving, cleaned)
    strict = read(False)
    strict_cleaned, strict_area, strict_support = _scored(small, strict[1])
    largest = max(area, strict_area)
    score = support + lead if area >= READING_SHARE * largest else -1.0
    strict_score = strict_support if strict_area >= READING_SHARE * largest else -1.0
    grown = strict_area >= GROWTH * area and strict_support >= support - GROWTH_SLACK
    keep = score >= strict_score and not grown and not (  # the symmetry is read only where it can decide
        strict_area >= SYMMETRIC_GROWTH * area and strict_support >= support - SYMMETRY_SUPPORT_SLACK
        and sor_score(main_component(strict_cleaned)) >= sor_score(main_component(cleaned)) - SYMMETRY_SLACK)
    return (*forgiving, cleaned) if keep else (*strict, strict_cleaned)


def detect(image: np.ndarray, threshold: float = 0.5, thorough: bool = False) -> list[Detection]:
    """Find the objects in a studio photograph.

    Args:
        image: H x W x 3 uint8 RGB, any size (it is downscaled to `WORK_SIDE` here).
        threshold: evidence level that separates object from backdrop.
        thorough: model the backdrop a second time from all round the first cut and cut again (about 1.5x
            the time; `radar derender` locates its one object so, `radar masks` does not).

    Returns:
        Detections, largest first; empty if nothing stands out from the backdrop.
    """
    small, scale = downscale(image)
    padding = frame_padding(small)  # a flat frame round the picture: it must not join the object to its edges
    band = backdrop_band(small) & ~padding
    # the photo is read with its shading forgiven and, where that reading could lose, not (a shadow, or a vessel
    # a little darker than its backdrop?): the reading whose outline lies more on the photo's edges is kept (one
    # that finds no object of MIN_AREA_FRAC does not count); on a colour photo the forgiving reading stands unless
    # the other one's outline lies clearly more on edges (a dark vessel on a grey backdrop: its body passes for
    # shade)
    lead = 0.0 if is_greyscale(small) else SHADING_LEAD
    strict = functools.cache(lambda: foreground_evidence(small, band, shading=False))  # glanced at, then read
    cuts: dict[bytes, np.ndarray] = {}
    evidence, raw, mask = _best_reading(
        small, lambda shading: _cut(small, band, padding, threshold, thorough, shading,
                                    first=None if shading else strict(), cuts=cuts), lead,
        lambda: _clean(strict() > threshold) & ~padding)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    if n <= 1:
        return []
    areas = stats[1:, cv2.CC_STAT_AREA]
    min_area = max(MIN_AREA_FRAC * mask.size, MIN_REL_AREA * areas.max())
    big = [i + 1 for i in range(n - 1) if areas[i] >= min_area]
    boxes = [(stats[i, 0], stats[i, 1], stats[i, 0] + stats[i, 2], stats[i, 1] + stats[i, 3]) for i in big]
    found = []
    for members in _groups(boxes, GROUP_GAP * max(mask.shape)):
        comp = np.isin(labels, [big[k] for k in members])
        ys, xs = np.nonzero(comp)
        box = (xs.min() / scale, ys.min() / scale, (xs.max() + 1) / scale, (ys.max() + 1) / scale)
        found.append(Detection(comp, box, float(evidence[comp].mean()), scale, comp & raw))
    return sorted(found, key=lambda d: -int(d.mask.sum()))
