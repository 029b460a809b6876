"""`radar fetch --images all`: an object's `additionalImages` downloaded as further views beside its primary image.

An object with at least one additional image gets a folder of its own, DATA/met/<id>/, holding its primary image
(moved there as `<id>_0<ext>`) and its views `<id>_1<ext>`, `<id>_2<ext>`, ... in the record's order: names
from the numeric id and the index only, never from a URL. Objects with one image keep DATA/met/<id><ext>, so
`radar derender DATA/met` reads each folder as one object seen from several sides. Views go through the image
host's paced client, are validated and limited like primary images, and are resumed from the catalog's `views`
table (a failed view is retried on the next run, a changed URL downloaded again).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from tqdm import tqdm

from radar_cli.errors import NetworkError
from radar_cli.harvest.catalog import Catalog
from radar_cli.harvest.client import FetchError, HttpClient
from radar_cli.harvest.images import download_image, image_stem

MAX_RECORD_BYTES = 16 * 1024 * 1024  # a stored object record (as the API sent it) larger than this is not read
MAX_VIEWS = 100  # additional images kept per object at most
PRIMARY_VIEW = 0


class ViewTotals(Protocol):
    """Where the stage counts what it did (the run's Summary)."""

    views_fetched: int
    views_unchanged: int


def read_stored_record(out: Path, record_path: str | None) -> dict[str, Any] | None:
    """The object record a harvest stored (DATA/met/<id>.json), or None if missing, too large or not a record."""
    if not record_path:
        return None
    path = out / record_path
    try:
        if path.stat().st_size > MAX_RECORD_BYTES:
            return None
        record = json.loads(path.read_bytes().decode("utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    return record if isinstance(record, dict) else None


def view_urls(record: dict[str, Any], primary_url: str) -> list[str]:
    """The record's additional image URLs: http(s) strings only, without repeats or the primary image."""
    found = record.get("additionalImages")
    urls = [u for u in found if isinstance(u, str) and u.startswith(("https://", "http://"))] \
        if isinstance(found, list) else []
    return [u for u in dict.fromkeys(urls) if u != primary_url][:MAX_VIEWS]


def object_folder(out: Path, objects_dir: str, object_id: int) -> Path:
    """DATA/met/<id>/: the folder of an object with several images."""
    return out / objects_dir / str(int(object_id))


@dataclass
class ViewStage:
    """Registers, places and downloads the views of every kept object of one catalog.

    Args:
        out: the harvest folder.
        objects_dir: its objects' sub-folder (`met`).
        catalog: the folder's catalog.
        client: the image host's client (its own pacing budget).
        max_pixels: largest image accepted.
        totals: where fetched and unchanged views are counted.
        progress: show a progress bar.
        max_failures: failures in a row that stop the run (an outage).
    """

    out: Path
    objects_dir: str
    catalog: Catalog
    client: HttpClient
    max_pixels: int
    totals: ViewTotals
    progress: bool = True
    max_failures: int = 20

    def run(self) -> None:
        """Sync the views of every object from its stored record, then download the pending ones."""
        for row in self.catalog.rows():
            if row["state"] == "image":
                record = read_stored_record(self.out, row["record_path"])
                if record is not None:
                    self._sync(row, view_urls(record, row["image_url"] or ""))
            elif row["state"] == "skipped":  # withdrawn by a --since refetch: its views go with it
                self._sync(row, [])
        pending = [v for v in self.catalog.views() if v["state"] in ("pending", "failed")]
        in_a_row = 0
        for view in tqdm(pending, desc="views", unit="img", disable=not self.progress, leave=False):
            try:
                self._download(view)
                in_a_row = 0
            except FetchError as e:
                self.catalog.set_view(view["object_id"], view["view"], "failed", str(e))
                tqdm.write(f"object {view['object_id']} view {view['view']}: failed: {e}")
                in_a_row += 1
                if in_a_row >= self.max_failures:
                    raise NetworkError(f"{in_a_row} views failed in a row (last: {e})") from None

    def _sync(self, row: dict[str, Any], urls: list[str]) -> None:
        for stale in self.catalog.sync_views(row["object_id"], urls):
            (self.out / stale).unlink(missing_ok=True)
        if urls and row["image_path"]:
            self._move_primary(row["object_id"], row["image_path"])

    def _move_primary(self, object_id: int, image_path: str) -> None:
        """Put the primary image into the object's folder as view 0 (a killed move is finished on resume)."""
        folder = object_folder(self.out, self.objects_dir, object_id)
        current = self.out / image_path
        target = folder / f"{image_stem(object_id, PRIMARY_VIEW)}{current.suffix}"
        if current == target:
            return
        if current.is_file():
            folder.mkdir(parents=True, exist_ok=True)
            os.replace(current, target)
        elif not target.is_file():
            return  # nothing to move: the image stage will fetch it again
        for other in folder.glob(f"{image_stem(object_id, PRIMARY_VIEW)}.*"):
            if other != target:  # a refetched primary of another format replaced this one
                other.unlink(missing_ok=True)
        self.catalog.move_image(object_id, target.relative_to(self.out).as_posix())

    def _download(self, view: dict[str, Any]) -> None:
        """Fetch one view (conditional on its ETag when its file is there) and record the outcome."""
        object_id, index = view["object_id"], view["view"]
        old = self.out / view["image_path"] if view["image_path"] else None
        folder = object_folder(self.out, self.objects_dir, object_id)
        got = download_image(self.client, view["url"], view["etag"], old, folder, object_id, self.max_pixels,
                             view=index)
        if got.outcome == "unchanged":
            self.catalog.set_view(object_id, index, "image", "", view["image_path"], view["bytes"], view["sha256"],
                                  view["etag"])
            self.totals.views_unchanged += 1
            return
        if got.outcome != "stored":
            self.catalog.set_view(object_id, index, got.outcome, got.reason)
            if got.message:
                tqdm.write(f"object {object_id} view {index}: {got.outcome}: {got.message}")
            return
        assert got.stored is not None
        if old is not None and old != got.stored.path:
            old.unlink(missing_ok=True)  # the view changed format
        self.catalog.set_view(object_id, index, "image", "", got.stored.path.relative_to(self.out).as_posix(),
                              got.stored.size, got.stored.sha256, got.etag)
        self.totals.views_fetched += 1
