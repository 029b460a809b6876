"""`radar derender --resolution 64` (the network's own side) writes exactly the files the network-only path
writes: every file's bytes are pinned by SHA-256 (golden/resolution_64.json), material.json as its record less
the keys that name the output resolution; the image-space diffuse and specular renders come besides them.
Regenerate with RADAR_WRITE_GOLDEN=1 only when a change of the network-size outputs is intended."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np
from PIL import Image

from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.export.object_folder import ExportConfig
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


def _digests(out: Path) -> dict[str, str]:
    """{object/file: sha256} of every file of every object folder (material.json: its record, sorted)."""
    found = {}
    for path in sorted(p for p in out.glob("*/*") if p.is_file() and not p.parent.name.startswith(".")):
        data = path.read_bytes()
        if path.name == "material.json":
            record = {k: v for k, v in json.loads(data).items() if k not in RESOLUTION_KEYS}
            record["source"] = Path(record["source"]).name  # the temporary folder differs per run
            data = json.dumps(record, sort_keys=True).encode()
        found[f"{path.parent.name}/{path.name}"] = hashlib.sha256(data).hexdigest()
    return found


def run_network_size(root: Path, **resolution) -> dict[str, str]:
    masks = _inputs(root)
    options = DerenderOptions(out=root / "out", masks=masks, export=ExportConfig(views=3, view_size=32), workers=1,
                              **resolution)
    summary = derender([root / "in"], Predictor(FakeModel(), SETUP, "fake-model", "cpu"), options,
                       say=lambda line: None)
    assert not summary.failures and len(summary.done) == 3
    return _digests(root / "out")


def test_network_side_reproduces_the_network_outputs(tmp_path: Path) -> None:
    found = run_network_size(tmp_path, resolution=SETUP.image_size)
    extra = {name for name in found if name.split("/")[1] in SHADING_RENDERS}
    if os.environ.get("RADAR_WRITE_GOLDEN"):
        pinned = {name: digest for name, digest in found.items() if name not in extra}
        GOLDEN.write_text(json.dumps(pinned, indent=1, sort_keys=True) + "\n")
    expected = json.loads(GOLDEN.read_text())
    assert sorted(set(found) - extra) == sorted(expected)
    assert len(extra) == 3 * len(SHADING_RENDERS)
    changed = [name for name in expected if found[name] != expected[name]]
    assert not changed, f"files that differ from the network-size outputs: {changed}"

