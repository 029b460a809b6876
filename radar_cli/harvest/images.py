"""Validate a downloaded image (decode it fully, refuse decompression bombs) and commit it by atomic rename."""

from __future__ import annotations

import hashlib
import io
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from PIL import Image

from radar_cli.fileio import write_bytes
from radar_cli.harvest.client import BodyTooLarge, HttpClient

MAX_PIXELS = 64_000_000  # the Met's originals are at most ~4000 x 6000 px
EXTENSIONS = {"JPEG": ".jpg", "PNG": ".png", "TIFF": ".tif", "WEBP": ".webp", "GIF": ".gif"}


class ImageRejected(Exception):
    """A downloaded body is not an image we keep.

    `skip_reason` is set for permanent rejections (the object is skipped for that reason); None means the body
    may have been damaged in transfer, so the object is marked failed and retried on the next run.
    """

    def __init__(self, message: str, skip_reason: str | None):
        super().__init__(message)
        self.skip_reason = skip_reason


@dataclass(frozen=True)
class StoredImage:
    """An image committed to disk."""

    path: Path
    size: int
    sha256: str


def validate_image(body: bytes, max_pixels: int = MAX_PIXELS) -> str:
    """Decode the whole image and return its file extension (".jpg", ...).

    Args:
        body: the downloaded bytes.
        max_pixels: largest width x height accepted (decompression-bomb guard, checked before decoding).

    Raises:
        ImageRejected: too many pixels or an unsupported format (permanent), or not decodable (retryable).
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(io.BytesIO(body)) as im:
                width, height = im.size
                if width * height > max_pixels:
                    raise ImageRejected(f"image too large ({width} x {height} px > {max_pixels} px)", "image_too_large")
                fmt = im.format or ""
                im.load()  # decodes every byte: truncated or corrupt data raises here
    except ImageRejected:
        raise
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as e:
        raise ImageRejected(f"image too large ({e})", "image_too_large") from None
    except (OSError, ValueError, SyntaxError, EOFError) as e:
        raise ImageRejected(f"corrupt image ({e})", None) from None
    if fmt not in EXTENSIONS:
        raise ImageRejected(f"unsupported image format {fmt or 'unknown'}", "unsupported_format")
    return EXTENSIONS[fmt]


def store_image(body: bytes, folder: Path, object_id: int, max_pixels: int = MAX_PIXELS,
                view: int | None = None) -> StoredImage:
    """Validate an image and write it as `folder/<object_id><ext>` (a view: `<object_id>_<view><ext>`) by
    atomic rename.

    The file name comes from the numeric object id and view index only, never from the remote URL.

    Raises:
        ImageRejected: see `validate_image`.
    """
    ext = validate_image(body, max_pixels)
    path = folder / f"{image_stem(object_id, view)}{ext}"
    write_bytes(path, body)
    return StoredImage(path, len(body), hashlib.sha256(body).hexdigest())


def image_stem(object_id: int, view: int | None = None) -> str:
    """The file name (without extension) of an object's image or of one of its views (0 = the primary)."""
    return f"{int(object_id)}" if view is None else f"{int(object_id)}_{int(view)}"


@dataclass(frozen=True)
class Download:
    """One image request's outcome.

    Attributes:
        outcome: `stored` (new bytes written), `unchanged` (304 for the file already there), `skipped` (too
            large, gone from the host, or refused for good) or `failed` (worth retrying).
        reason: the catalog's reason for skipped or failed ("image_too_large", "image_missing", ...).
        message: a line worth printing (a skip the user should see), or "".
        stored: the written file, for `stored`.
        etag: the reply's ETag, for `stored`.
    """

    outcome: Literal["stored", "unchanged", "skipped", "failed"]
    reason: str = ""
    message: str = ""
    stored: StoredImage | None = None
    etag: str = ""


def download_image(client: HttpClient, url: str, etag: str, old: Path | None, folder: Path, object_id: int,
                   max_pixels: int = MAX_PIXELS, view: int | None = None) -> Download:
    """Fetch an image (conditional on `etag` when its file `old` is there), validate it and store it as
    store_image does; the outcome says what the catalog should record."""
    headers = {"If-None-Match": etag} if etag and old is not None and old.is_file() else {}
    try:
        reply = client.get(url, headers=headers)
    except BodyTooLarge as e:
        return Download("skipped", "image_too_large", str(e))
    if reply.status == 304 and headers:
        return Download("unchanged")
    if reply.status in (404, 410):
        return Download("skipped", "image_missing")
    if reply.status != 200:
        return Download("failed", f"image HTTP {reply.status}")
    try:
        stored = store_image(reply.body, folder, object_id, max_pixels, view=view)
    except ImageRejected as e:
        if e.skip_reason:
            return Download("skipped", e.skip_reason, str(e))
        return Download("failed", str(e), str(e))
    return Download("stored", stored=stored, etag=reply.headers.get("ETag", ""))
