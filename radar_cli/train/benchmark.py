"""`bench_train`: seconds per training step and peak memory of a preset, on random images with elliptic masks."""

from __future__ import annotations

import resource
import time
from pathlib import Path
from typing import Callable

import torch

from radar_cli import distributed as D
from radar_cli.fileio import write_text
from radar_cli.model.config import RunConfig, load_run_config
from radar_cli.model.losses import distance_transform
from radar_cli.threads import torch_threads
from radar_cli.train.step import Batch
from radar_cli.train.trainer import build_state, train_step


def elliptic_batch(config: RunConfig, batch_size: int, device: torch.device) -> Batch:
    """Random B x 3 x S x S images with one elliptic B x S x S mask (and its distance transform), and B pitch
    labels of 10 deg when the preset self-trains on pitch: the work of a training step without a dataset."""
    size = config.model.render.image_size
    c = (torch.arange(size) + 0.5) / size * 2 - 1
    yy, xx = torch.meshgrid(c, c, indexing="ij")
    mask = ((xx / 0.45) ** 2 + (yy / 0.8) ** 2 < 1).float().expand(batch_size, size, size).contiguous()
    dt = torch.from_numpy(distance_transform(mask[0].numpy() > 0)).expand_as(mask).contiguous()
    image = torch.rand(batch_size, 3, size, size, generator=torch.Generator().manual_seed(0))
    labels = torch.full((batch_size,), 10.0, device=device) if config.loss.pitch_label_weight > 0 else None
    return Batch(image.to(device), mask.to(device), dt.to(device), pitch_label=labels)


def bench_train(config: RunConfig | str | Path, steps: int = 5, warmup: int = 2, batch_size: int | None = None,
                device: str = "auto", threads: int | None = None, profile: str | Path | None = None) -> dict:
    """Time full training steps (model + D forward, backward, Adam) of a preset.

    Args:
        config: a RunConfig, the path of a pipelines/**/*.toml preset, or a model or checkpoint file
            (.safetensors: the configuration stored in it).
        steps: timed steps (after `warmup` untimed ones).
        batch_size: overrides train.batch_size.
        device: "auto", "cpu" or "cuda".
        threads: torch CPU threads (default: the preset's train.threads, else torch's default).
        profile: also profile 3 more steps with torch.profiler and write its operator tables (by own CPU time, and
            on a GPU by own GPU time with the kernel launches and synchronisations per step) to this text file.

    Returns:
        {"preset", "device", "batch_size", "image_size", "threads", "sec_per_step", "steps_per_sec",
         "peak_memory_mb", "steps"}: peak memory is the CUDA allocator's peak on GPUs, the process's max RSS on CPU.
    """
    if isinstance(config, (str, Path)) and Path(config).suffix == ".safetensors":
        from radar_cli.model.weights import read_checkpoint

        config = read_checkpoint(config)[2]
    elif not isinstance(config, RunConfig):
        config = load_run_config(config)
    dev = D.pick_device(device)
    n_threads = threads if threads is not None else (config.train.threads or torch.get_num_threads())
    with torch_threads(n_threads):
        sec, peak = _time_steps(config, batch_size or config.train.batch_size, dev, steps, warmup, profile)
    return {"preset": config.name, "device": str(dev), "batch_size": batch_size or config.train.batch_size,
            "image_size": config.model.render.image_size, "threads": n_threads, "sec_per_step": round(sec, 4),
            "steps_per_sec": round(1 / sec, 3), "peak_memory_mb": round(peak, 1), "steps": steps}


def _time_steps(config: RunConfig, bs: int, dev: torch.device, steps: int, warmup: int,
                profile: str | Path | None) -> tuple[float, float]:
    """Median seconds per step and peak memory in MiB (and the profile, when asked, after the timed steps)."""
    state = build_state(config, dev)
    batch = elliptic_batch(config, bs, dev)
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
    if profile is not None:
        _write_profile(Path(profile), lambda: train_step(state, state.model, state.disc, batch, config, info,
                                                         Path(".")), dev)
    return sec, peak


PROFILED_STEPS = 3


def _write_profile(path: Path, step: Callable[[], object], dev: torch.device) -> None:
    """torch.profiler over PROFILED_STEPS calls of `step`: operator tables as text, written atomically."""
    from torch.profiler import ProfilerActivity, profile

    activities = [ProfilerActivity.CPU] + ([ProfilerActivity.CUDA] if dev.type == "cuda" else [])
    with profile(activities=activities) as prof:
        for _ in range(PROFILED_STEPS):
            step()
        if dev.type == "cuda":
            torch.cuda.synchronize(dev)
    table = prof.key_averages()
    text = f"# torch.profiler, {PROFILED_STEPS} training steps on {dev}\n"
    if dev.type == "cuda":
        launches = sum(e.count for e in table if e.key in ("cudaLaunchKernel", "cudaLaunchKernelExC"))
        syncs = sum(e.count for e in table if e.key == "cudaStreamSynchronize")
        text += (f"# per step: {launches / PROFILED_STEPS:.0f} kernel launches, {syncs / PROFILED_STEPS:.0f} stream "
                 f"synchronisations\n\n# by own GPU time\n"
                 + table.table(sort_by="self_cuda_time_total", row_limit=40, max_name_column_width=60))
    text += "\n# by own CPU time\n" + table.table(sort_by="self_cpu_time_total", row_limit=30, max_name_column_width=60)
    write_text(path, text)
