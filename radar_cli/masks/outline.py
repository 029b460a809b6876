"""Whether a silhouette sits on the object's edge: the share of its outline where the photo shows an edge.

A silhouette that is where the object is has the object's colour just inside its outline and the backdrop's
just outside, nearly all round. One moved off the object has plain backdrop on both sides of part of its
outline and the object's own paint on both sides of another part.
"""

from __future__ import annotations

import cv2
import numpy as np

CONTRAST = 12.0
"""Colour difference (Euclidean, 0-255 RGB, after a slight blur) across the outline that counts as an edge."""
MIN_OUTLINE = 20  # fewer measurable outline pixels than this: no score


def reach(side: int) -> float:
    """How far (pixels) inside and outside the outline the colours are compared, in a crop of this side: 4 px
    at 512, never under 2."""
    return max(2.0, side / 128)


def outline_normals(silhouette: np.ndarray, smooth: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The outline pixels of an H x W bool silhouette (its pixels with a 4-neighbour outside it) and their
    outward unit normals: (ys, xs, normals), normals K x 2 as (dx, dy)."""
    if silhouette.all() or not silhouette.any():  # no outline (and no distance to measure)
        empty = np.zeros(0, int)
        return empty, empty, np.zeros((0, 2))
    sil = silhouette.astype(np.uint8)
    inside = cv2.distanceTransform(sil, cv2.DIST_L2, 3)
    outside = cv2.distanceTransform(1 - sil, cv2.DIST_L2, 3)
    signed = cv2.GaussianBlur(outside - inside, (0, 0), smooth)  # rises outwards
    gy, gx = np.gradient(signed)
    edge = silhouette & ~cv2.erode(sil, np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], np.uint8),
                                   borderType=cv2.BORDER_CONSTANT, borderValue=1).astype(bool)
    ys, xs = np.nonzero(edge)
    normals = np.stack([gx[ys, xs], gy[ys, xs]], axis=1)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return ys, xs, normals / np.maximum(length, 1e-6)


def edge_contrast(image: np.ndarray, silhouette: np.ndarray, measurable: np.ndarray | None = None,
                  distance: float | None = None) -> np.ndarray:
    """The colour difference across each outline pixel of a silhouette.

    Args:
        image: H x W x 3 uint8, the photo as photographed (backdrop not replaced).
        silhouette: H x W bool.
        measurable: H x W bool, where a colour may be read (the photo, not its padding nor an appendage); all
            of the image if None.
        distance: how far inside and outside the outline the colours are read (pixels; `reach` if None).

    Returns:
        K floats: per outline pixel whose two readings are both measurable, the Euclidean RGB difference of
        the blurred image `distance` px outside and inside it.
    """
    h, w = silhouette.shape
    d = reach(max(h, w)) if distance is None else distance
    ys, xs, normals = outline_normals(silhouette, d / 2)
    if not len(ys):
        return np.zeros(0)
    blurred = cv2.GaussianBlur(image.astype(np.float32), (0, 0), max(0.7, d / 3))
    ok = np.ones((h, w), bool) if measurable is None else measurable
    reads, keep = [], np.ones(len(ys), bool)
    for sign in (1.0, -1.0):
        u = np.rint(xs + sign * d * normals[:, 0]).astype(int)
        v = np.rint(ys + sign * d * normals[:, 1]).astype(int)
        inside_frame = (u >= 0) & (u < w) & (v >= 0) & (v < h)
        u, v = np.clip(u, 0, w - 1), np.clip(v, 0, h - 1)
        keep &= inside_frame & ok[v, u]
        reads.append(blurred[v, u])
    return np.linalg.norm(reads[0] - reads[1], axis=1)[keep]


def outline_support(image: np.ndarray, silhouette: np.ndarray, measurable: np.ndarray | None = None,
                    contrast: float = CONTRAST) -> float | None:
    """Share of an H x W bool silhouette's measurable outline where the H x W x 3 uint8 photo shows an edge
    (`edge_contrast` above `contrast`); None if too little of the outline is measurable."""
    diff = edge_contrast(image, silhouette, measurable)
    return float((diff > contrast).mean()) if len(diff) >= MIN_OUTLINE else None
