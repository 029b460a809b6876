"""`radar bench derender`: images per second for the network alone and for the whole de-rendering with every
export, on this machine."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import torch

from radar_cli.derender.batch import DerenderOptions, derender, torch_threads
from radar_cli.derender.export import ExportConfig
from radar_cli.derender.predictor import AlbedoSource, PitchSource, Predictor
from radar_cli.fileio import write_image

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _photos(n: int, size: int, seed: int = 0) -> list[np.ndarray]:
    """n square H x W x 3 uint8 inputs: the repository's example vases if present, else drawn ellipses."""
    found = sorted(EXAMPLES.glob("*.png")) if EXAMPLES.is_dir() else []
    if found:
        from PIL import Image

        images = []
        for path in found:
            with Image.open(path) as im:
                images.append(np.asarray(im.convert("RGB").resize((size, size))))
        return [images[i % len(images)] for i in range(n)]
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size] / size
    photos = []
    for _ in range(n):
        image = np.full((size, size, 3), 235, np.uint8)
        inside = ((xx - 0.5) / rng.uniform(0.15, 0.3)) ** 2 + ((yy - 0.5) / rng.uniform(0.3, 0.42)) ** 2 < 1
        image[inside] = rng.integers(30, 200, 3)
        photos.append(image)
    return photos


def _silhouettes(images: list[np.ndarray]) -> list[np.ndarray]:
    """H x W bool masks: the pixels that differ from the image's corner (the plain backdrop) by > 12 levels."""
    return [np.abs(im.astype(np.int16) - im[0, 0].astype(np.int16)).max(axis=-1) > 12 for im in images]


def _network_rate(predictor: Predictor, images: list[np.ndarray], batch_size: int) -> tuple[float, float]:
    """(images/s wall, images/s of process CPU time) of predictor.predict with the images' silhouettes, after
    one warm-up batch."""
    masks = _silhouettes(images)
    predictor.predict(images[:batch_size], masks[:batch_size])
    wall, cpu = time.perf_counter(), time.process_time()
    for i in range(0, len(images), batch_size):
        predictor.predict(images[i : i + batch_size], masks[i : i + batch_size])
    if predictor.device.type == "cuda":
        torch.cuda.synchronize()
    return len(images) / (time.perf_counter() - wall), len(images) / max(time.process_time() - cpu, 1e-9)


def bench_derender(checkpoint: str | Path | None = None, device: str = "cpu", n_images: int = 32,
                   n_export: int = 4, batch_size: int = 8, threads: int = 1,
                   export: ExportConfig = ExportConfig(), predictor: Predictor | None = None,
                   workers: int = 2, albedo: AlbedoSource = "divided",
                   pitch: PitchSource = "network") -> dict:
    """Measure de-rendering speed.

    Args:
        checkpoint: model weights (default: the bundled model).
        device: auto, cpu, cuda.
        n_images: images pushed through the network alone.
        n_export: images de-rendered end to end (read, crop, network, all exports, report).
        batch_size: network batch size.
        threads: torch intra-op threads.
        export: turntable and view settings of the full run.
        predictor: use this instead of loading `checkpoint` (tests).
        workers: threads cropping and exporting objects.
        albedo: the predictor's albedo source (`divided` adds the shading division to the network's time).
        pitch: the predictor's pitch source (`search` adds the pitch search).

    Returns:
        {"network_images_per_s", "network_images_per_cpu_s", "full_images_per_s", "full_seconds_per_image",
         "image_size", "batch_size", "n_images", "n_export", "device", "threads", "workers", "albedo", "pitch",
         "model"}.
    """
    predictor = predictor or Predictor.from_checkpoint(checkpoint, device, albedo, pitch)
    size = predictor.setup.image_size
    images = _photos(n_images, size)
    with torch_threads(threads):
        net_wall, net_cpu = _network_rate(predictor, images, batch_size)
    with tempfile.TemporaryDirectory(prefix="radar-bench-") as tmp:
        for i, image in enumerate(_photos(n_export, size)):
            write_image(Path(tmp) / "in" / f"bench_{i:03d}.png", image)
        options = DerenderOptions(out=Path(tmp) / "out", batch_size=batch_size, workers=workers, threads=threads,
                                  export=export)
        start = time.perf_counter()
        summary = derender([Path(tmp) / "in"], predictor, options, say=lambda line: None)
        full = time.perf_counter() - start
    return {
        "network_images_per_s": round(net_wall, 2),
        "network_images_per_cpu_s": round(net_cpu, 2),
        "full_images_per_s": round(len(summary.done) / full, 3),
        "full_seconds_per_image": round(full / max(len(summary.done), 1), 2),
        "failed": len(summary.failures),
        "image_size": size,
        "batch_size": batch_size,
        "n_images": n_images,
        "n_export": n_export,
        "device": str(predictor.device),
        "threads": threads,
        "workers": workers,
        "albedo": predictor.albedo,
        "pitch": predictor.pitch,
        "model": predictor.version,
    }
