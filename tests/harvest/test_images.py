"""Image validation before commit: decodable images are stored under the numeric id, others rejected."""

from __future__ import annotations

import hashlib
import io

import pytest
from PIL import Image

from radar_cli.harvest.images import ImageRejected, store_image, validate_image


def encoded(fmt: str, size: tuple[int, int] = (32, 20), mode: str = "RGB") -> bytes:
    buf = io.BytesIO()
    Image.new(mode, size, 128).save(buf, format=fmt)
    return buf.getvalue()


def test_store_names_file_from_id_and_hashes(tmp_path):
    body = encoded("JPEG")
    stored = store_image(body, tmp_path / "met", 45734)
    assert stored.path == tmp_path / "met" / "45734.jpg"
    assert stored.path.read_bytes() == body and stored.size == len(body)
    assert stored.sha256 == hashlib.sha256(body).hexdigest()
    assert [p.name for p in (tmp_path / "met").iterdir()] == ["45734.jpg"]  # no temp file left


def test_png_keeps_its_extension(tmp_path):
    assert store_image(encoded("PNG"), tmp_path, 3).path.name == "3.png"


@pytest.mark.parametrize("body", [encoded("JPEG")[:-300], b"\xff\xd8\xff\xe0" + b"\x00" * 500, b"<html>no</html>"])
def test_corrupt_or_truncated_is_retryable(body, tmp_path):
    with pytest.raises(ImageRejected, match="corrupt") as e:
        store_image(body, tmp_path, 1)
    assert e.value.skip_reason is None
    assert not list(tmp_path.iterdir())


def test_too_many_pixels_is_skipped_before_decoding():
    with pytest.raises(ImageRejected) as e:
        validate_image(encoded("PNG", (2000, 1000), "1"), max_pixels=1_000_000)
    assert e.value.skip_reason == "image_too_large"


def test_decompression_bomb():
    with pytest.raises(ImageRejected) as e:
        validate_image(encoded("PNG", (12_000, 12_000), "1"))
    assert e.value.skip_reason == "image_too_large"


def test_unsupported_format():
    with pytest.raises(ImageRejected) as e:
        validate_image(encoded("BMP"))
    assert e.value.skip_reason == "unsupported_format"
