"""Environment maps for relighting: a few procedural built-ins and loading user maps (.hdr, .exr, .png, .npy).

All maps follow radar_cli.render.lighting's convention: grey, equirectangular He x We, camera frame, row 0 at the
zenith, column centre = the direction of the camera (light falling on the side of the object that is seen).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from radar_cli.errors import InputError
from radar_cli.render.lighting import GAMMA, env_directions

MAX_ENV_BYTES = 256 * 1024 * 1024  # refuse larger environment files (untrusted input)
TARGET_FRONT_IRRADIANCE = 1.0  # built-ins are scaled so a surface facing the camera gets this diffuse factor
ENV_SUFFIXES = (".hdr", ".exr", ".png", ".jpg", ".jpeg", ".npy")


def _directions(height: int, width: int) -> np.ndarray:
    """He x We x 3 unit light directions of the map's texels (numpy)."""
    dirs, _ = env_directions(height, width)
    return dirs.numpy().reshape(height, width, 3)


def _lobe(dirs: np.ndarray, el_deg: float, az_deg: float, sharpness: float) -> np.ndarray:
    """Spherical Gaussian exp(s (d . xi - 1)) centred at elevation/azimuth (degrees), He x We."""
    el, az = math.radians(el_deg), math.radians(az_deg)
    xi = np.array([math.cos(el) * math.sin(az), math.sin(el), -math.cos(el) * math.cos(az)])
    return np.exp(sharpness * (dirs @ xi - 1.0))


def front_irradiance(env: np.ndarray) -> float:
    """The diffuse factor an He x We map gives a surface facing the camera (its exposure)."""
    h, w = env.shape
    dirs, solid = env_directions(h, w)
    cos = (-dirs[:, 2]).clamp_min(0).numpy()  # normal (0, 0, -1) faces the camera
    return float((env.reshape(-1) * solid.numpy() * cos).sum())


def normalise(env: np.ndarray, target: float = TARGET_FRONT_IRRADIANCE) -> np.ndarray:
    """Scale an He x We map so the diffuse factor of a surface facing the camera equals `target`."""
    return (env * (target / max(front_irradiance(env), 1e-8))).astype(np.float32)


def match_exposure(env: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Scale `env` to the exposure of `reference` (the object's own lighting), so a relit view changes the light's
    direction and spread, not the overall brightness (HDR files come in arbitrary units)."""
    return normalise(env, max(front_irradiance(reference), 1e-8))


def builtin_environments(height: int, width: int) -> dict[str, np.ndarray]:
    """The procedural environments every object is relit under, by name.

    Returns:
        {name: He x We float32 map}: studio (key softbox + fill), sunset (low warm side sun, dim sky), overcast
        (bright sky, no direction), two_lights (small lamps left and right).
    """
    d = _directions(height, width)
    up = np.clip(d[..., 1], 0, None)
    maps = {
        "studio": 1.0 * _lobe(d, 35, -40, 8) + 0.25 * _lobe(d, 10, 50, 6) + 0.03,
        "sunset": 1.0 * _lobe(d, 8, 75, 60) + 0.05 * up + 0.01,
        "overcast": 0.2 + 0.8 * up,
        "two_lights": _lobe(d, 20, -70, 40) + _lobe(d, 20, 70, 40) + 0.01,
    }
    return {name: normalise(env) for name, env in maps.items()}


def _read_float_image(path: Path) -> np.ndarray:
    """H x W (x C) float32 radiance from an HDR/EXR (linear) or an 8-bit image (sRGB-like, linearised)."""
    import cv2

    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            return np.load(path, allow_pickle=False).astype(np.float32)
        except (OSError, ValueError) as e:
            raise InputError(f"{path}: not a readable .npy array ({e})") from None
    if suffix in (".hdr", ".exr"):
        os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")  # OpenCV reads EXR only when asked to
        try:
            arr = cv2.imread(str(path), cv2.IMREAD_ANYDEPTH | cv2.IMREAD_ANYCOLOR)
        except cv2.error as e:
            raise InputError(f"{path}: not a readable {suffix} image ({e})") from None
        if arr is None:
            hint = "" if suffix == ".hdr" or _has_openexr() else " (this OpenCV has no EXR support: use .hdr or .npy)"
            raise InputError(f"{path}: not a readable {suffix} image{hint}")
        return np.asarray(arr, np.float32)
    from radar_cli.fileio import read_image

    return (read_image(path, "RGB").astype(np.float32) / 255.0) ** GAMMA


def _has_openexr() -> bool:
    """Whether the installed OpenCV was built with OpenEXR (the pip wheels of OpenCV 5 are not)."""
    import cv2

    return any("OpenEXR" in line and "YES" in line for line in cv2.getBuildInformation().splitlines())


def load_environment(path: str | Path, height: int, width: int) -> np.ndarray:
    """Read an environment map and resample it to the model's He x We (grey = mean of the channels).

    Args:
        path: .hdr or .exr (linear), .png/.jpg (tone-mapped, linearised with gamma 2.2), or .npy (He' x We' or
            He' x We' x C, linear).
        height, width: He x We to resample to (area averaging keeps the mean radiance).

    Returns:
        He x We float32, >= 0.
    """
    import cv2

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such environment map")
    if path.suffix.lower() not in ENV_SUFFIXES:
        raise InputError(f"{path}: unsupported environment map type (use {', '.join(ENV_SUFFIXES)})")
    if path.stat().st_size > MAX_ENV_BYTES:
        raise InputError(f"{path}: environment map larger than {MAX_ENV_BYTES // 2**20} MB")
    arr = _read_float_image(path)
    if arr.ndim == 3:
        arr = arr.mean(axis=2)
    if arr.ndim != 2 or min(arr.shape) < 1:
        raise InputError(f"{path}: expected an H x W or H x W x C map, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise InputError(f"{path}: environment map has NaN or infinite values")
    arr = np.clip(arr, 0.0, None)
    if arr.shape != (height, width):
        interp = cv2.INTER_AREA if arr.shape[0] > height else cv2.INTER_LINEAR
        arr = cv2.resize(arr, (width, height), interpolation=interp)
    return np.ascontiguousarray(arr, np.float32)


def named_or_file_environment(spec: str | Path, height: int, width: int) -> np.ndarray:
    """A built-in environment by name (studio, sunset, overcast, two_lights) or a map file (load_environment);
    an existing file wins over a name."""
    builtin = builtin_environments(height, width)
    if str(spec) in builtin and not Path(spec).is_file():
        return builtin[str(spec)]
    if not Path(spec).is_file() and not Path(spec).suffix:
        raise InputError(f"{spec}: no such environment (built-in: {', '.join(builtin)}; or a map file)")
    return load_environment(spec, height, width)


def env_name(path: str | Path) -> str:
    """A file-name-safe label for a user environment map (its stem)."""
    from radar_cli.dataset import safe_id

    return safe_id(Path(path).stem)
