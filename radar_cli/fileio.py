"""Atomic file writes (temp file + rename) and safe image reading: the only way radar writes results."""

from __future__ import annotations

import io
import json
import math
import os
import re
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np
from PIL import Image

from radar_cli.errors import InputError

MAX_IMAGE_PIXELS = 100_000_000  # decompression-bomb limit for untrusted images
Image.MAX_IMAGE_PIXELS = MAX_IMAGE_PIXELS


TEMP_MARK = ".tmp"  # atomic_path's temporary files are named .<name>.<random>.tmp<suffix>


def umask() -> int:
    """The process's file-creation mask (read without changing it where Linux allows)."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def ordinary_file_mode() -> int:
    """The mode an ordinary `open(path, "w")` gives a new file under the current umask (0644 under 022)."""
    return 0o666 & ~umask()


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to `path`; on success rename it over `path`, on failure remove it.

    The file gets the mode an ordinary write would give it (mkstemp makes it 0600, unreadable by a web server)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=TEMP_MARK + path.suffix)
    os.fchmod(fd, ordinary_file_mode())
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        os.chmod(tmp_path, ordinary_file_mode())  # a writer that replaced the file (e.g. OpenCV) set its own
        os.replace(tmp_path, path)
    except BaseException:
        tmp_path.unlink(missing_ok=True)
        raise


def is_temp_name(name: str) -> bool:
    """True for the names atomic_path gives its temporary files: .<name>.<8 random characters>.tmp[.<suffix>]."""
    return _TEMP_NAME.fullmatch(name) is not None


_TEMP_NAME = re.compile(r"\..+\.[a-z0-9_]{8}" + re.escape(TEMP_MARK) + r"(\.[^./]*)?")


def remove_stale_temps(folder: str | Path, recursive: bool = False, min_age_s: float = 0.0) -> int:
    """Delete the temporary files atomic_path left in `folder` (and its sub-folders when `recursive`) when their
    process was killed mid-write; finished files and files of other names are never touched. min_age_s: keep
    temporary files modified more recently (another process sharing the folder may be writing them). The number
    removed."""
    removed = 0
    now = time.time()
    for root, _dirs, files in os.walk(folder):
        for name in files:
            path = Path(root) / name
            try:
                if is_temp_name(name) and now - path.stat().st_mtime >= min_age_s:
                    path.unlink()
                    removed += 1
            except FileNotFoundError:
                continue  # removed meanwhile
        if not recursive:
            break
    return removed


def write_bytes(path: str | Path, data: bytes) -> None:
    """Write bytes atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path: str | Path, text: str) -> None:
    """Write text (UTF-8) atomically."""
    write_bytes(path, text.encode("utf-8"))


def write_json(path: str | Path, obj: Any) -> None:
    """Write an object as indented JSON atomically."""
    write_bytes(path, encode_json(obj))


def encode_json(obj: Any) -> bytes:
    """An object as radar's JSON files hold it: indented, sorted keys, UTF-8, a final newline."""
    return (json.dumps(obj, indent=2, sort_keys=True) + "\n").encode("utf-8")


def write_npy(path: str | Path, array: np.ndarray) -> None:
    """Write a numpy array atomically."""
    write_bytes(path, encode_npy(array))


def encode_npy(array: np.ndarray) -> bytes:
    """A numpy array as the bytes of a .npy file."""
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def to_uint8(image: np.ndarray) -> np.ndarray:
    """Convert a float image in [0, 1] (H x W or H x W x C) to uint8, clipping."""
    return (np.clip(image, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


PNG_LEVEL = 6  # zlib level of PNG writes (Pillow's default)


def write_image(path: str | Path, image: np.ndarray, png_level: int = PNG_LEVEL) -> None:
    """Write an image atomically; float arrays are taken as [0, 1], uint8 as is. H x W or H x W x {3,4}.
    png_level: zlib compression level 0-9 when the file is a PNG."""
    write_bytes(path, encode_image(image, _format_for(Path(path)), png_level))


def encode_image(image: np.ndarray, fmt: str = "PNG", png_level: int = PNG_LEVEL) -> bytes:
    """The bytes of an image file (PIL format name, e.g. "PNG"); float arrays are taken as [0, 1], uint8 as is."""
    if image.dtype != np.uint8:
        image = to_uint8(image)
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format=fmt, **({"compress_level": png_level} if fmt == "PNG" else {}))
    return buffer.getvalue()


def encode_png_fast(image: np.ndarray) -> bytes:
    """PNG bytes for bulk writers (radar synth): zlib level 1 and the Sub filter on every row, through OpenCV.

    Where Pillow tries every row filter, this uses one: faster, files slightly larger, pixels identical
    (docs/performance.md). Float arrays are taken as [0, 1], uint8 as is; H x W or H x W x 3 (RGB).
    """
    import cv2  # here, not at the top: `radar fetch` and the other light commands never load OpenCV

    if image.dtype != np.uint8:
        image = to_uint8(image)
    if image.ndim == 3:
        image = np.ascontiguousarray(image[..., ::-1])  # OpenCV writes BGR
    ok, buffer = cv2.imencode(".png", image, [cv2.IMWRITE_PNG_COMPRESSION, 1,
                                              cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_SUB])
    if not ok:
        raise ValueError(f"OpenCV could not encode a {image.shape} {image.dtype} image as PNG")
    return buffer.tobytes()


def _format_for(path: Path) -> str:
    ext = path.suffix.lower()
    return {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG", ".gif": "GIF", ".webp": "WEBP"}.get(ext, "PNG")


@contextmanager
def image_errors(path: Path) -> Iterator[None]:
    """Turn any failure to open or decode the image at `path` into one InputError naming the file."""
    try:
        yield
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except Image.DecompressionBombError as e:
        raise InputError(f"{path}: image too large ({e})") from None
    except (OSError, ValueError, SyntaxError) as e:
        raise InputError(f"{path}: not a readable image ({e})") from None


def read_image(path: str | Path, mode: str = "RGB") -> np.ndarray:
    """Read an image file as uint8 (H x W x 3 for RGB, H x W for L), honouring EXIF orientation.

    Grey, palette, RGBA, CMYK and 16-bit images are converted. Raises InputError naming the file on any
    decoding problem, including decompression bombs.
    """
    from PIL import ImageOps

    path = Path(path)
    with image_errors(path), Image.open(path) as im:
        im = ImageOps.exif_transpose(im)
        if im.mode in ("I;16", "I;16B", "I;16L", "I"):
            arr = np.asarray(im, dtype=np.float64)
            scale = 65535.0 if arr.max() > 255 else 255.0
            im = Image.fromarray((arr / scale * 255.0).clip(0, 255).astype(np.uint8))
        if mode == "RGB" and im.mode in ("RGBA", "LA", "PA") or (im.mode == "P" and "transparency" in im.info):
            im = im.convert("RGBA")
            background = Image.new("RGBA", im.size, (255, 255, 255, 255))
            im = Image.alpha_composite(background, im)
        return np.asarray(im.convert(mode)).copy()


MAX_JSON_BYTES = 1_000_000  # result and sample records are a few kB; refuse absurd files


def read_json(path: Path) -> dict:
    """A JSON object from a small file; InputError naming the file otherwise."""
    try:
        if path.stat().st_size > MAX_JSON_BYTES:
            raise InputError(f"{path}: larger than {MAX_JSON_BYTES} bytes")
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise InputError(f"{path}: not valid JSON ({e})") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a JSON object")
    return data


def number(data: dict, key: str, path: Path, index: int | None = None) -> float:
    """data[key] (or data[key][index]) as a finite float; InputError naming the file and key otherwise."""
    value = data.get(key)
    if index is not None:
        value = value[index] if isinstance(value, list) and len(value) > index else None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        where = key if index is None else f"{key}[{index}]"
        raise InputError(f"{path}: '{where}' must be a finite number, got {value!r}")
    return float(value)
