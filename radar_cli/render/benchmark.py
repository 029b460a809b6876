"""Speed and memory benchmark of the renderer: silhouette + shading + frontal texture render + unwrap, forward and
backward, for a batch of random vases at several image sizes (`radar bench render`)."""

from __future__ import annotations

import math
import resource
import time
from dataclasses import dataclass

import torch

from radar_cli.config import CameraConfig, RenderConfig
from radar_cli.errors import InputError
from radar_cli.render.material import Material
from radar_cli.render.raycast import cast_rays
from radar_cli.render.scene import render_front, shade
from radar_cli.render.texture import unwrap
from radar_cli.sor.solid import Solid


@dataclass(frozen=True)
class BenchResult:
    """Timing of one image size: median seconds of forward+backward and the peak memory it needed."""

    size: int
    batch: int
    seconds: float
    seconds_forward: float
    cpu_seconds: float  # process CPU time of one forward+backward (all threads)
    peak_mib: float
    memory: str  # what peak_mib measures


def resolve_device(name: str) -> torch.device:
    """'cpu', 'cuda' or 'auto' (cuda when available) -> torch.device."""
    if name == "auto":
        name = "cuda" if torch.cuda.is_available() else "cpu"
    if name not in ("cpu", "cuda"):
        raise InputError(f"--device: expected cpu, cuda or auto, got {name!r}")
    if name == "cuda" and not torch.cuda.is_available():
        raise InputError("--device cuda: no CUDA device is available")
    return torch.device(name)


def random_inputs(batch: int, size: int, render: RenderConfig, device: torch.device, seed: int = 0) -> dict:
    """Vase-like profiles, poses in the paper's ranges, albedo, environment map and material; all leaves."""
    g = torch.Generator().manual_seed(seed)
    y = torch.linspace(0, 1, 32)[None]
    phase = torch.rand(batch, 1, generator=g) * math.tau
    radius = 0.35 + 0.2 * torch.sin(3 * y + phase) * torch.rand(batch, 1, generator=g)
    tex = (size, size)
    inputs = {
        "radius": radius,
        "height": 0.5 + 0.45 * torch.rand(batch, generator=g),
        "pose": (torch.rand(batch, 4, generator=g) * torch.tensor([20.0, 20.0, 0.4, 0.4])
                 - torch.tensor([0, 10, 0.2, 0.2])),
        "albedo": torch.rand(batch, 3, *tex, generator=g),
        "env": torch.rand(batch, render.env_height, render.env_width, generator=g),
        "alpha": 1 + 195 * torch.rand(batch, generator=g),
        "rho": 0.1 + 0.9 * torch.rand(batch, generator=g),
        "image": torch.rand(batch, 3, size, size, generator=g),
    }
    return {k: v.to(device).requires_grad_(k != "image") for k, v in inputs.items()}


def render_step(x: dict, size: int, render: RenderConfig, camera: CameraConfig) -> torch.Tensor:
    """One training-like render: soft silhouette, shaded frontal texture drawn into the image, unwrap of the
    input image. Returns a scalar loss touching every output."""
    solid = Solid(x["radius"], x["height"], x["pose"])
    hits = cast_rays(solid, size, camera, render.sil_sigma_px)
    shading = shade(solid, Material(x["albedo"], x["env"], x["alpha"], x["rho"]), render, camera)
    image, mask = render_front(hits, shading.texture)
    tex = unwrap(solid, x["image"], tuple(x["albedo"].shape[-2:]), camera)
    return (hits.sil - 0.5).square().mean() + ((image - x["image"]) * mask).abs().mean() + tex.mean()


def _sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize()


def bench_config(size: int) -> RenderConfig:
    """The render settings benchmarked at one image size: texture = image size, lighting grid = size / 4 (the
    paper's 64 x 64 at 256 px; the repository's CPU pipelines use 16 x 16 at 64 px)."""
    grid = max(4, size // 4)
    return RenderConfig(image_size=size, tex_height=size, tex_width=size, shading_height=grid, shading_width=grid)


def bench_size(size: int, batch: int, device: torch.device, repeats: int = 3,
               camera: CameraConfig = CameraConfig()) -> BenchResult:
    """Median forward and forward+backward time of render_step at one size, after one warm-up run."""
    render = bench_config(size)
    x = random_inputs(batch, size, render, device)
    render_step(x, size, render, camera).backward()  # warm-up (allocator, first-call overheads)
    if device.type == "cuda":
        torch.cuda.reset_peak_memory_stats(device)
    fwd, total, cpu = [], [], []
    for _ in range(repeats):
        _sync(device)
        c0 = time.process_time()
        t0 = time.perf_counter()
        loss = render_step(x, size, render, camera)
        _sync(device)
        t1 = time.perf_counter()
        loss.backward()
        _sync(device)
        fwd.append(t1 - t0)
        total.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    if device.type == "cuda":
        peak, what = torch.cuda.max_memory_allocated(device) / 2**20, "cuda max_memory_allocated"
    else:
        peak, what = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, "process peak RSS so far (ru_maxrss)"
    return BenchResult(size, batch, _median(total), _median(fwd), _median(cpu), round(peak, 1), what)


def _median(values: list[float]) -> float:
    return round(sorted(values)[len(values) // 2], 4)


def run_benchmark(sizes: list[int], batch: int, device_name: str = "auto", repeats: int = 3,
                  threads: int = 0) -> dict:
    """Benchmark every size in increasing order; a JSON-ready dict."""
    if batch < 1 or repeats < 1 or not sizes or min(sizes) < 8 or max(sizes) > 2048:
        raise InputError(f"--batch and --repeats must be >= 1 and --sizes in [8, 2048], got batch={batch}, "
                         f"repeats={repeats}, sizes={sizes}")
    device = resolve_device(device_name)
    if threads > 0:
        torch.set_num_threads(threads)
    torch.manual_seed(0)
    results = [bench_size(s, batch, device, repeats) for s in sorted(sizes)]
    return {
        "device": str(device),
        "threads": torch.get_num_threads(),
        "torch": torch.__version__,
        "pipeline": "cast_rays + shade (lighting grid size/4, env 16x48) + render_front + unwrap (texture = size), "
                    "forward+backward",
        "results": [r.__dict__ for r in results],
    }
