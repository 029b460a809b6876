"""Read one synthetic sample's ground truth and one de-rendering result, with one-line errors naming the file."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from radar_cli.dataset import IMAGE_FILE, MASK_FILE
from radar_cli.errors import InputError
from radar_cli.evaluate.metrics import decode_normals
from radar_cli.fileio import number, read_image, read_json
from radar_cli.results import ResultPaths
from radar_cli.synth import layout


@dataclass(frozen=True)
class Truth:
    """Ground truth of one sample: images H x W (x 3) float in [0, 1], normals H x W x 3, env He x We."""

    image: np.ndarray
    mask: np.ndarray
    albedo_rendered: np.ndarray
    normal: np.ndarray
    env: np.ndarray
    pitch: float
    alpha: float
    rho: float


@dataclass(frozen=True)
class Prediction:
    """What `radar eval` reads from one result folder (see radar_cli.results)."""

    mask_front: np.ndarray
    albedo_rendered: np.ndarray
    normal: np.ndarray
    env: np.ndarray
    pitch: float
    alpha: float
    rho: float


def read_env(path: Path) -> np.ndarray:
    """He x We float environment map from .npy (no pickles); InputError naming the file otherwise."""
    try:
        env = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except (OSError, ValueError, EOFError) as e:
        raise InputError(f"{path}: not a readable .npy array ({e})") from None
    if env.ndim != 2 or not np.issubdtype(env.dtype, np.number) or env.size > 1_000_000:
        raise InputError(f"{path}: expected an He x We numeric map, got {env.dtype} {env.shape}")
    if not np.isfinite(env).all():
        raise InputError(f"{path}: contains NaN or Inf")
    return env.astype(np.float64)


def _rgb(path: Path) -> np.ndarray:
    return read_image(path, "RGB").astype(np.float64) / 255.0


def _mask(path: Path) -> np.ndarray:
    return read_image(path, "L") > 127


def load_truth(folder: Path) -> Truth:
    """Ground truth from a sample folder written by `radar synth`."""
    params_path = folder / layout.PARAMS_FILE
    params = read_json(params_path)
    truth = Truth(
        image=_rgb(folder / IMAGE_FILE),
        mask=_mask(folder / MASK_FILE),
        albedo_rendered=_rgb(folder / layout.ALBEDO_RENDERED_FILE),
        normal=decode_normals(read_image(folder / layout.NORMAL_RENDERED_FILE, "RGB")),
        env=read_env(folder / layout.ENV_MAP_FILE),
        pitch=number(params, "pose", params_path, 0),
        alpha=number(params, "alpha", params_path),
        rho=number(params, "rho", params_path),
    )
    _same_size(folder, truth.image, truth.mask, truth.albedo_rendered, truth.normal)
    return truth


def load_prediction(paths: ResultPaths) -> Prediction:
    """The files `radar eval` needs from one result folder."""
    material = read_json(paths.material)
    pred = Prediction(
        mask_front=_mask(paths.mask_front),
        albedo_rendered=_rgb(paths.albedo_rendered),
        normal=decode_normals(read_image(paths.normal_rendered, "RGB")),
        env=read_env(paths.env_map),
        pitch=number(material, "pitch", paths.material),
        alpha=number(material, "alpha", paths.material),
        rho=number(material, "rho", paths.material),
    )
    _same_size(paths.folder, pred.mask_front, pred.albedo_rendered, pred.normal)
    return pred


def _same_size(folder: Path, *maps: np.ndarray) -> None:
    sizes = {m.shape[:2] for m in maps}
    if len(sizes) > 1:
        raise InputError(f"{folder}: image-space maps differ in size {sorted(sizes)}")
