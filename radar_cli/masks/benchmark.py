"""`radar bench masks`: photos per second of the whole masks pipeline on large generated studio photos."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from radar_cli.fileio import write_bytes
from radar_cli.masks.pipeline import Settings, process_photo
from radar_cli.masks.synthetic import backdrop, sor_mask


def studio_photo(long_side: int, rng: np.random.Generator) -> np.ndarray:
    """A long_side x (3/4 long_side) x 3 uint8 portrait photo: a flat-shaded vase on a gradient backdrop."""
    h, w = long_side, long_side * 3 // 4
    small = backdrop("gradient", h // 8, w // 8, rng)
    bg = cv2.resize(small, (w, h), interpolation=cv2.INTER_LINEAR)
    side = min(int(h * 0.8), w - 8)
    mask = cv2.resize(sor_mask(256, rng).astype(np.uint8), (side, side), interpolation=cv2.INTER_NEAREST) > 0
    top, left = (h - side) // 2, (w - side) // 2
    region = bg[top : top + side, left : left + side]
    region[mask] = rng.uniform(0.1, 0.6, 3) * np.linspace(0.7, 1.0, side)[None, :, None].repeat(side, 0)[mask]
    return (bg * 255).astype(np.uint8)


def bench_masks(n_photos: int = 12, long_side: int = 4000, size: int = 256, seed: int = 0) -> dict:
    """Time `process_photo` (JPEG decode included) on n generated photos of `long_side` px.

    One process; `cpu_seconds_per_photo` (process time) is the figure to trust on a shared machine, where
    wall-clock seconds include other users' load.

    Returns:
        dict with photos, long_side, seconds, photos_per_second, cpu_seconds_per_photo, accepted_crops.
    """
    rng = np.random.default_rng(seed)
    settings = Settings(size=size)
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for i in range(n_photos):
            ok, buf = cv2.imencode(".jpg", cv2.cvtColor(studio_photo(long_side, rng), cv2.COLOR_RGB2BGR),
                                   [cv2.IMWRITE_JPEG_QUALITY, 90])
            paths.append(Path(tmp) / f"photo_{i}.jpg")
            write_bytes(paths[-1], buf.tobytes())
        process_photo(paths[0], settings)  # warm-up (imports, allocations)
        t0, c0 = time.perf_counter(), time.process_time()
        accepted = sum(c.accepted for p in paths for c in process_photo(p, settings))
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    return {"photos": n_photos, "long_side": long_side, "seconds": round(seconds, 2),
            "photos_per_second": round(n_photos / seconds, 2), "cpu_seconds_per_photo": round(cpu / n_photos, 3),
            "accepted_crops": int(accepted)}
