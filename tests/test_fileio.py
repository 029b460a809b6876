"""Atomic writes and safe image reading."""

import io
import os

import numpy as np
import pytest
from PIL import Image

from radar_cli import fileio
from radar_cli.errors import InputError


def test_atomic_write_leaves_no_partial_file(tmp_path):
    target = tmp_path / "out.json"
    fileio.write_json(target, {"a": 1})
    with pytest.raises(RuntimeError):
        with fileio.atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("killed")
    assert target.read_text().strip().startswith("{") and '"a": 1' in target.read_text()
    assert sorted(os.listdir(tmp_path)) == ["out.json"]


def test_image_round_trip(tmp_path):
    img = np.random.default_rng(0).random((5, 7, 3))
    fileio.write_image(tmp_path / "a.png", img)
    back = fileio.read_image(tmp_path / "a.png")
    assert back.shape == (5, 7, 3) and back.dtype == np.uint8
    assert np.abs(back / 255.0 - img).max() <= 0.5 / 255 + 1e-9


@pytest.mark.parametrize("mode", ["L", "RGBA", "CMYK", "I;16", "P"])
def test_read_converts_modes(tmp_path, mode):
    path = tmp_path / ("x.tif" if mode in ("CMYK", "I;16") else "x.png")
    im = Image.new("RGB", (6, 4), (200, 100, 50))
    if mode == "I;16":
        im = Image.fromarray(np.full((4, 6), 40000, dtype=np.uint16))
    else:
        im = im.convert(mode)
    im.save(path)
    out = fileio.read_image(path)
    assert out.shape == (4, 6, 3) and out.dtype == np.uint8


def test_read_errors_name_the_file(tmp_path):
    bad = tmp_path / "broken.jpg"
    bad.write_bytes(b"\xff\xd8\xff\xe0 not really a jpeg")
    with pytest.raises(InputError, match="broken.jpg: not a readable image"):
        fileio.read_image(bad)
    with pytest.raises(InputError, match="missing.png: no such file"):
        fileio.read_image(tmp_path / "missing.png")


def test_decompression_bomb_rejected(tmp_path, monkeypatch):
    path = tmp_path / "big.png"
    Image.new("L", (400, 400)).save(path)
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", 1000)
    with pytest.raises(InputError, match="big.png: image too large"):
        fileio.read_image(path)


def test_exif_orientation_honoured(tmp_path):
    path = tmp_path / "rot.jpg"
    im = Image.new("RGB", (8, 4), (255, 0, 0))
    exif = im.getexif()
    exif[0x0112] = 6  # rotate 90 deg clockwise on display
    im.save(path, exif=exif.tobytes())
    assert fileio.read_image(path).shape == (8, 4, 3)


@pytest.mark.parametrize("shape, dtype", [((9, 14, 3), np.float32), ((9, 14), np.float32), ((9, 14, 3), np.uint8),
                                          ((9, 14), np.uint8)])
def test_fast_png_decodes_to_the_same_pixels(shape, dtype):
    """radar synth's encoder (OpenCV, level 1, Sub filter): the same pixels, in RGB order, as Pillow's PNG."""
    rng = np.random.default_rng(0)
    image = rng.random(shape).astype(np.float32) if dtype == np.float32 else rng.integers(0, 256, shape, np.uint8)
    fast = fileio.encode_png_fast(image)
    assert fast[:8] == b"\x89PNG\r\n\x1a\n"
    got = np.array(Image.open(io.BytesIO(fast)))
    want = np.array(Image.open(io.BytesIO(fileio.encode_image(image, "PNG"))))
    assert got.shape == shape and np.array_equal(got, want)
