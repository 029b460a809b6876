"""Albedo maps for synthetic vases: a procedural family that looks like painted and glazed pottery, or images
from a folder, with the paper's brightness, contrast and hue augmentation.

Every map is an unwrapped 360 deg texture, H x W x 3 float32 in [0, 1], display (tone-mapped) space, periodic
across the left and right edges (column 0 continues column W-1) so the vase shows no seam. Rows run from the
top of the vase (0) to the bottom. Everything is drawn from a numpy Generator: same seed, same map.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import cv2
import numpy as np

from radar_cli.errors import InputError
from radar_cli.fileio import read_image

IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".webp", ".bmp", ".tif", ".tiff")

# glaze and slip colours (display RGB in [0, 1]): terracotta, cream, cobalt, celadon, black, ochre, white,
# oxblood, turquoise, manganese brown, sage, straw
POTTERY_COLOURS = np.array([
    [0.72, 0.38, 0.22], [0.93, 0.88, 0.76], [0.12, 0.22, 0.58], [0.58, 0.72, 0.60], [0.08, 0.07, 0.07],
    [0.80, 0.58, 0.20], [0.96, 0.96, 0.94], [0.50, 0.08, 0.10], [0.20, 0.62, 0.66], [0.36, 0.22, 0.14],
    [0.55, 0.60, 0.45], [0.86, 0.78, 0.52],
], dtype=np.float32)


class _Canvas:
    """Pixel coordinates of an unwrapped map: theta (angle, radians, periodic) and v (0 top .. 1 bottom)."""

    def __init__(self, height: int, width: int):
        self.h, self.w = height, width
        self.theta = ((np.arange(width, dtype=np.float32) + 0.5) / width * 2 * math.pi)[None, :]  # 1 x W
        self.v = ((np.arange(height, dtype=np.float32) + 0.5) / height)[:, None]  # H x 1

    def rows(self, v0: float, v1: float) -> tuple[slice, "_Canvas"]:
        """The rows that a band from v0 to v1 can touch (its anti-aliased edges included), and a canvas of just
        those rows: same scale (h), so every pattern drawn on it equals the full canvas's rows there."""
        r0, r1 = max(0, math.floor(v0 * self.h) - 1), min(self.h, math.ceil(v1 * self.h) + 1)
        sub = copy.copy(self)
        sub.v = self.v[r0:r1]  # (r1 - r0) x 1
        return slice(r0, r1), sub


def _soft(signed_px: np.ndarray) -> np.ndarray:
    """Coverage from a signed distance in pixels (negative inside), anti-aliased over one pixel."""
    return np.clip(0.5 - signed_px, 0.0, 1.0).astype(np.float32)


def _blend(tex: np.ndarray, mask: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """tex painted with colour where mask (H x W or broadcastable) is 1: tex + (colour - tex) * mask, in place."""
    m = np.broadcast_to(mask, tex.shape[:2])[..., None]
    tex += (colour[None, None, :] - tex) * m
    return tex


def periodic_noise(rng: np.random.Generator, canvas: _Canvas, cells: tuple[int, int], octaves: int = 1) -> np.ndarray:
    """Smooth value noise, periodic in x, H x W float32 with values in about [0, 1]."""
    out = np.zeros((canvas.h, canvas.w), dtype=np.float32)
    total = 0.0
    for octave in range(octaves):
        cy, cx = cells[0] * 2**octave, cells[1] * 2**octave
        grid = rng.random((cy, cx), dtype=np.float32)
        tiled = np.concatenate([grid, grid, grid], axis=1)  # the middle third of the resize is periodic
        big = cv2.resize(tiled, (3 * canvas.w, canvas.h), interpolation=cv2.INTER_CUBIC)
        out += big[:, canvas.w : 2 * canvas.w] * 0.5**octave
        total += 0.5**octave
    return np.clip(out / total, 0.0, 1.0)


def _band(rng: np.random.Generator, c: _Canvas, v0: float, v1: float) -> np.ndarray:
    """A horizontal band between v0 and v1, H x 1."""
    return _soft(np.maximum(v0 - c.v, c.v - v1) * c.h)


def _stripes(rng: np.random.Generator, c: _Canvas, v0: float, v1: float) -> np.ndarray:
    """Vertical or slanted stripes (an integer number around the vase, so they close up)."""
    k = int(rng.integers(6, 40))
    slant = float(rng.uniform(-2.0, 2.0)) if rng.random() < 0.4 else 0.0
    duty = float(rng.uniform(0.2, 0.6))
    phase = (k * c.theta / (2 * math.pi) + slant * c.v) % 1.0  # H x W
    dist_px = (np.abs(phase - 0.5) - duty / 2) * (c.w / k)
    return _soft(dist_px) * _band(rng, c, v0, v1)


def _zigzag(rng: np.random.Generator, c: _Canvas, v0: float, v1: float) -> np.ndarray:
    """A zigzag or wave line running around the vase inside a band."""
    k = int(rng.integers(4, 24))
    a = (k * c.theta / (2 * math.pi)) % 1.0
    wave = np.abs(2 * a - 1) if rng.random() < 0.5 else 0.5 + 0.5 * np.cos(2 * math.pi * a)
    centre = v0 + (v1 - v0) * (0.2 + 0.6 * wave)  # 1 x W
    thick = float(rng.uniform(0.08, 0.25)) * (v1 - v0) * c.h
    return _soft(np.abs(c.v - centre) * c.h - thick / 2)


def _meander(rng: np.random.Generator, c: _Canvas, v0: float, v1: float) -> np.ndarray:
    """A Greek-key-like meander: bars and hooks on a repeating cell inside a band."""
    k = int(rng.integers(8, 28))
    a = (k * c.theta / (2 * math.pi)) % 1.0  # 1 x W, position in the cell
    b = np.clip((c.v - v0) / max(v1 - v0, 1e-6), -1, 2)  # H x 1
    cell_w, cell_h = c.w / k, (v1 - v0) * c.h
    t = 0.14
    rail = np.minimum(np.abs(b - t / 2), np.abs(b - 1 + t / 2)) * cell_h - t * cell_h / 2  # top and bottom rails
    post = np.abs(a - t / 2) * cell_w - t * cell_w / 2 + np.zeros_like(b)
    arm = np.maximum(np.abs(b - 0.5) * cell_h - t * cell_h / 2, (a - 0.7) * cell_w)
    hook = np.maximum(np.abs(a - 0.7) * cell_w - t * cell_w / 2, (0.5 - b) * cell_h)
    hook = np.maximum(hook, (b - 1 + t) * cell_h)
    dist = np.minimum(np.minimum(rail, post), np.minimum(arm, hook))
    return _soft(dist) * _band(rng, c, v0, v1)


def _dots(rng: np.random.Generator, c: _Canvas, v0: float, v1: float) -> np.ndarray:
    """A row of round dots (or several rows) inside a band."""
    k = int(rng.integers(8, 48))
    rows = int(rng.integers(1, 4))
    a = (k * c.theta / (2 * math.pi)) % 1.0 - 0.5  # 1 x W
    rows_v = (c.v - v0) / max(v1 - v0, 1e-6) * rows  # H x 1
    b = rows_v % 1.0 - 0.5
    shift = np.where((np.floor(rows_v) % 2) == 1, 0.5, 0.0)  # stagger alternate rows
    a = (a + shift + 0.5) % 1.0 - 0.5
    dx, dy = a * (c.w / k), b * (v1 - v0) * c.h / rows
    radius = float(rng.uniform(0.2, 0.42)) * min(c.w / k, (v1 - v0) * c.h / rows)
    return _soft(np.sqrt(dx * dx + dy * dy) - radius) * _band(rng, c, v0, v1)


def _flowers(rng: np.random.Generator, c: _Canvas, v0: float, v1: float) -> tuple[np.ndarray, np.ndarray]:
    """Floral-ish blobs: rosettes with n petals and a centre disc; returns (petals, centres) masks."""
    k = int(rng.integers(3, 14))
    petals = int(rng.integers(4, 9))
    a = (k * c.theta / (2 * math.pi)) % 1.0 - 0.5
    vc = 0.5 * (v0 + v1)
    dx = a * (c.w / k)
    dy = (c.v - vc) * c.h
    size = 0.45 * min(c.w / k, (v1 - v0) * c.h)
    r = np.sqrt(dx * dx + dy * dy)
    phi = np.arctan2(dy, dx)
    outline = size * (0.55 + 0.45 * np.abs(np.cos(petals * phi / 2)))
    return _soft(r - outline), _soft(r - 0.22 * size)


def _marble(rng: np.random.Generator, c: _Canvas) -> np.ndarray:
    """Marbled veins: a sine of a turbulent coordinate, sharpened."""
    turb = periodic_noise(rng, c, (4, 8), octaves=4)
    k = int(rng.integers(1, 6))
    s = np.sin(k * c.theta + float(rng.uniform(4, 16)) * c.v * math.pi + float(rng.uniform(4, 10)) * turb)
    return (1.0 - np.abs(s)) ** float(rng.uniform(4, 12))


def _crackle(rng: np.random.Generator, c: _Canvas) -> np.ndarray:
    """Crazing of the glaze: thin lines along the zero crossings of band-passed noise."""
    cells = (int(rng.integers(6, 16)), int(rng.integers(16, 48)))
    n = periodic_noise(rng, c, cells) - periodic_noise(rng, c, (cells[0] // 2 + 1, cells[1] // 2 + 1))
    gy, gx = np.gradient(n)
    grad = np.sqrt(gx * gx + gy * gy) + 1e-6
    return _soft(np.abs(n) / grad - float(rng.uniform(0.4, 1.0)))  # distance to the crossing, in pixels


def _speckle(rng: np.random.Generator, c: _Canvas) -> np.ndarray:
    """Iron speckle: sparse small spots."""
    density = float(rng.uniform(0.002, 0.02))
    spots = (rng.random((c.h, c.w), dtype=np.float32) < density).astype(np.float32)
    pad = 4
    wrapped = np.pad(spots, ((0, 0), (pad, pad)), mode="wrap")  # blur across the seam too
    blurred = cv2.GaussianBlur(wrapped, (0, 0), float(rng.uniform(0.5, 1.2)))[:, pad:-pad]
    return np.clip(blurred * 3.0, 0.0, 1.0)


def _pick(rng: np.random.Generator, palette: np.ndarray) -> np.ndarray:
    return np.clip(palette[rng.integers(len(palette))] + rng.normal(0, 0.04, 3).astype(np.float32), 0, 1)


def _decorate_bands(tex: np.ndarray, rng: np.random.Generator, c: _Canvas, palette: np.ndarray) -> np.ndarray:
    """Stack 0..6 decorated horizontal bands (plain, stripes, zigzag, meander, dots, flowers), each drawn on
    the rows it covers only (every pattern is 0 outside its band)."""
    for _ in range(int(rng.integers(0, 7))):
        v0 = float(rng.uniform(0.0, 0.9))
        v1 = min(1.0, v0 + float(rng.uniform(0.03, 0.3)))
        kind = int(rng.integers(6))
        colour = _pick(rng, palette)
        rows, band = c.rows(v0, v1)
        part = tex[rows]  # a view: blends below paint tex in place
        if kind == 0:
            _blend(part, _band(rng, band, v0, v1), colour)
        elif kind == 1:
            _blend(part, _stripes(rng, band, v0, v1), colour)
        elif kind == 2:
            _blend(part, _zigzag(rng, band, v0, v1), colour)
        elif kind == 3:
            _blend(part, _meander(rng, band, v0, v1), colour)
        elif kind == 4:
            _blend(part, _dots(rng, band, v0, v1), colour)
        else:
            petals, centres = _flowers(rng, band, v0, v1)
            _blend(_blend(part, petals, colour), centres, _pick(rng, palette))
    return tex


def procedural_texture(rng: np.random.Generator, height: int, width: int) -> np.ndarray:
    """A random pottery-like albedo map, H x W x 3 float32 in [0, 1], periodic in x, before augmentation."""
    c = _Canvas(height, width)
    palette = POTTERY_COLOURS[rng.choice(len(POTTERY_COLOURS), size=int(rng.integers(2, 6)), replace=False)]
    base = _pick(rng, palette)
    tex: np.ndarray = np.broadcast_to(base, (height, width, 3)).astype(np.float32)
    if rng.random() < 0.4:  # a dipped glaze: another colour over the top or the bottom part
        split = float(rng.uniform(0.2, 0.8))
        edge = periodic_noise(rng, c, (1, 6)) * 0.08
        sign = 1.0 if rng.random() < 0.5 else -1.0
        tex = _blend(tex, _soft(sign * (c.v - split - edge) * c.h), _pick(rng, palette))
    if rng.random() < 0.3:
        tex = _blend(tex, _marble(rng, c) * float(rng.uniform(0.5, 1.0)), _pick(rng, palette))
    if rng.random() < 0.25:  # an all-over pattern
        kind = int(rng.integers(3))
        cover = (_stripes if kind == 0 else _dots if kind == 1 else _zigzag)(rng, c, 0.0, 1.0)
        tex = _blend(tex, cover, _pick(rng, palette))
    tex = _decorate_bands(tex, rng, c, palette)
    glaze = periodic_noise(rng, c, (int(rng.integers(2, 8)), int(rng.integers(4, 16))), octaves=3)
    tex = tex * (1.0 + float(rng.uniform(0.0, 0.3)) * (glaze[..., None] - 0.5))
    if rng.random() < 0.3:
        tex = _blend(tex, _crackle(rng, c) * float(rng.uniform(0.3, 0.8)), _pick(rng, POTTERY_COLOURS[[4, 9]]))
    if rng.random() < 0.4:
        tex = _blend(tex, _speckle(rng, c) * float(rng.uniform(0.4, 0.9)), _pick(rng, POTTERY_COLOURS[[4, 9, 7]]))
    return np.clip(tex, 0.0, 1.0).astype(np.float32)


def list_texture_images(folder: str | Path) -> list[Path]:
    """Image files directly in `folder`, sorted; InputError if there are none."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: no such texture folder")
    files = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_EXTENSIONS)
    if not files:
        raise InputError(f"{folder}: no texture images ({', '.join(IMAGE_EXTENSIONS)})")
    return files


def image_texture(path: Path, rng: np.random.Generator, height: int, width: int) -> np.ndarray:
    """A map from an image file: a random crop, resized to H x W/2 and mirrored so the map closes seamlessly."""
    img = read_image(path, "RGB").astype(np.float32) / 255.0
    ih, iw = img.shape[:2]
    frac = float(rng.uniform(0.5, 1.0))
    ch, cw = max(1, int(ih * frac)), max(1, int(iw * frac))
    y0, x0 = int(rng.integers(0, ih - ch + 1)), int(rng.integers(0, iw - cw + 1))
    half = cv2.resize(img[y0 : y0 + ch, x0 : x0 + cw], (max(1, width // 2), height), interpolation=cv2.INTER_AREA)
    full = np.concatenate([half, half[:, ::-1]], axis=1)
    if full.shape[1] != width:
        full = cv2.resize(full, (width, height), interpolation=cv2.INTER_LINEAR)
    return full


def augment(tex: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, dict[str, float]]:
    """The paper's colour augmentation (as its released generator): brightness x U(1, 1.5), contrast x U(1, 1.6)
    about the mean grey, hue shifted by U(-180, 180) deg.

    Returns:
        (augmented H x W x 3 float32 in [0.02, 1], the drawn values).
    """
    brightness = float(rng.uniform(1.0, 1.5))
    contrast = float(rng.uniform(1.0, 1.6))
    hue = float(rng.uniform(-180.0, 180.0))
    out: np.ndarray = np.clip(tex * brightness, 0.0, 1.0)
    grey = float((out @ np.array([0.299, 0.587, 0.114], dtype=np.float32)).mean())
    out = np.clip((out - grey) * contrast + grey, 0.0, 1.0).astype(np.float32)
    hsv = cv2.cvtColor(out, cv2.COLOR_RGB2HSV)  # float input: H in [0, 360)
    hsv[..., 0] = (hsv[..., 0] + hue) % 360.0
    out = cv2.cvtColor(hsv, cv2.COLOR_HSV2RGB)
    return np.clip(out, 0.02, 1.0).astype(np.float32), {"brightness": brightness, "contrast": contrast, "hue": hue}
