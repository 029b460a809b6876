"""Test material with known answers: rendered vases pasted over generated backdrops, and non-SoR silhouettes.

Used by the accuracy evaluation and the tests; nothing here touches real photographs.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import torch

from radar_cli.sor.solid import Solid

BACKDROPS = ("plain", "gradient", "textured", "shadow", "label")


def sine_profiles(n: int, rows: int, rng: np.random.Generator) -> np.ndarray:
    """n x rows radius columns (fractions of r_max, top row first) made of a few sine waves, in [0.05, 0.9]
    (the supplementary material's recipe for vase-like curves)."""
    t = np.linspace(0.0, 1.0, rows)[None]
    base = rng.uniform(0.3, 0.55, (n, 1))
    r = base.copy()
    for _ in range(3):
        amp = rng.uniform(0.0, 0.18, (n, 1))
        freq = rng.uniform(0.5, 2.0, (n, 1))
        phase = rng.uniform(0, 2 * math.pi, (n, 1))
        r = r + amp * np.sin(2 * math.pi * freq * t + phase)
    return np.clip(r, 0.08, 0.85)


def render_vases(n: int, size: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Render n textured, shaded vases with the project's ray caster.

    Returns:
        image: n x size x size x 3 float in [0, 1] (premultiplied by alpha), alpha: n x size x size float,
        mask: n x size x size bool (ground-truth silhouette).
    """
    from radar_cli.render.raycast import cast_rays
    from radar_cli.render.texture import render_texture

    rng = np.random.default_rng(seed)
    radius = torch.tensor(sine_profiles(n, 32, rng), dtype=torch.float32)
    height = torch.tensor(rng.uniform(0.5, 0.95, n), dtype=torch.float32)
    pose = torch.tensor(np.stack([rng.uniform(0, 20, n), rng.uniform(-5, 5, n), np.zeros(n), np.zeros(n)], 1),
                        dtype=torch.float32)
    with torch.no_grad():
        hits = cast_rays(Solid(radius, height, pose), size)
        texture = torch.tensor(_vase_textures(n, rng), dtype=torch.float32)  # n x 3 x 64 x 192
        color, _ = render_texture(hits, texture)
    shade = 0.35 + 0.65 * hits.normal[..., 2].abs().clamp(0, 1)  # n x size x size, light from the camera
    mask = hits.mask.numpy()
    # alpha is the hard silhouette, slightly blurred: half coverage on the true outline, no outward halo
    alpha = np.stack([cv2.GaussianBlur(m.astype(np.float32), (0, 0), 0.5) for m in mask])
    colour = color.permute(0, 2, 3, 1) * shade[..., None]
    image = colour.numpy().clip(0, 1) * alpha[..., None]
    return image, alpha, mask


def _vase_textures(n: int, rng: np.random.Generator) -> np.ndarray:
    """n x 3 x 64 x 192 full 360 deg texture maps: a glaze colour with bands and speckle."""
    v = np.linspace(0, 1, 64)[:, None]
    u = np.linspace(0, 1, 192)[None]
    out = np.empty((n, 3, 64, 192), np.float32)
    for i in range(n):
        base = rng.uniform(0.05, 0.95, 3)
        other = rng.uniform(0.05, 0.95, 3)
        bands = (np.sin(2 * math.pi * rng.uniform(2, 6) * v + rng.uniform(0, 6)) > rng.uniform(0.3, 0.9))
        motif = np.sin(2 * math.pi * 6 * u) * np.sin(2 * math.pi * 3 * v) > 0.6
        pick = (bands | (motif & (rng.random() < 0.5))).astype(np.float32)
        tex = base[:, None, None] * (1 - pick) + other[:, None, None] * pick
        out[i] = np.clip(tex + rng.normal(0, 0.03, (3, 64, 192)), 0, 1)
    return out


def backdrop(kind: str, height: int, width: int, rng: np.random.Generator) -> np.ndarray:
    """A height x width x 3 float backdrop in [0, 1] of one of `BACKDROPS` (shadow and label add their extras
    in `composite`)."""
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    yy, xx = yy / height, xx / width
    colour = rng.uniform(0.55, 0.95) * (1 - rng.uniform(0, 0.15, 3))
    if kind == "plain":
        img = np.broadcast_to(colour, (height, width, 3)).copy()
    elif kind == "textured":
        f1, f2 = rng.uniform(40, 90), rng.uniform(40, 90)
        weave = 0.06 * np.sin(2 * math.pi * f1 * xx) * np.sin(2 * math.pi * f2 * yy)
        folds = 0.08 * np.sin(2 * math.pi * (rng.uniform(1, 3) * xx + rng.uniform(0.5, 2) * yy) + rng.uniform(0, 6))
        blotch = cv2.GaussianBlur(rng.normal(0, 1, (height, width)).astype(np.float32), (0, 0), 6) * 0.6
        img = colour * (1 + weave + folds + blotch)[..., None]
    else:  # gradient, and the base of shadow / label: a studio sweep with a light pool
        sweep = rng.uniform(0.25, 0.45) * (yy - 0.5)
        pool = rng.uniform(0.05, 0.15) * np.exp(-((xx - 0.5) ** 2 + (yy - 0.45) ** 2) / 0.08)
        img = colour * (1 - sweep + pool)[..., None]
    return np.clip(img + rng.normal(0, 0.008, img.shape), 0, 1).astype(np.float32)


def composite(vase: np.ndarray, alpha: np.ndarray, mask: np.ndarray, kind: str,
              rng: np.random.Generator, shape: tuple[int, int] = (600, 480)) -> tuple[np.ndarray, np.ndarray]:
    """Paste a rendered vase (S x S x 3 premultiplied, S x S alpha and mask) over a backdrop of `kind`.

    Returns:
        photo: H x W x 3 uint8; mask: H x W bool ground truth.
    """
    h, w = shape
    ys, xs = np.nonzero(mask)
    y0, y1, x0, x1 = ys.min(), ys.max() + 1, xs.min(), xs.max() + 1
    scale = rng.uniform(0.5, 0.75) * h / (y1 - y0)
    scale = min(scale, 0.8 * w / (x1 - x0))
    s = vase.shape[0]
    ns = max(8, int(round(s * scale)))
    v = cv2.resize(vase[y0:y1, x0:x1], None, fx=ns / s, fy=ns / s, interpolation=cv2.INTER_LINEAR)
    a = cv2.resize(alpha[y0:y1, x0:x1], (v.shape[1], v.shape[0]), interpolation=cv2.INTER_LINEAR)
    m = cv2.resize(mask[y0:y1, x0:x1].astype(np.uint8), (v.shape[1], v.shape[0]),
                   interpolation=cv2.INTER_NEAREST) > 0
    oh, ow = m.shape
    top = int(rng.uniform(0.15, 0.9) * (h - oh))
    left = int(rng.uniform(0.25, 0.75) * (w - ow))
    bg = backdrop(kind, h, w, rng)
    if kind == "shadow":
        shadow = np.zeros((h, w), np.float32)
        cv2.ellipse(shadow, (left + ow // 2 + int(0.1 * ow), top + oh), (int(0.6 * ow), max(3, oh // 14)), 0, 0,
                    360, 1.0, -1)
        bg *= (1 - 0.45 * cv2.GaussianBlur(shadow, (0, 0), max(2.0, oh / 40)))[..., None]
    if kind == "label":
        _draw_label(bg, rng)
    photo = bg.copy()
    region = photo[top : top + oh, left : left + ow]
    region[:] = v + region * (1 - a[..., None])
    gt = np.zeros((h, w), bool)
    gt[top : top + oh, left : left + ow] = m
    return (photo * 255 + 0.5).clip(0, 255).astype(np.uint8), gt


def _draw_label(img: np.ndarray, rng: np.random.Generator) -> None:
    """A white card with text or a black-and-white scale bar in one corner, in place."""
    h, w = img.shape[:2]
    lw, lh = int(w * rng.uniform(0.15, 0.25)), int(h * rng.uniform(0.04, 0.07))
    corner = rng.integers(4)
    x = 4 if corner % 2 == 0 else w - lw - 4
    y = 4 if corner < 2 else h - lh - 4
    if rng.random() < 0.5:
        card = np.full((lh, lw, 3), 247, np.uint8)
        cv2.putText(card, "MMA 1234", (3, lh - 4), cv2.FONT_HERSHEY_SIMPLEX, lh / 40, (0, 0, 0), 1)
        img[y : y + lh, x : x + lw] = card / 255.0
    else:
        step = max(2, lw // 10)
        for k in range(0, lw, step):
            img[y : y + lh // 2, x + k : x + k + step] = 0.05 if (k // step) % 2 == 0 else 0.97


def sor_mask(size: int, rng: np.random.Generator) -> np.ndarray:
    """size x size bool silhouette of a solid of revolution drawn in 2D: a sine profile mirrored about a
    vertical axis, the mouth's ellipse on top (pitch) and a small roll."""
    r = sine_profiles(1, 64, rng)[0]
    half_h = rng.uniform(0.5, 0.95) * size * 0.45
    scale = size * 0.45 * rng.uniform(0.7, 1.0)
    cx, cy = size / 2.0, size / 2.0
    left = [(cx - r[i] * scale * 0.95, cy - half_h + 2 * half_h * i / 63) for i in range(64)]
    right = [(cx + r[i] * scale * 0.95, cy - half_h + 2 * half_h * i / 63) for i in reversed(range(64))]
    m = np.zeros((size, size), np.uint8)
    cv2.fillPoly(m, [np.round(np.array(left + right)).astype(np.int32)], 1)
    squash = math.sin(math.radians(rng.uniform(0, 20)))
    cv2.ellipse(m, (int(cx), int(cy - half_h)), (int(r[0] * scale * 0.95), int(r[0] * scale * squash)), 0, 0,
                360, 1, -1)
    rot = cv2.getRotationMatrix2D((cx, cy), rng.uniform(-8, 8), 1.0)
    return cv2.warpAffine(m, rot, (size, size), flags=cv2.INTER_NEAREST) > 0


NON_SOR = ("teapot", "figurine", "animal", "blob", "jug")


def non_sor_mask(kind: str, size: int, rng: np.random.Generator) -> np.ndarray:
    """size x size bool silhouette of something that is not a solid of revolution (`NON_SOR` kinds)."""
    m = np.zeros((size, size), np.uint8)
    s, c = size, size // 2
    u = lambda lo, hi: float(rng.uniform(lo, hi))  # noqa: E731
    if kind in ("teapot", "jug"):
        body_w, body_h = int(s * u(0.2, 0.3)), int(s * u(0.15, 0.25))
        cv2.ellipse(m, (c, c), (body_w, body_h), 0, 0, 360, 1, -1)
        cv2.rectangle(m, (c - body_w // 3, c - body_h - int(s * u(0.02, 0.1))), (c + body_w // 3, c), 1, -1)
        side = 1 if rng.random() < 0.5 else -1
        handle = (c - side * body_w, c)
        cv2.ellipse(m, handle, (int(s * u(0.07, 0.12)), int(body_h * u(0.6, 0.9))), 0, 0, 360, 1,
                    max(2, s // 40))
        if kind == "teapot":
            base = (c + side * int(body_w * 0.8), c + body_h // 3)
            tip = (c + side * int(body_w + s * u(0.1, 0.18)), c - int(body_h * u(0.6, 1.2)))
            cv2.line(m, base, tip, 1, max(3, int(s * u(0.03, 0.06))))
    elif kind == "figurine":
        cv2.circle(m, (c + int(s * u(-0.05, 0.05)), int(s * 0.22)), int(s * u(0.05, 0.08)), 1, -1)
        cv2.ellipse(m, (c, int(s * 0.45)), (int(s * u(0.08, 0.13)), int(s * 0.17)), u(-15, 15), 0, 360, 1, -1)
        for sgn in (-1, 1):
            ang = math.radians(u(20, 160))
            start = (c + sgn * int(s * 0.09), int(s * 0.35))
            end = (start[0] + sgn * int(s * 0.2 * abs(math.cos(ang))),
                   start[1] + int(s * 0.2 * math.sin(ang) - 0.1 * s))
            cv2.line(m, start, end, 1, max(3, s // 30))
            cv2.line(m, (c + sgn * int(s * 0.05), int(s * 0.6)),
                     (c + sgn * int(s * u(0.03, 0.15)), int(s * 0.85)), 1, max(4, s // 22))
    elif kind == "animal":
        cv2.ellipse(m, (c, c), (int(s * u(0.22, 0.3)), int(s * u(0.1, 0.14))), u(-10, 10), 0, 360, 1, -1)
        side = 1 if rng.random() < 0.5 else -1
        cv2.circle(m, (c + side * int(s * 0.3), c - int(s * 0.13)), int(s * u(0.06, 0.09)), 1, -1)
        for dx in (-0.18, -0.1, 0.1, 0.18):
            cv2.line(m, (c + int(dx * s), c), (c + int(dx * s), c + int(s * u(0.2, 0.28))), 1, max(3, s // 30))
    else:  # blob: a random star-ish polygon
        k = 9
        angles = np.sort(rng.uniform(0, 2 * math.pi, k))
        rad = rng.uniform(0.15, 0.4, k) * s
        pts = np.stack([c + rad * np.cos(angles), c + rad * np.sin(angles)], 1)
        cv2.fillPoly(m, [np.round(pts).astype(np.int32)], 1)
    return m > 0
