"""Hard framings of one photo with its object's silhouette known: the test set of the object locator.

Each source (a real photo with the silhouette located on it, or a rendered vase pasted over a backdrop with its
true silhouette) is re-framed as a new user's photos come: cropped tight (the object touching two opposite
edges), on a frame-filling grey, coloured, gradient or textured backdrop, cut out on white and on transparent
(ragged edges), with a label, scale bar and colour chart, and standing on a plinth. `with_handles` adds handles
to a pasted vase, whose handle-free silhouette is then the truth of the symmetric core.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from radar_cli.masks.synthetic import backdrop

KINDS = ("tight", "backdrop", "white", "rgba", "label", "stand")
FILLS = ("grey", "coloured", "gradient", "textured")  # the frame-filling backdrops, in turn


@dataclass(frozen=True)
class Variant:
    """One test photo.

    Attributes:
        kind: one of `KINDS` (or `original`, `handles`).
        image: H x W x 3 uint8 RGB, or H x W x 4 RGBA for `rgba`.
        truth: H x W bool silhouette of the object (stands, labels and, for `handles`, handles excluded).
    """

    kind: str
    image: np.ndarray
    truth: np.ndarray


def _bbox(mask: np.ndarray) -> tuple[int, int, int, int]:
    ys, xs = np.nonzero(mask)
    return int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1


def tight_window(mask: np.ndarray, rng: np.random.Generator) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1): a window cut at the object's extent along its long axis (it touches those two edges)
    with a margin of 10-30 % of its width across."""
    h, w = mask.shape
    x0, y0, x1, y1 = _bbox(mask)
    if y1 - y0 >= x1 - x0:
        pad = (x1 - x0) * rng.uniform(0.1, 0.3, 2)
        return max(0, int(x0 - pad[0])), y0, min(w, int(x1 + pad[1])), y1
    pad = (y1 - y0) * rng.uniform(0.1, 0.3, 2)
    return x0, max(0, int(y0 - pad[0])), x1, min(h, int(y1 + pad[1]))


def _alpha(mask: np.ndarray) -> np.ndarray:
    """H x W float coverage of a bool mask with a soft (about one pixel) edge."""
    return cv2.GaussianBlur(mask.astype(np.float32), (0, 0), 0.7)


def paste(photo: np.ndarray, mask: np.ndarray, canvas: np.ndarray) -> np.ndarray:
    """The object of H x W x 3 uint8 `photo` (through H x W bool `mask`) over H x W x 3 float [0, 1] `canvas`."""
    a = _alpha(mask)[..., None]
    out = photo.astype(np.float32) / 255.0 * a + canvas * (1 - a)
    return (out * 255 + 0.5).clip(0, 255).astype(np.uint8)


def fill_backdrop(kind: str, h: int, w: int, rng: np.random.Generator) -> np.ndarray:
    """H x W x 3 float frame-filling backdrop: `grey`, `coloured` (saturated), `gradient` or `textured`."""
    if kind == "grey":
        return np.full((h, w, 3), rng.uniform(0.3, 0.7), np.float32) + rng.normal(0, 0.006, (h, w, 3)).astype(
            np.float32)
    if kind == "coloured":
        hue = np.uint8(rng.integers(0, 180))
        hsv = np.array([[[hue, rng.integers(120, 230), rng.integers(110, 220)]]], np.uint8)
        colour = cv2.cvtColor(hsv, cv2.COLOR_HSV2RGB)[0, 0] / 255.0
        return np.broadcast_to(colour, (h, w, 3)).astype(np.float32) + rng.normal(0, 0.006, (h, w, 3)).astype(
            np.float32)
    return backdrop(kind, h, w, rng)


def ragged(mask: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The mask with a ragged outline (a hand-made cut-out): the edge moved in and out by up to ~1 % of the
    object's size, in patches."""
    size = math.sqrt(mask.sum())
    noise: np.ndarray = cv2.GaussianBlur(rng.normal(0, 1, mask.shape).astype(np.float32), (0, 0), max(1.0, size / 60))
    noise /= max(float(np.abs(noise).max()), 1e-6)
    dist_in = cv2.distanceTransform(mask.astype(np.uint8), cv2.DIST_L2, 3)
    dist_out = cv2.distanceTransform((~mask).astype(np.uint8), cv2.DIST_L2, 3)
    signed = np.where(mask, dist_in, -dist_out)
    return signed + noise * 0.012 * size > 0.5


def _stamp(img: np.ndarray, free: np.ndarray, patch: np.ndarray, rng: np.random.Generator) -> None:
    """Put a h x w x 3 float patch in place where it covers only `free` pixels (a corner first), if anywhere."""
    H, W = free.shape
    h, w = patch.shape[:2]
    spots = [(4, 4), (4, W - w - 4), (H - h - 4, 4), (H - h - 4, W - w - 4)]
    rng.shuffle(spots)
    for y, x in spots:
        if y >= 0 and x >= 0 and free[y : y + h, x : x + w].all():
            img[y : y + h, x : x + w] = patch
            free[max(0, y - 6) : y + h + 6, max(0, x - 6) : x + w + 6] = False
            return


def add_label(photo: np.ndarray, mask: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The photo with a text card, a black-and-white scale bar and a colour chart where they miss the object."""
    H, W = mask.shape
    img = photo.astype(np.float32) / 255.0
    free = ~(cv2.dilate(mask.astype(np.uint8), np.ones((15, 15), np.uint8)) > 0)
    s = min(H, W)
    card: np.ndarray = np.full((int(0.07 * s), int(0.28 * s), 3), 247, np.uint8)
    cv2.putText(card, "1984.12.3", (3, card.shape[0] - 5), cv2.FONT_HERSHEY_SIMPLEX, card.shape[0] / 45,
                (0, 0, 0), 1)
    card = card.astype(np.float32) / 255.0
    bar = np.full((int(0.035 * s), int(0.3 * s), 3), 0.97, np.float32)
    step = max(2, bar.shape[1] // 10)
    for k in range(0, bar.shape[1], 2 * step):
        bar[:, k : k + step] = 0.03
    chart = np.zeros((int(0.1 * s), int(0.3 * s), 3), np.float32)
    cells = rng.uniform(0.05, 0.95, (2, 6, 3)).astype(np.float32)
    chart[:] = cv2.resize(cells, (chart.shape[1], chart.shape[0]), interpolation=cv2.INTER_NEAREST)
    for patch in (card, bar, chart):
        _stamp(img, free, patch, rng)
    return (img * 255 + 0.5).clip(0, 255).astype(np.uint8)


def add_stand(photo: np.ndarray, mask: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The object standing on a plinth that reaches the photo's bottom edge (the canvas grows downwards with
    the bottom rows' backdrop if the object stands too low). Returns (photo, its object mask)."""
    H, W = mask.shape
    x0, y0, x1, y1 = _bbox(mask)
    need = int(0.12 * (y1 - y0)) - (H - y1)
    if need > 0:
        colour = np.median(photo[-3:].reshape(-1, 3), axis=0).astype(np.uint8)
        photo = np.concatenate([photo, np.broadcast_to(colour, (need, W, 3))], axis=0)
        mask = np.concatenate([mask, np.zeros((need, W), bool)], axis=0)
        H += need
    foot = np.nonzero(mask[max(y0, y1 - max(2, (y1 - y0) // 30)) : y1].any(0))[0]
    cx, half = (foot.min() + foot.max()) / 2, (foot.max() - foot.min()) / 2 * rng.uniform(1.2, 1.6)
    half = max(half, 0.15 * (x1 - x0))
    img = photo.astype(np.float32) / 255.0
    top = y1 - 1
    shade = rng.uniform(0.12, 0.35) if rng.random() < 0.5 else rng.uniform(0.75, 0.9)
    tone = np.array([1.0, 0.85, 0.7] if rng.random() < 0.5 else [1.0, 1.0, 1.0], np.float32) * shade
    ramp = np.linspace(1.0, 0.8, H - top)[:, None, None]
    xa, xb = int(max(0, cx - half)), int(min(W, cx + half))
    img[top:, xa:xb] = tone * ramp
    out = (img * 255 + 0.5).clip(0, 255).astype(np.uint8)
    return np.where(mask[..., None], photo, out), mask  # the vase stands in front of the plinth's top edge


def make_variant(kind: str, photo: np.ndarray, mask: np.ndarray, rng: np.random.Generator,
                 index: int = 0) -> Variant:
    """One `KINDS` variant of an H x W x 3 uint8 photo whose object is the H x W bool `mask`.

    Args:
        index: picks the frame-filling backdrop in turn (`FILLS`) for `backdrop`.
    """
    if kind == "tight":
        x0, y0, x1, y1 = tight_window(mask, rng)
        return Variant(kind, np.ascontiguousarray(photo[y0:y1, x0:x1]), mask[y0:y1, x0:x1])
    if kind == "backdrop":
        x0, y0, x1, y1 = tight_window(mask, rng)
        m = mask[y0:y1, x0:x1]
        canvas = fill_backdrop(FILLS[index % len(FILLS)], m.shape[0], m.shape[1], rng)
        return Variant(kind, paste(photo[y0:y1, x0:x1], m, canvas), m)
    if kind == "white":
        m = ragged(mask, rng)
        return Variant(kind, paste(photo, m, np.ones(photo.shape, np.float32)), m)
    if kind == "rgba":
        m = ragged(mask, rng)
        alpha = (_alpha(m) * 255 + 0.5).astype(np.uint8)
        rgb = np.where(alpha[..., None] > 0, photo, 0).astype(np.uint8)
        return Variant(kind, np.dstack([rgb, alpha]), m)
    if kind == "label":
        return Variant(kind, add_label(photo, mask, rng), mask)
    if kind == "stand":
        img, m = add_stand(photo, mask, rng)
        return Variant(kind, img, m)
    raise ValueError(f"unknown variant kind {kind!r} (use one of {', '.join(KINDS)})")


def with_handles(photo: np.ndarray, mask: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A vase given two loop handles (an amphora's), drawn in its own colour on both sides, each joining the
    body at two heights.

    Returns:
        (H x W x 3 uint8 photo, H x W bool silhouette with the handles); the input mask is the core's truth.
    """
    x0, y0, x1, y1 = _bbox(mask)
    height = y1 - y0
    ya = y0 + int(rng.uniform(0.12, 0.3) * height)
    yb = ya + int(rng.uniform(0.25, 0.4) * height)
    thick = max(2, int(rng.uniform(0.03, 0.05) * height))
    reach = rng.uniform(0.12, 0.22) * (x1 - x0)
    colour = tuple(float(c) for c in np.median(photo[mask], axis=0) * rng.uniform(0.7, 0.9))
    layer = np.zeros(mask.shape, np.uint8)
    t = np.linspace(0.0, 1.0, 40)[:, None]
    for side in (-1, 1):
        ends = []
        for y in (ya, yb):
            xs = np.nonzero(mask[y])[0]
            edge = (xs.max() if side > 0 else xs.min()) if len(xs) else (x1 if side > 0 else x0)
            ends.append(np.array([edge - side * thick, y], float))
        apex = np.array([(x1 if side > 0 else x0) + side * 2 * reach, (ya + yb) / 2])
        curve = (1 - t) ** 2 * ends[0] + 2 * t * (1 - t) * apex + t**2 * ends[1]  # quadratic Bezier, 40 x 2
        cv2.polylines(layer, [np.round(curve).astype(np.int32)], False, 1, thick)
    handles = (layer > 0) & ~mask
    img = photo.copy()
    img[handles] = colour
    return img, mask | handles
