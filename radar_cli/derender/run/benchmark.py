"""`radar bench derender`: images per second for the network alone and for the whole de-rendering with every
export, and the seconds and memory of one object's export at the output resolution, on this machine."""

from __future__ import annotations

import resource
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import torch

from radar_cli.derender.export.object_folder import ExportConfig, export_object
from radar_cli.derender.refine.driver import RefineMode
from radar_cli.derender.run.batch import EXPORT_THREADS, DerenderOptions, derender, environments
from radar_cli.derender.run.inputs import DEFAULT_RESOLUTION, InputItem, Resolution, output_side, prepare
from radar_cli.derender.run.predictor import AlbedoSource, PitchSource, Predictor
from radar_cli.derender.run.upsample import full_resolution_state
from radar_cli.fileio import write_image
from radar_cli.process_memory import PeakMemory
from radar_cli.threads import torch_threads

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
PHOTO_MARGIN = 1.6  # photos this much larger than the output side: the examples' crop windows span 0.68-1.05 of them


def _rss_mib() -> float:
    """This process's resident memory now, MiB (Linux /proc; 0 elsewhere)."""
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
    except (OSError, ValueError, IndexError):
        return 0.0
    return pages * resource.getpagesize() / 2**20


def _peak_rss_mib() -> float:
    """This process's peak resident memory so far, MiB (ru_maxrss is KiB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


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


def _export_cost(predictor: Predictor, photo_dir: Path, out: Path, resolution: Resolution,
                 export: ExportConfig) -> dict:
    """Seconds per object of building the output-resolution state and of writing every file, one object at a
    time on EXPORT_THREADS torch threads (as radar derender exports), and the memory it took."""
    setup = predictor.setup
    items = [InputItem(p.stem, p) for p in sorted(photo_dir.glob("*.png"))]
    prepared = [prepare(item, setup.render.image_size, resolution=resolution) for item in items]
    dec = predictor.predict([p.image for p in prepared], [p.silhouette for p in prepared])
    envs = environments((), setup.render.env_height, setup.render.env_width)
    refine_s, refine_cpu_s, state_s, write_s, cpu_s = [], [], [], [], []
    rss_before = _rss_mib()
    with torch_threads(EXPORT_THREADS):
        for k, (item, prep) in enumerate(zip(items, prepared)):
            start, cpu = time.perf_counter(), time.process_time()
            assert prep.photo_image is not None  # Prepared sets it
            refined, report = predictor.refine_object(dec.select(k), prep.image, prep.photo_image,
                                                      prep.photo_silhouette)
            refine_s.append(time.perf_counter() - start)
            refine_cpu_s.append(time.process_time() - cpu)
            start, cpu = time.perf_counter(), time.process_time()
            state = full_resolution_state(refined, prep, setup, predictor.albedo)
            middle = time.perf_counter()
            export_object(out / item.name, item, prep, state, setup, predictor.version, envs, export,
                          predictor.albedo, predictor.pitch, report.record())
            state_s.append(middle - start)
            write_s.append(time.perf_counter() - middle)
            cpu_s.append(time.process_time() - cpu)
    return {
        "resolution": sorted({p.side for p in prepared}),
        "refine": predictor.refine,
        "refine_seconds_per_object": round(statistics.median(refine_s), 3),
        "refine_cpu_seconds_per_object": round(statistics.median(refine_cpu_s), 3),
        "export_state_seconds": round(statistics.median(state_s), 4),
        "export_write_seconds": round(statistics.median(write_s), 3),
        "export_seconds_per_object": round(statistics.median(s + w for s, w in zip(state_s, write_s)), 3),
        "export_cpu_seconds_per_object": round(statistics.median(cpu_s), 3),
        "rss_before_export_mib": round(rss_before, 1),
        "peak_rss_mib": round(_peak_rss_mib(), 1),
    }


def bench_derender(checkpoint: str | Path | None = None, device: str = "cpu", n_images: int = 32,
                   n_export: int = 4, batch_size: int = 8, threads: int = 1,
                   export: ExportConfig = ExportConfig(), predictor: Predictor | None = None,
                   workers: int = 2, albedo: AlbedoSource = "divided",
                   pitch: PitchSource = "network", resolution: Resolution = DEFAULT_RESOLUTION,
                   refine: RefineMode = "full", n_full: int = 24) -> dict:
    """Measure de-rendering speed.

    Args:
        checkpoint: model weights (default: the bundled model).
        device: auto, cpu, cuda.
        n_images: images pushed through the network alone (at its side S).
        n_export: images exported one by one for the per-object figures; their photos are PHOTO_MARGIN x the
            output side.
        batch_size: network batch size.
        threads: torch intra-op threads.
        export: turntable and view settings of the full run.
        predictor: use this instead of loading `checkpoint` (tests).
        workers: radar derender --workers (processes on the CPU, threads beside a GPU).
        albedo: the predictor's albedo source (`divided` adds the shading division to the network's time).
        pitch: the predictor's pitch source (`search` adds the pitch search).
        resolution: radar derender --resolution.
        refine: radar derender --refine (timed apart from the export, one object at a time).
        n_full: photos de-rendered end to end by `radar derender` (read, crop, network, every export, report): the
            n_export photos cycled. Enough of them that the workers' start is a small part of the run.

    Returns:
        {"network_images_per_s", "network_images_per_cpu_s", "full_images_per_s", "full_seconds_per_image",
         "resolution", "refine", "refine_seconds_per_object", "refine_cpu_seconds_per_object",
         "export_state_seconds", "export_write_seconds", "export_seconds_per_object",
         "export_cpu_seconds_per_object" (process CPU time: steadier than wall time on a shared machine),
         "rss_before_export_mib", "peak_rss_mib" (after the one-at-a-time exports), "full_peak_rss_mib" and
         "full_peak_pss_mib" (the full run's processes together, process_memory.PeakMemory), "image_size", "photo_side",
         "batch_size", "n_images", "n_export", "n_full", "device", "threads", "workers", "albedo", "pitch",
         "model"}; the export figures are medians over the objects.
    """
    predictor = predictor or Predictor.from_checkpoint(checkpoint, device, albedo, pitch, refine)
    size = predictor.setup.render.image_size
    images = _photos(n_images, size)
    with torch_threads(threads):
        net_wall, net_cpu = _network_rate(predictor, images, batch_size)
    photo_side = max(size, round(PHOTO_MARGIN * output_side(resolution, 1 << 30)))
    with tempfile.TemporaryDirectory(prefix="radar-bench-") as tmp:
        photos = _photos(max(n_export, n_full), photo_side)
        for i, image in enumerate(photos[:n_export]):
            write_image(Path(tmp) / "in" / f"bench_{i:03d}.png", image)
        for i, image in enumerate(photos[:n_full]):
            write_image(Path(tmp) / "full" / f"bench_{i:03d}.png", image)
        # one object at a time first, so its peak memory is not the parallel run's
        cost = _export_cost(predictor, Path(tmp) / "in", Path(tmp) / "one", resolution, export)
        options = DerenderOptions(out=Path(tmp) / "out", batch_size=batch_size, workers=workers, threads=threads,
                                  export=export, resolution=resolution, processes=True)
        start = time.perf_counter()
        with PeakMemory() as memory:
            summary = derender([Path(tmp) / "full"], predictor, options, say=lambda line: None)
        full = time.perf_counter() - start
    return {
        "network_images_per_s": round(net_wall, 2),
        "network_images_per_cpu_s": round(net_cpu, 2),
        "full_images_per_s": round(len(summary.done) / full, 3),
        "full_seconds_per_image": round(full / max(len(summary.done), 1), 2),
        "failed": len(summary.failures),
        "full_peak_rss_mib": round(memory.rss, 1),
        "full_peak_pss_mib": round(memory.pss, 1),
        **cost,
        "image_size": size,
        "photo_side": photo_side,
        "batch_size": batch_size,
        "n_images": n_images,
        "n_export": n_export,
        "n_full": n_full,
        "device": str(predictor.device),
        "threads": threads,
        "workers": workers,
        "albedo": predictor.albedo,
        "pitch": predictor.pitch,
        "model": predictor.version,
    }
