"""Typed configuration: frozen dataclasses with the paper's values (supplementary Table 4) and strict TOML loading."""

from __future__ import annotations

import dataclasses
import math
import sys
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, TypeVar, get_args, get_origin, get_type_hints

from radar_cli.errors import ConfigError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

T = TypeVar("T")


@dataclass(frozen=True)
class CameraConfig:
    """Fixed pinhole camera at the origin looking down +z (paper Sec. 4.1)."""

    fov_deg: float = 10.0
    """Full field of view in degrees, the same horizontally and vertically (square images)."""
    distance: float = 5.0
    """Distance from the camera to the object's centre along +z."""

    @property
    def r_max(self) -> float:
        """Half-extent of the view at the object's distance: the unit of all object-space sizes."""
        return math.tan(math.radians(self.fov_deg) / 2.0) * self.distance


@dataclass(frozen=True)
class GeometryConfig:
    """Surface-of-revolution parameterisation and the ranges the networks' outputs are rescaled to."""

    n_rows: int = 32
    """L: samples of the radius column along the axis."""
    n_cols: int = 96
    """K: rotation angles of the exported vertex grid."""
    radius_range: tuple[float, float] = (0.05, 0.9)
    """Radius, as a fraction of CameraConfig.r_max."""
    height_range: tuple[float, float] = (0.5, 0.95)
    """Half-height h of the axis, as a fraction of r_max: the profile spans y in [-h, h] * r_max."""
    pitch_range: tuple[float, float] = (0.0, 20.0)
    """Pitch (camera elevation) in degrees; positive shows the vase's mouth."""
    roll_range: tuple[float, float] = (-10.0, 10.0)
    """Roll about the viewing axis in degrees."""
    trans_range: tuple[float, float] = (-0.2, 0.2)
    """Translation in x and y, as a fraction of r_max."""


@dataclass(frozen=True)
class RenderConfig:
    """Renderer settings shared by training, synthesis and de-rendering."""

    image_size: int = 256
    """Square image side in pixels."""
    tex_height: int = 256
    """Rows of the unwrapped texture map."""
    tex_width: int = 256
    """Columns of the frontal third of the unwrapped texture map (the whole 360 deg map is 3x wider)."""
    env_height: int = 16
    env_width: int = 48
    shading_height: int = 64
    """Rows of the grid the environment lighting is evaluated on before bilinear upsampling to the texture."""
    shading_width: int = 64
    """Columns of that grid for the frontal third."""
    sil_sigma_px: float = 1.0
    """Softness of the soft silhouette, in pixels."""
    inside_dim: float = 0.5
    """Brightness factor for the inside of an open vase seen through its mouth."""
    gamma: float = 2.2


def _convert(value: Any, tp: Any, where: str) -> Any:
    """Convert a TOML value to the annotated type, raising ConfigError on mismatch."""
    origin = get_origin(tp)
    if isinstance(tp, type) and dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise ConfigError(f"{where}: expected a table, got {type(value).__name__}")
        return from_dict(tp, value, where)
    if origin is Literal:
        if value not in get_args(tp):
            raise ConfigError(f"{where}: expected one of {get_args(tp)}, got {value!r}")
        return value
    if origin in (typing.Union, types.UnionType):
        args = get_args(tp)
        if value is None and type(None) in args:
            return None
        errors = []
        for arg in args:
            if arg is type(None):
                continue
            try:
                return _convert(value, arg, where)
            except ConfigError as e:
                errors.append(str(e))
        raise ConfigError(errors[0] if errors else f"{where}: bad value {value!r}")
    if origin is tuple:
        args = get_args(tp)
        if not isinstance(value, (list, tuple)) or len(value) != len(args):
            raise ConfigError(f"{where}: expected a list of {len(args)} values, got {value!r}")
        return tuple(_convert(v, a, f"{where}[{i}]") for i, (v, a) in enumerate(zip(value, args)))
    if origin is list:
        (arg,) = get_args(tp)
        if not isinstance(value, list):
            raise ConfigError(f"{where}: expected a list, got {value!r}")
        return [_convert(v, arg, f"{where}[{i}]") for i, v in enumerate(value)]
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{where}: expected a number, got {value!r}")
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{where}: expected an integer, got {value!r}")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{where}: expected true or false, got {value!r}")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where}: expected a string, got {value!r}")
        return value
    raise ConfigError(f"{where}: unsupported type {tp}")  # pragma: no cover


def from_dict(cls: type[T], data: dict[str, Any], where: str = "config") -> T:
    """Build dataclass `cls` from a dict, rejecting unknown keys and wrong types; missing keys take defaults."""
    hints = get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    unknown = sorted(set(data) - names)
    if unknown:
        raise ConfigError(f"{where}: unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(names))})")
    kwargs = {k: _convert(v, hints[k], f"{where}.{k}") for k, v in data.items()}
    return cls(**kwargs)


def to_dict(obj: Any) -> dict[str, Any]:
    """A dataclass as a plain dict (tuples become lists), ready for TOML or JSON."""
    def plain(v: Any) -> Any:
        if isinstance(v, tuple):
            return [plain(x) for x in v]
        if isinstance(v, list):
            return [plain(x) for x in v]
        if isinstance(v, dict):
            return {k: plain(x) for k, x in v.items()}
        return v

    return plain(dataclasses.asdict(obj))


BASE_KEY = "base"
"""Top-level key of a preset naming the preset it builds on, relative to the preset's own folder."""


def _read_table(path: Path) -> dict[str, Any]:
    """One TOML file as a dict; ConfigError naming the file when it is missing or malformed."""
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such config file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ConfigError(f"{path}: not valid TOML ({e})") from None


def deep_merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    """`base` with `over`'s values on top: tables merge key by key, any other value (lists too) replaces."""
    merged = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = deep_merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _resolve(cls: type, path: Path, chain: tuple[Path, ...]) -> dict[str, Any]:
    """The dict of `path` merged over its `base` chain; each file is checked against `cls` on its own first."""
    data = _read_table(path)
    base = data.pop(BASE_KEY, None)
    from_dict(cls, data, where=str(path))  # unknown keys and wrong types, named in the file that holds them
    if base is None:
        return data
    if not isinstance(base, str):
        raise ConfigError(f"{path}.{BASE_KEY}: expected a file name, got {base!r}")
    base_path = (path.parent / base).resolve()
    if not base_path.is_file():
        raise ConfigError(f"{path}.{BASE_KEY}: no such config file {base_path}")
    if base_path in chain:
        loop = " -> ".join(str(p) for p in (*chain, base_path))
        raise ConfigError(f"{path}: base presets form a cycle ({loop})")
    return deep_merge(_resolve(cls, base_path, (*chain, base_path)), data)


def load_toml(cls: type[T], path: str | Path) -> T:
    """Load dataclass `cls` from a TOML file, strictly.

    A top-level `base = "other.toml"` (relative to the file's folder) loads that file first and lays this one's
    values over it (tables merged key by key); bases may have bases of their own, a cycle is an error. Every file
    in the chain is held to `cls`'s keys and types.
    """
    path = Path(path)
    data = _resolve(cls, path, (path.resolve(),))
    return from_dict(cls, data, where=str(path))


__all__ = ["CameraConfig", "GeometryConfig", "RenderConfig", "from_dict", "to_dict", "load_toml", "deep_merge",
           "field"]
