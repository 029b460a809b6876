"""`bench_train`: seconds per training step and peak memory of a preset, on random images with elliptic masks."""

from __future__ import annotations

import resource
import time
from pathlib import Path

import torch

from radar_cli.model.config import RunConfig, load_run_config
from radar_cli.model.losses import distance_transform
from radar_cli.train import distributed as D
from radar_cli.train.step import Batch
from radar_cli.train.trainer import build_state, train_step


def _batch(config: RunConfig, batch_size: int, device: torch.device) -> Batch:
    size = config.model.render.image_size
    c = (torch.arange(size) + 0.5) / size * 2 - 1
    yy, xx = torch.meshgrid(c, c, indexing="ij")
    mask = ((xx / 0.45) ** 2 + (yy / 0.8) ** 2 < 1).float().expand(batch_size, size, size).contiguous()
    dt = torch.from_numpy(distance_transform(mask[0].numpy() > 0)).expand_as(mask).contiguous()
    image = torch.rand(batch_size, 3, size, size, generator=torch.Generator().manual_seed(0))
    return Batch(image.to(device), mask.to(device), dt.to(device))


def bench_train(config: RunConfig | str | Path, steps: int = 5, warmup: int = 2, batch_size: int | None = None,
                device: str = "auto", threads: int | None = None) -> dict:
    """Time full training steps (model + D forward, backward, Adam) of a preset.

    Args:
        config: a RunConfig or the path of a pipelines/*.toml preset.
        steps: timed steps (after `warmup` untimed ones).
        batch_size: overrides train.batch_size.
        device: "auto", "cpu" or "cuda".
        threads: torch CPU threads (default: the preset's train.threads, else torch's default).

    Returns:
        {"preset", "device", "batch_size", "image_size", "threads", "sec_per_step", "steps_per_sec",
         "peak_memory_mb", "steps"}: peak memory is the CUDA allocator's peak on GPUs, the process's max RSS on CPU.
    """
    if not isinstance(config, RunConfig):
        config = load_run_config(config)
    dev = D.pick_device(device)
    n_threads = threads if threads is not None else (config.train.threads or torch.get_num_threads())
    with D.torch_threads(n_threads):
        sec, peak = _time_steps(config, batch_size or config.train.batch_size, dev, steps, warmup)
    return {"preset": config.name, "device": str(dev), "batch_size": batch_size or config.train.batch_size,
            "image_size": config.model.render.image_size, "threads": n_threads, "sec_per_step": round(sec, 4),
            "steps_per_sec": round(1 / sec, 3), "peak_memory_mb": round(peak, 1), "steps": steps}


def _time_steps(config: RunConfig, bs: int, dev: torch.device, steps: int, warmup: int) -> tuple[float, float]:
    """Median seconds per step and peak memory in MiB."""
    state = build_state(config, dev)
    batch = _batch(config, bs, dev)
    info = D.DistInfo(0, 1, dev)
    if dev.type == "cuda":
        torch.cuda.reset_peak_memory_stats(dev)
    times = []
    for i in range(warmup + steps):
        tic = time.perf_counter()
        train_step(state, state.model, state.disc, batch, config, info, Path("."))
        if dev.type == "cuda":
            torch.cuda.synchronize(dev)
        if i >= warmup:
            times.append(time.perf_counter() - tic)
    sec = sorted(times)[len(times) // 2]  # median: robust to other processes on a shared machine
    if dev.type == "cuda":
        peak = torch.cuda.max_memory_allocated(dev) / 2**20
    else:
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB on Linux
    return sec, peak
