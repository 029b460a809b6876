"""Faces on the photographed object. A head vase, a flask blown or moulded as a head, a lid shaped as a head: their
silhouettes can be those of turned vessels, and the solid of revolution then turns the face into a smooth body
with the face painted on it. dlib's frontal face detector (HOG features and a linear classifier, trained on
photographs of people; no model file to fetch) finds such faces; its own decision threshold is 0."""

from __future__ import annotations

import threading

import cv2
import dlib
import numpy as np

DETECT_WIDTH = 400
"""The object's width in pixels when faces are looked for: a face a fifth of the object's width or wider is then at
least 80 px, the detector's window, so it is found without upsampling."""
MAX_SIDE = 1600
"""... but no side of the scaled crop over this (a tall, thin object is not blown up to a giant image)."""
MARGIN = 0.1
"""Backdrop kept round the object's bounding box, as a share of its width (a face's window needs its edges)."""
FLOOR = -1.0
"""The lowest detector score reported; an image without a candidate window scores this."""

_DETECTOR: dlib.fhog_object_detector | None = None
_LOCK = threading.Lock()


def _detect(image: np.ndarray) -> tuple[list, list]:
    """(rectangles, scores) of the face windows in an H x W x 3 uint8 image scoring at least FLOOR (one call at a
    time: the detector is built once, 0.3-0.5 s, and shared)."""
    global _DETECTOR
    with _LOCK:
        if _DETECTOR is None:
            _DETECTOR = dlib.get_frontal_face_detector()
        rects, scores, _ = _DETECTOR.run(image, 0, FLOOR)
    return list(rects), list(scores)


def _best(image: np.ndarray, whole: np.ndarray) -> float:
    """The best score of a face window centred on the object and no wider than it (FLOOR without one).

    Args:
        image: H x W x 3 uint8, the object DETECT_WIDTH wide; whole: H x W bool, the object."""
    best = FLOOR
    h, w = whole.shape
    for rect, score in zip(*_detect(image)):
        x = min(max(rect.center().x, 0), w - 1)
        y = min(max(rect.center().y, 0), h - 1)
        if rect.width() <= DETECT_WIDTH and whole[y, x]:
            best = max(best, float(score))
    return best


def face_score(photo: np.ndarray, whole: np.ndarray) -> float | None:
    """How much the object shows a face looking out of the photo: the detector's best score on the object, the
    mean of the photo's and its mirror image's (a face is its own mirror image; a pattern that passes for one
    seldom does both ways). Above 0 a face is there by the detector's own threshold.

    Args:
        photo: N x N x 3 uint8 input; whole: N x N bool located object (core and appendages).
    Returns:
        the score (FLOOR where no window comes near), or None for an empty object.
    """
    rows, cols = np.nonzero(whole.any(1))[0], np.nonzero(whole.any(0))[0]
    if not len(cols):
        return None
    width = cols[-1] - cols[0] + 1
    pad = int(MARGIN * width)
    v0, v1 = max(rows[0] - pad, 0), min(rows[-1] + pad + 1, whole.shape[0])
    u0, u1 = max(cols[0] - pad, 0), min(cols[-1] + pad + 1, whole.shape[1])
    scale = min(DETECT_WIDTH / width, MAX_SIDE / max(u1 - u0, v1 - v0))
    size = (max(round((u1 - u0) * scale), 1), max(round((v1 - v0) * scale), 1))
    interp = cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR
    image = cv2.resize(np.ascontiguousarray(photo[v0:v1, u0:u1]), size, interpolation=interp)
    mask = cv2.resize(whole[v0:v1, u0:u1].astype(np.uint8), size, interpolation=cv2.INTER_NEAREST) > 0
    seen = _best(image, mask)
    mirrored = _best(np.ascontiguousarray(image[:, ::-1]), np.ascontiguousarray(mask[:, ::-1]))
    return 0.5 * (seen + mirrored)
