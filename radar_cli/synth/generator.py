"""`radar synth`: sample, render and write synthetic vases with full ground truth, in parallel and resumably.

Sample `<split>/<index:06d>` is drawn from numpy's SeedSequence([seed, split number, index]) alone, and rendered
single-threaded, so the same settings give the same bytes whatever the number of workers or the order of work.
Each sample is written into a hidden temporary folder that is renamed into place once complete (params.json
last inside it), so a killed run leaves either a finished sample or nothing; a rerun skips finished ones.
"""

from __future__ import annotations

import csv
import io
import json
import multiprocessing
import os
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import torch
from tqdm import tqdm

from radar_cli.allocator import keep_freed_memory
from radar_cli.config import CameraConfig, GeometryConfig, RenderConfig, to_dict
from radar_cli.dataset import IMAGE_FILE, MASK_FILE, SPLITS, sample_images, sample_ref
from radar_cli.errors import ConfigError, InputError, RadarError
from radar_cli.fileio import encode_json, encode_npy, encode_png_fast, remove_stale_temps, write_json, write_text
from radar_cli.synth import layout
from radar_cli.synth.lighting import bake_env, sample_lobes
from radar_cli.synth.render import env_preview, render_sample
from radar_cli.synth.shapes import sample_shape
from radar_cli.synth.textures import augment, image_texture, list_texture_images, procedural_texture

# What the written samples look like, recorded in synth.json and every params.json; raised whenever the same seed
# would draw different pixels (tests/synth/test_pinned_output.py pins them; docs/formats.md lists the versions).
FORMAT_VERSION = 2
DEFAULT_SHADING = 32  # rows (and frontal-third columns) of the lighting grid when shading_size = 0
MAX_SIZE = 1024
PARTIAL_DIR = ".partial"  # samples being written; removed at the start of every run


@dataclass(frozen=True)
class SynthConfig:
    """Settings of a synthetic set; stored in DATA/synth.json so that a resumed run cannot mix settings."""

    size: int = 256
    """Image side in pixels."""
    seed: int = 0
    tex_size: int = 0
    """Rows (and frontal-third columns) of the albedo map; 0 = the image size (the 360 deg map is 3x wider)."""
    shading_size: int = 0
    """Side of the frontal-third grid the lighting is evaluated on; 0 = DEFAULT_SHADING (or size // 2 if smaller):
    32 x 96 over the full turn, the paper's vertex grid (how little finer grids change: docs/data.md)."""
    background: float = 1.0
    """Grey level of the plain background (1 = white, like museum photographs)."""
    random_roll: bool = False
    random_translation: bool = False
    textures: str = ""
    """Folder of texture images to use instead of procedural textures ("" = procedural)."""

    def render_config(self) -> RenderConfig:
        tex = self.tex_size or self.size
        shading = self.shading_size or max(8, min(DEFAULT_SHADING, self.size // 2))
        return RenderConfig(image_size=self.size, tex_height=tex, tex_width=tex, shading_height=shading,
                            shading_width=shading)

    def grids(self) -> dict[str, list[int]]:
        """The effective [rows, columns over the full turn] of the albedo map and of the lighting grid."""
        render = self.render_config()
        return {"tex": [render.tex_height, 3 * render.tex_width],
                "shading": [render.shading_height, 3 * render.shading_width]}

    def check(self) -> None:
        """Raise ConfigError on values outside the supported ranges."""
        if not 16 <= self.size <= MAX_SIZE:
            raise ConfigError(f"size must be in [16, {MAX_SIZE}], got {self.size}")
        if self.tex_size and not 8 <= self.tex_size <= MAX_SIZE:
            raise ConfigError(f"tex_size must be 0 or in [8, {MAX_SIZE}], got {self.tex_size}")
        if self.shading_size and not 4 <= self.shading_size <= 256:
            raise ConfigError(f"shading_size must be 0 or in [4, 256], got {self.shading_size}")
        if not 0.0 <= self.background <= 1.0:
            raise ConfigError(f"background must be in [0, 1], got {self.background}")
        if self.seed < 0:
            raise ConfigError(f"seed must be >= 0, got {self.seed}")


@dataclass
class SynthSummary:
    """What a `radar synth` run did."""

    written: int = 0
    skipped: int = 0
    failed: list[tuple[str, str, str]] = field(default_factory=list)  # (split, id, problem)
    seconds: float = 0.0
    first_seconds: float = 0.0  # wall time until the first sample came back: the pool's start-up + one sample
    workers: int = 1

    @property
    def rate(self) -> float:
        """Samples written per second of wall time."""
        return self.written / self.seconds if self.seconds > 0 else 0.0

    @property
    def steady_rate(self) -> float:
        """Samples per second once every worker is running: the samples after each worker's first over the time
        after the first came back (a long run's rate; start-up weighs on `rate` in short ones)."""
        later = self.written + len(self.failed) - self.workers
        span = self.seconds - self.first_seconds
        return later / span if later > 0 and span > 0 else self.rate


def sample_id(index: int) -> str:
    return f"{index:06d}"


def sample_rng(seed: int, split: str, index: int) -> np.random.Generator:
    """The one random stream of a sample."""
    return np.random.default_rng(np.random.SeedSequence([seed, SPLITS.index(split) if split in SPLITS else 99, index]))


def make_sample(cfg: SynthConfig, split: str, index: int, textures: list[Path] | None) -> tuple[dict, dict]:
    """Sample and render one vase.

    Returns:
        (arrays to write keyed by file name, params for params.json).
    """
    rng = sample_rng(cfg.seed, split, index)
    render = cfg.render_config()
    geometry, camera = GeometryConfig(), CameraConfig()
    shape = sample_shape(rng, geometry, camera, cfg.random_roll, cfg.random_translation)
    alpha, rho = float(rng.uniform(1.0, 196.0)), float(rng.uniform(0.1, 1.0))
    lobes = sample_lobes(rng)
    env = bake_env(lobes, render.env_height, render.env_width)
    tex_h, tex_w = render.tex_height, 3 * render.tex_width
    texture_info: dict[str, Any]
    if textures:
        source = textures[int(rng.integers(len(textures)))]
        raw, texture_info = image_texture(source, rng, tex_h, tex_w), {"source": source.name}
    else:
        raw, texture_info = procedural_texture(rng, tex_h, tex_w), {"source": "procedural"}
    albedo, texture_info["augment"] = augment(raw, rng)
    out = render_sample(shape.radius, shape.height, shape.pose, albedo, env, alpha, rho, cfg.size, render,
                        camera, cfg.background)
    files = {
        layout.MASK_FRONT_FILE: out.mask_front,
        layout.ALBEDO_FILE: albedo,
        layout.ALBEDO_RENDERED_FILE: out.albedo_rendered,
        layout.NORMAL_RENDERED_FILE: (out.normal + 1.0) * 0.5,
        layout.DEPTH_FILE: out.depth.astype(np.float32),
        layout.DIFFUSE_FILE: out.diffuse.astype(np.float16),
        layout.SPECULAR_FILE: out.specular.astype(np.float16),
        layout.ENV_MAP_FILE: env.astype(np.float32),
        layout.ENV_PREVIEW_FILE: env_preview(env, render.gamma),
        IMAGE_FILE: out.image,
        MASK_FILE: out.mask,
    }
    params = {
        "radius": [round(float(x), 6) for x in shape.radius], "height": round(shape.height, 6),
        "pose": [round(float(x), 6) for x in shape.pose], "alpha": round(alpha, 6), "rho": round(rho, 6),
        "lobes": [lobe.as_dict() for lobe in lobes], "curve": shape.curve, "texture": texture_info,
        "image_size": cfg.size, "format_version": FORMAT_VERSION,
    }
    return files, params


def write_sample_folder(root: Path, split: str, sid: str, files: dict, params: dict) -> None:
    """Write one sample into a temporary folder under DATA/.partial, then rename it into place, so readers
    of the split never see half a sample. The folder is the unit of atomicity: its files are written directly,
    without a temporary file and rename each (that cost 3-10 ms of a sample's ~25 ms of writing)."""
    final = sample_ref(root, split, sid).folder
    tmp = root / PARTIAL_DIR / f"{split}-{sid}-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    files = {**files, **sample_images(files[IMAGE_FILE], files[MASK_FILE])}  # the mask as the dataset stores it
    for name, arr in files.items():
        if name.endswith(".npy"):
            data = encode_npy(arr)
        else:
            data = encode_png_fast(arr.astype(np.uint8) * 255 if arr.dtype == bool else arr)
        (tmp / name).write_bytes(data)
    (tmp / layout.PARAMS_FILE).write_bytes(encode_json(params))
    if final.exists():  # an unfinished folder from an older run
        shutil.rmtree(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    os.replace(tmp, final)


def is_done(root: Path, split: str, index: int) -> bool:
    return (root / split / sample_id(index) / layout.PARAMS_FILE).is_file()


def _work(job: tuple[SynthConfig, str, str, int, list[Path] | None]) -> tuple[str, str, str]:
    """Pool task: make and write one sample; returns (split, id, problem or "")."""
    cfg, root, split, index, textures = job
    sid = sample_id(index)
    try:
        files, params = make_sample(cfg, split, index, textures)
        write_sample_folder(Path(root), split, sid, files, params)
        return split, sid, ""
    except (RadarError, OSError, ValueError) as e:
        return split, sid, f"{type(e).__name__}: {e}"


def _init_worker() -> None:
    """One thread per worker for torch and OpenCV: the pool is the parallelism (more threads oversubscribe);
    freed memory kept for reuse (a fresh interpreter does not run the CLI's entry point)."""
    keep_freed_memory()
    torch.set_num_threads(1)
    cv2.setNumThreads(1)


def _check_settings(root: Path, cfg: SynthConfig) -> None:
    """Write DATA/synth.json, or check that an existing one matches (a resumed run must not mix settings)."""
    path = root / layout.SETTINGS_FILE
    # the effective grids too, so a changed default cannot mix two kinds of sample
    settings = {"format_version": FORMAT_VERSION, **to_dict(cfg), "effective": cfg.grids()}
    if path.is_file():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as e:
            raise InputError(f"{path}: unreadable settings file ({e})") from None
        if old != settings:
            diff = sorted(k for k in set(old) | set(settings) if old.get(k) != settings.get(k))
            raise ConfigError(f"{path}: {root} was made with other settings ({', '.join(diff)}); use another --out")
    else:
        write_json(path, settings)


def _clean_partial(root: Path) -> None:
    """Remove the temporary folders and files left by a killed run."""
    shutil.rmtree(root / PARTIAL_DIR, ignore_errors=True)
    remove_stale_temps(root)


def generate(out: str | Path, splits: dict[str, int], cfg: SynthConfig = SynthConfig(), workers: int = 1,
             progress: bool = True) -> SynthSummary:
    """Generate (or finish) a synthetic set.

    Args:
        out: dataset root; samples go to out/<split>/<index:06d>/.
        splits: samples per split, e.g. {"train": 4115, "test": 460}.
        cfg: settings. workers: processes (1 = in this process).

    Returns:
        SynthSummary; failures are also written to out/failures.csv.
    """
    cfg.check()
    root = Path(out)
    textures = list_texture_images(cfg.textures) if cfg.textures else None
    if textures:
        textures = [p.resolve() for p in textures]
    root.mkdir(parents=True, exist_ok=True)
    _clean_partial(root)
    _check_settings(root, cfg)
    summary = SynthSummary(workers=max(1, workers))
    jobs = []
    for split, n in splits.items():
        for index in range(n):
            if is_done(root, split, index):
                summary.skipped += 1
            else:
                jobs.append((cfg, str(root), split, index, textures))
    start = time.perf_counter()
    bar = tqdm(total=len(jobs), desc="synth", unit="vase", disable=not progress)
    for split, sid, problem in _run(jobs, workers):
        if not summary.first_seconds:
            summary.first_seconds = time.perf_counter() - start
        if problem:
            summary.failed.append((split, sid, problem))
            tqdm.write(f"{root / split / sid}: {problem}", file=sys.stderr)
        else:
            summary.written += 1
        bar.update(1)
    bar.close()
    summary.seconds = time.perf_counter() - start
    _clean_partial(root)
    _write_failures(root, summary.failed)
    return summary


def _run(jobs: list, workers: int):
    """Yield job results, in this process (workers <= 1) or from a spawn pool."""
    if workers <= 1 or len(jobs) <= 1:
        threads = torch.get_num_threads()
        torch.set_num_threads(1)  # the same arithmetic as in a worker: same bytes
        try:
            for job in jobs:
                yield _work(job)
        finally:
            torch.set_num_threads(threads)
        return
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(workers, initializer=_init_worker) as pool:
        yield from pool.imap_unordered(_work, jobs, chunksize=1)


def _write_failures(root: Path, failed: list[tuple[str, str, str]]) -> None:
    path = root / layout.FAILURES_FILE
    if not failed:
        path.unlink(missing_ok=True)
        return
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(["split", "id", "problem"])
    writer.writerows(sorted(failed))
    write_text(path, buf.getvalue())
