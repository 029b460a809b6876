"""`radar bench masks`: photos per second of the whole masks pipeline on large generated studio photos."""

from __future__ import annotations

import resource
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from radar_cli.fileio import write_bytes
from radar_cli.masks.pipeline import Settings, process_photo
from radar_cli.masks.prepare import prepare
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


def _cpu_seconds() -> float:
    """User + system CPU time of this process and its finished children (pool workers)."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def bench_masks(n_photos: int = 12, long_side: int = 4000, size: int = 256, workers: int = 2,
                seed: int = 0) -> dict:
    """Time `radar masks` (JPEG decode, detection, GrabCut, crops, scores, writes; no contact sheet) on n
    generated studio photos of `long_side` px.

    On a shared machine wall-clock seconds include other users' load; `cpu_seconds_per_photo` does not.

    Returns:
        dict with photos, long_side, workers, seconds, photos_per_second, cpu_seconds_per_photo, accepted.
    """
    rng = np.random.default_rng(seed)
    with tempfile.TemporaryDirectory() as tmp:
        photos = Path(tmp) / "photos"
        for i in range(n_photos):
            ok, buf = cv2.imencode(".jpg", cv2.cvtColor(studio_photo(long_side, rng), cv2.COLOR_RGB2BGR),
                                   [cv2.IMWRITE_JPEG_QUALITY, 90])
            write_bytes(photos / f"photo_{i:03d}.jpg", buf.tobytes())
        process_photo(photos / "photo_000.jpg", Settings(size=size))  # warm-up: imports, first allocations
        t0, c0 = time.perf_counter(), _cpu_seconds()
        summary = prepare(photos, Path(tmp) / "out", Settings(size=size), workers=workers, contact_sheet=False,
                          progress=False)
        seconds, cpu = time.perf_counter() - t0, _cpu_seconds() - c0
    return {"photos": n_photos, "long_side": long_side, "workers": workers, "seconds": round(seconds, 2),
            "photos_per_second": round(n_photos / seconds, 2), "cpu_seconds_per_photo": round(cpu / n_photos, 3),
            "accepted": int(sum(summary.accepted.values()))}
