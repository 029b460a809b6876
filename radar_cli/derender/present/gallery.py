"""The results root's interactive gallery: index.html, the page's code and 3D viewer copied from the package
into RESULTS/.gallery/, one data file describing every object, a small thumbnail per object, and the lighting
files the viewer relights with (each object's recovered environment and the built-in ones).

The page needs no network: the viewer is Google's <model-viewer> (vendored, see radar_cli/assets/gallery/).
Browsers refuse a page opened from disk (file://) the mesh and HDR fetches WebGL needs: the 3D view works through
`radar serve RESULTS` (or any static HTTP server), and from disk once the user picks the object's mesh.glb (files
chosen by the user may be read); the built-in lighting is in a script for that case.
"""

from __future__ import annotations

import base64
import json
import math
import re
import shutil
import sqlite3
from pathlib import Path

import numpy as np

from radar_cli.derender.export.environments import builtin_environments
from radar_cli.errors import RadarError
from radar_cli.fileio import atomic_path, read_image, write_image, write_text
from radar_cli.results import (
    APPENDAGES_FILE,
    COVERAGE_FILE,
    ENV_MAP_FILE,
    INDEX_FILE,
    INPUT_FILE,
    MATERIAL_FILE,
    RECON_FILE,
    RELIT_PREFIX,
    SUMMARY_FILE,
    VIEWS_DIR,
)

ASSETS = Path(__file__).resolve().parents[2] / "assets" / "gallery"
GALLERY_DIR = ".gallery"  # RESULTS/.gallery/: page code, viewer, data, built-in environments
DATA_FILE = "data.js"  # a script, not JSON: a page opened from disk may run scripts but not fetch files
ENV_DIR = "env"
ENV_SCRIPT = "env.js"  # the built-in environments' .hdr files as base64, for a page opened from disk
THUMBNAIL_FILE = "thumbnail.png"  # per object: input | reconstruction, THUMB_SIDE px each
VIEWER_ENV_FILE = "env_viewer.hdr"  # per object: its recovered lighting in the viewer's convention
THUMB_SIDE = 128
VIEWER_ENV_SIZE = (64, 128)  # He x We of the built-in environments written for the viewer
VIEWER_ENV_UPSAMPLE = 4  # an object's He x We map is enlarged (nearest) so its width divides by 4
MAX_META_BYTES = 1024 * 1024  # meta.json beside an input is untrusted: refuse larger files
STATUS_UNKNOWN = "unknown"  # objects without a quality record
SCORE_KEYS = ("silhouette_iou", "symmetry", "recon_psnr", "appendage_fraction", "outline_support",
              "frame_coverage")
VIEW_PICTURE = re.compile(re.escape(VIEWS_DIR) + r"/[A-Za-z0-9_-][A-Za-z0-9._-]{0,127}\.png")  # as written
PAGE_FILES = ("index.css", "gallery.js", "model-viewer-umd.min.js", "LICENSE-model-viewer.txt",
              "THIRD_PARTY_LICENSES.txt")


def viewer_environment(env: np.ndarray, upsample: int = 1) -> np.ndarray:
    """A radar environment map (He x We, camera frame, column centre = towards the camera) as the
    equirectangular RGB radiance three.js expects around the exported mesh (seen side at +z).

    three.js puts direction atan2(z, x) = 0 (+x) at the image's centre; the mesh export turns the camera frame
    180 deg about the axis, so radar's column fraction c lands at u = c + 1/4. radar's diffuse factor is the
    cosine-weighted sum of the map, three.js divides a Lambertian surface's by pi: the map is scaled by pi.

    Args:
        env: He x We float map (linear, >= 0).
        upsample: nearest-neighbour enlargement factor (the roll needs We * upsample divisible by 4).

    Returns:
        (He * upsample) x (We * upsample) x 3 float32.
    """
    big = np.repeat(np.repeat(env, upsample, axis=0), upsample, axis=1)
    if big.shape[1] % 4:
        raise ValueError(f"environment width {big.shape[1]} is not divisible by 4; raise `upsample`")
    rolled = np.roll(big, big.shape[1] // 4, axis=1) * math.pi
    return np.repeat(rolled[..., None], 3, axis=2).astype(np.float32)


def write_hdr(path: Path, rgb: np.ndarray) -> None:
    """Write H x W x 3 float radiance as a Radiance .hdr file, atomically."""
    import cv2

    with atomic_path(path) as tmp:
        if not cv2.imwrite(str(tmp), np.ascontiguousarray(rgb[..., ::-1])):
            raise OSError(f"{path}: OpenCV could not write the HDR file")


def _newer(target: Path, source: Path) -> bool:
    """True if `target` exists and was written after `source` (so it need not be redone)."""
    return target.is_file() and target.stat().st_mtime_ns >= source.stat().st_mtime_ns


def write_object_files(folder: Path) -> None:
    """The object's thumbnail and viewer lighting, unless already newer than its material.json."""
    material = folder / MATERIAL_FILE
    if not _newer(folder / THUMBNAIL_FILE, material) and (folder / INPUT_FILE).is_file():
        tiles = [_tile(folder / name) for name in (INPUT_FILE, RECON_FILE) if (folder / name).is_file()]
        write_image(folder / THUMBNAIL_FILE, np.concatenate(tiles, axis=1))
    if not _newer(folder / VIEWER_ENV_FILE, material) and (folder / ENV_MAP_FILE).is_file():
        env = np.load(folder / ENV_MAP_FILE, allow_pickle=False).astype(np.float32)
        factor = VIEWER_ENV_UPSAMPLE * (1 if env.shape[1] % 4 == 0 else 4)
        write_hdr(folder / VIEWER_ENV_FILE, viewer_environment(env, factor))


def _tile(path: Path) -> np.ndarray:
    """THUMB_SIDE x THUMB_SIDE x 3 uint8 of an image (area-averaged down, never enlarged past its size)."""
    from PIL import Image

    image = Image.fromarray(read_image(path, "RGB"))
    return np.asarray(image.resize((THUMB_SIDE, THUMB_SIDE), Image.Resampling.BOX
                                   if image.width >= THUMB_SIDE else Image.Resampling.BICUBIC))


def _safe_url(url: object) -> str:
    """A catalogue link only if it is plainly http(s) (a `javascript:` link from a record must never run)."""
    return url if isinstance(url, str) and url.startswith(("https://", "http://")) else ""


def attribution(source: str, catalogs: dict[Path, sqlite3.Connection]) -> dict | None:
    """Title, credit line, licence and catalogue link of an input that came from `radar masks` (its meta.json)
    or straight from a `radar fetch` folder (its catalog.sqlite, opened read-only once into `catalogs`), else
    None."""
    from radar_cli.harvest.catalog import photo_row

    path = Path(source)
    meta = path.parent / "meta.json"
    found: dict | None = None
    try:
        if meta.is_file() and meta.stat().st_size <= MAX_META_BYTES:
            found = json.loads(meta.read_text("utf-8")).get("attribution") or None
        else:
            found = photo_row(path, catalogs)
    except (OSError, ValueError, AttributeError, sqlite3.Error):
        return None
    if not isinstance(found, dict):
        return None
    return {"title": str(found.get("title") or ""), "credit": str(found.get("credit_line") or ""),
            "licence": str(found.get("licence") or ""), "url": _safe_url(found.get("object_url")),
            "object_id": str(found.get("object_id") or "")}


def _number(value: object) -> float | None:
    return float(value) if isinstance(value, (int, float)) and math.isfinite(value) else None


def real_size(rec: dict) -> dict | None:
    """The catalogued lengths (cm), their source and the mesh's measured ones, when the mesh is in metres."""
    lengths, mesh = rec.get("size_cm"), rec.get("mesh_cm")
    if rec.get("mesh_unit") != "m" or not isinstance(lengths, dict) or not isinstance(mesh, dict):
        return None
    return {"cm": {str(k): _number(v) for k, v in lengths.items()}, "source": str(rec.get("size_source") or ""),
            "mesh_cm": {str(k): _number(v) for k, v in mesh.items()}}


def view_entries(folder: Path, rec: dict) -> list[dict]:
    """An object's photographs (material.json `views`: several for an object seen from several sides, none
    otherwise): name, picture (views/<name>.png, only a name of the form radar writes and only if the file is
    there), used or left out and why, turn in degrees."""
    views = rec.get("views")
    entries = []
    for view in views if isinstance(views, list) else []:
        if not isinstance(view, dict):
            continue
        picture = view.get("picture")
        ok = isinstance(picture, str) and VIEW_PICTURE.fullmatch(picture) and (folder / picture).is_file()
        entries.append({"name": Path(str(view.get("source") or "")).stem, "picture": picture if ok else None,
                        "used": view.get("used") is True, "reason": str(view.get("reason") or ""),
                        "turn_deg": _number(view.get("turn_deg"))})
    return entries


def object_entry(folder: Path, rec: dict, catalogs: dict[Path, sqlite3.Connection]) -> dict:
    """What the page knows of one object: id, quality, material, attribution and which files exist."""
    quality = rec.get("quality")
    if not isinstance(quality, dict):
        quality = {}
    relit = [e for e in rec.get("environments", []) if (folder / f"{RELIT_PREFIX}{e}.png").is_file()]
    return {
        "id": folder.name,
        "status": str(quality.get("status") or STATUS_UNKNOWN),
        "reasons": [str(r) for r in quality.get("reasons", []) or []],
        "cut_edges": [str(c) for c in quality.get("cut_edges", []) or []],
        "scores": {k: _number(quality.get(k)) for k in SCORE_KEYS if k in quality},
        "material": {k: _number(rec.get(k)) for k in ("pitch", "roll", "alpha", "rho", "roughness", "height")},
        "attribution": attribution(str(rec.get("source", "")), catalogs),
        "size": real_size(rec),
        "relit": relit,
        "appendages": (folder / APPENDAGES_FILE).is_file(),
        "views": view_entries(folder, rec),
        "coverage": (folder / COVERAGE_FILE).is_file(),
        "thumbnail": (folder / THUMBNAIL_FILE).is_file(),
        "viewer_env": (folder / VIEWER_ENV_FILE).is_file(),
    }


def _copy_page_files(target: Path) -> None:
    """The page's code and the vendored viewer, copied (atomically) when missing or different."""
    for name in PAGE_FILES:
        src, dst = ASSETS / name, target / name
        if dst.is_file() and dst.stat().st_size == src.stat().st_size and dst.read_bytes() == src.read_bytes():
            continue
        with atomic_path(dst) as tmp:
            shutil.copyfile(src, tmp)


def _write_builtin_environments(gallery: Path) -> list[str]:
    """RESULTS/.gallery/env/<name>.hdr for every built-in environment, and the same files in env.js for a page
    opened from disk (which may run a script but not fetch a file); written once. Returns their names."""
    envs = builtin_environments(*VIEWER_ENV_SIZE)
    target = gallery / ENV_DIR
    for name, env in envs.items():
        if not (target / f"{name}.hdr").is_file():
            write_hdr(target / f"{name}.hdr", viewer_environment(env))
    if not (gallery / ENV_SCRIPT).is_file():
        files = {name: base64.b64encode((target / f"{name}.hdr").read_bytes()).decode("ascii")
                 for name in sorted(envs)}
        write_text(gallery / ENV_SCRIPT, "window.RADAR_ENVS = " + json.dumps(files) + ";\n")
    return sorted(envs)


def write_gallery(root: Path, records: list[tuple[str, dict]], n_failed: int) -> Path:
    """index.html and RESULTS/.gallery/ for the complete objects `records` (name, material.json record)."""
    gallery = root / GALLERY_DIR
    _copy_page_files(gallery)
    builtins = _write_builtin_environments(gallery)
    entries: list[dict] = []
    catalogs: dict[Path, sqlite3.Connection] = {}
    try:
        for name, rec in records:
            try:
                write_object_files(root / name)
            except (RadarError, OSError, ValueError):
                pass  # an unreadable picture costs its thumbnail or viewer lighting, not the gallery
            entries.append(object_entry(root / name, rec, catalogs))
    finally:
        for db in catalogs.values():
            db.close()
    data = {"objects": entries, "builtin_envs": builtins, "failed": n_failed, "scores": list(SCORE_KEYS)}
    write_text(gallery / DATA_FILE, "window.RADAR_GALLERY = " + json.dumps(data, separators=(",", ":")) + ";\n")
    write_text(root / INDEX_FILE, (ASSETS / "index.html").read_text("utf-8")
               .replace("{{COUNT}}", str(len(entries))).replace("{{SUMMARY}}", SUMMARY_FILE))
    return root / INDEX_FILE
