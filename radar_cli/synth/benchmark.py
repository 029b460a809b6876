"""Throughput of `radar synth`: samples per second written by the worker pool into a
temporary folder, and, in this process, the split of one sample's time between making it (texture, lighting,
rendering every map) and writing its files."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import torch

from radar_cli.synth.generator import SynthConfig, generate, make_sample, write_sample_folder

STAGE_SAMPLES = 8  # samples timed one by one for the stage split


def bench_synth(size: int, n: int, workers: int, shading_size: int = 0, seed: int = 0) -> dict:
    """Generate n test-split samples with `workers` processes and time them.

    Returns:
        JSON-ready dict: samples_per_sec (wall, pool start-up included), startup_sec (until the first sample
        came back), steady_samples_per_sec (after it: a long run's rate), sec_per_sample for make and write
        (single process, one thread, the median of STAGE_SAMPLES samples), and the settings.
    """
    cfg = SynthConfig(size=size, seed=seed, shading_size=shading_size)
    with tempfile.TemporaryDirectory(prefix="radar-bench-synth-") as tmp:
        summary = generate(Path(tmp) / "pool", {"test": n}, cfg, workers=workers, progress=False)
        make_s, write_s = _stage_times(cfg, Path(tmp) / "stages")
    return {
        "size": size,
        "samples": n,
        "workers": workers,
        "shading_grid": cfg.grids()["shading"],
        "samples_per_sec": round(summary.rate, 2),
        "startup_sec": round(summary.first_seconds, 2),
        "steady_samples_per_sec": round(summary.steady_rate, 2),
        "failed": len(summary.failed),
        "sec_per_sample_make": round(make_s, 4),
        "sec_per_sample_write": round(write_s, 4),
    }


def _stage_times(cfg: SynthConfig, root: Path) -> tuple[float, float]:
    """Median seconds to make and to write one sample, in this process with one torch thread."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    make, write = [], []
    try:
        for index in range(STAGE_SAMPLES):
            t0 = time.perf_counter()
            files, params = make_sample(cfg, "test", index, None)
            t1 = time.perf_counter()
            write_sample_folder(root, "test", f"{index:06d}", files, params)
            make.append(t1 - t0)
            write.append(time.perf_counter() - t1)
    finally:
        torch.set_num_threads(threads)
    return sorted(make)[len(make) // 2], sorted(write)[len(write) // 2]
