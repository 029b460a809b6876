"""`radar derender --resolution 64` (the network's own side) writes exactly the files the network-only path
writes (golden/resolution_64.json), compared by what they decode to, so an encoder upgrade that keeps the pixels
keeps the test: PNG (lossless) by a SHA-256 of its decoded pixels, .npy by its array, the mesh.glb by its
geometry, texture pixels and material, Radiance .hdr and the turntable GIF (whose encoders round and quantise) by
their shape and per-channel mean and maximum within a tolerance, material.json by its record less the keys that
name the output resolution, anything else by its bytes. The image-space diffuse and specular renders come besides
them. Regenerate with RADAR_WRITE_GOLDEN=1 only when a change of the network-size outputs is intended."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import cv2
import numpy as np
import trimesh
from PIL import Image, ImageSequence

from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor

from .conftest import SETUP, FakeModel, write_photo

GOLDEN = Path(__file__).parent / "golden" / "resolution_64.json"
RESOLUTION_KEYS = ("resolution", "view_size")  # material.json keys that record the output size
SHADING_RENDERS = ("diffuse_rendered.png", "specular_rendered.png")  # written besides the pinned files


def _inputs(root: Path) -> Path:
    """A photo the detector crops, a photo with a known mask (cropped by it) and a square one."""
    write_photo(root / "in" / "wide.png", 2, (96, 144))
    write_photo(root / "in" / "square.png", 1, (80, 80))
    photo = write_photo(root / "in" / "masked.png", 3, (120, 100))
    masks = root / "masks"
    masks.mkdir()
    dark = np.asarray(Image.open(photo)).max(axis=-1) < 200
    Image.fromarray((dark * 255).astype(np.uint8)).save(masks / "masked.png")
    return masks


HDR_RTOL = 1 / 64  # RGBE keeps an 8-bit mantissa: a re-rounding moves a decoded value by < 1/128 of itself
GIF_ATOL = 2.0  # of 255: the GIF palette is Pillow's quantisation, which may change between versions


def _sha(*parts: bytes | str) -> str:
    digest = hashlib.sha256()
    for part in parts:
        digest.update(part.encode() if isinstance(part, str) else part)
    return digest.hexdigest()


def _array_sha(array: np.ndarray) -> str:
    array = np.ascontiguousarray(array)
    return _sha(str(array.dtype), str(array.shape), array.tobytes())


def _stats(array: np.ndarray) -> dict:
    """Shape, and per-channel mean and maximum of an ... x C array."""
    flat = array.reshape(-1, array.shape[-1]).astype(np.float64)
    return {"shape": list(array.shape), "mean": flat.mean(0).round(4).tolist(), "max": flat.max(0).round(4).tolist()}


def _glb_sha(path: Path) -> str:
    mesh = trimesh.load(path, force="mesh", process=False)
    material = mesh.visual.material
    texture = np.asarray(material.baseColorTexture.convert("RGBA"))
    factors = f"{material.metallicFactor} {material.roughnessFactor} {material.doubleSided}"
    return _sha(_array_sha(np.asarray(mesh.vertices)), _array_sha(np.asarray(mesh.faces)),
                _array_sha(np.asarray(mesh.visual.uv)), _array_sha(texture), factors)


def _digest(path: Path) -> str | dict:
    """What `path` decodes to: a SHA-256 where decoding is exact, statistics where an encoder rounds."""
    if path.suffix == ".png":
        with Image.open(path) as image:
            return _sha(image.mode, _array_sha(np.asarray(image)))
    if path.suffix == ".npy":
        return _array_sha(np.load(path, allow_pickle=False))
    if path.suffix == ".glb":
        return _glb_sha(path)
    if path.suffix == ".hdr":
        return _stats(cv2.imread(str(path), cv2.IMREAD_ANYDEPTH | cv2.IMREAD_COLOR))
    if path.suffix == ".gif":
        with Image.open(path) as image:
            return _stats(np.stack([np.asarray(frame.convert("RGB")) for frame in ImageSequence.Iterator(image)]))
    data = path.read_bytes()
    if path.name == "material.json":
        record = {k: v for k, v in json.loads(data).items() if k not in RESOLUTION_KEYS}
        record["source"] = Path(record["source"]).name  # the temporary folder differs per run
        data = json.dumps(record, sort_keys=True).encode()
    return _sha(data)


def _digests(out: Path) -> dict[str, str | dict]:
    """{object/file: digest} of every file of every object folder."""
    return {f"{path.parent.name}/{path.name}": _digest(path)
            for path in sorted(p for p in out.glob("*/*") if p.is_file() and not p.parent.name.startswith("."))}


def _matches(name: str, found: str | dict, expected: str | dict) -> bool:
    if isinstance(expected, str) or isinstance(found, str):
        return found == expected
    if found["shape"] != expected["shape"]:
        return False
    rtol, atol = (HDR_RTOL, 0.0) if name.endswith(".hdr") else (0.0, GIF_ATOL)
    return all(np.allclose(found[k], expected[k], rtol=rtol, atol=atol) for k in ("mean", "max"))


def run_network_size(root: Path, **resolution) -> dict[str, str | dict]:
    masks = _inputs(root)
    options = DerenderOptions(out=root / "out", masks=masks, export=ExportConfig(views=3, view_size=32), workers=1,
                              **resolution)
    summary = derender([root / "in"], Predictor(FakeModel(), SETUP, "fake-model", "cpu"), options,
                       say=lambda line: None)
    assert not summary.failures and len(summary.done) == 3
    return _digests(root / "out")


def test_network_side_reproduces_the_network_outputs(tmp_path: Path) -> None:
    found = run_network_size(tmp_path, resolution=SETUP.render.image_size)
    extra = {name for name in found if name.split("/")[1] in SHADING_RENDERS}
    if os.environ.get("RADAR_WRITE_GOLDEN"):
        pinned = {name: digest for name, digest in found.items() if name not in extra}
        lines = [f" {json.dumps(name)}: {json.dumps(pinned[name])}" for name in sorted(pinned)]
        GOLDEN.write_text("{\n" + ",\n".join(lines) + "\n}\n")
    expected = json.loads(GOLDEN.read_text())
    assert sorted(set(found) - extra) == sorted(expected)
    assert len(extra) == 3 * len(SHADING_RENDERS)
    changed = [name for name in expected if not _matches(name, found[name], expected[name])]
    assert not changed, f"files that differ from the network-size outputs: {changed}"

