"""The harvest catalog: one SQLite file in DATA with one row per object (state, reason, metadata, image facts).

States follow the pipeline: `searched` (id known) -> `record` (object record stored, image wanted) -> `image`
(image validated and stored). `skipped` rows carry a reason (not_found, bad_id, not_public_domain, no_image,
image_too_large); `failed` rows carry the error and are retried on the next run. Every update is its own
transaction, so a killed run leaves a consistent catalog. Later stages read it through `iter_images`.
The `size` column holds the size parsed from the record (radar_cli.sizes.ObjectSize as JSON). With
`radar fetch --images all` the `views` table holds one row per additional image (view 1, 2, ... in the record's
`additionalImages` order): `pending` -> `image`, or `skipped`/`failed` with a reason like the objects'.
"""

from __future__ import annotations

import json
import sqlite3
from collections import Counter
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Iterable, Iterator

from radar_cli.errors import InputError
from radar_cli.harvest.dimensions import size_of_record
from radar_cli.sizes import ObjectSize

CATALOG_NAME = "catalog.sqlite"
OBJECTS_DIR = "met"
"""The folder under a harvest's --out that holds the photos: <id>.<ext>, or <id>/ with every view."""
STATES = ("searched", "record", "image", "skipped", "failed")
LICENCE_PD = "CC0-1.0"
LICENCE_OTHER = "not public domain"

# Catalog column -> object record field, for the metadata later stages need.
RECORD_FIELDS = {
    "title": "title",
    "object_name": "objectName",
    "classification": "classification",
    "department": "department",
    "culture": "culture",
    "object_date": "objectDate",
    "object_url": "objectURL",
    "credit_line": "creditLine",
    "metadata_date": "metadataDate",
}

SCHEMA = """
CREATE TABLE IF NOT EXISTS objects (
    object_id INTEGER PRIMARY KEY,
    rank INTEGER NOT NULL,
    state TEXT NOT NULL,
    reason TEXT NOT NULL DEFAULT '',
    title TEXT, object_name TEXT, classification TEXT, department TEXT, culture TEXT, object_date TEXT,
    object_url TEXT, licence TEXT, credit_line TEXT, metadata_date TEXT,
    image_url TEXT, record_path TEXT, image_path TEXT, bytes INTEGER, sha256 TEXT, etag TEXT,
    updated_at TEXT NOT NULL, size TEXT
);
CREATE INDEX IF NOT EXISTS objects_state ON objects (state, rank);
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS views (
    object_id INTEGER NOT NULL, view INTEGER NOT NULL, url TEXT NOT NULL, state TEXT NOT NULL,
    reason TEXT NOT NULL DEFAULT '', image_path TEXT, bytes INTEGER, sha256 TEXT, etag TEXT,
    updated_at TEXT NOT NULL, PRIMARY KEY (object_id, view)
);
"""
ADDED_COLUMNS = {"size": "TEXT"}  # columns newer than the first catalogs, added to those when opened
VIEW_STATES = ("pending", "image", "skipped", "failed")


@dataclass(frozen=True)
class ImageEntry:
    """One harvested image with what is needed to attribute results derived from it."""

    object_id: int
    image_path: Path
    title: str
    credit_line: str
    licence: str
    object_url: str
    size: ObjectSize | None = None


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


class Catalog:
    """The SQLite catalog of one harvest folder (WAL mode, one transaction per update).

    Args:
        path: the catalog file (created with its schema when missing).
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self.db = sqlite3.connect(self.path, isolation_level=None, timeout=30.0)
            self.db.row_factory = sqlite3.Row
            self.db.execute("PRAGMA journal_mode=WAL")
            self.db.execute("PRAGMA synchronous=NORMAL")
            self.db.executescript(SCHEMA)
            have = {r[1] for r in self.db.execute("PRAGMA table_info(objects)")}
            for column, kind in ADDED_COLUMNS.items():
                if column not in have:
                    self.db.execute(f"ALTER TABLE objects ADD COLUMN {column} {kind}")
        except sqlite3.DatabaseError as e:
            raise InputError(f"{self.path}: not a usable catalog ({e})") from None

    def close(self) -> None:
        """Close the database connection."""
        self.db.close()

    def __enter__(self) -> "Catalog":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- writing -------------------------------------------------------------------------------------------
    def add_searched(self, object_ids: Iterable[int]) -> int:
        """Add new ids in the given order as `searched`; known ids are left alone. Returns how many were new."""
        (top,) = self.db.execute("SELECT COALESCE(MAX(rank), -1) FROM objects").fetchone()
        new = 0
        with self.db:
            self.db.execute("BEGIN")
            for object_id in object_ids:
                cur = self.db.execute(
                    "INSERT OR IGNORE INTO objects (object_id, rank, state, updated_at) VALUES (?, ?, 'searched', ?)",
                    (int(object_id), top + 1 + new, _now()))
                new += cur.rowcount
        return new

    def set_record(self, object_id: int, record: dict[str, Any], record_path: str, image_url: str,
                   state: str, reason: str = "") -> None:
        """Store the metadata of a fetched object record and move it to `state` (record or skipped)."""
        values = {col: str(record.get(key) or "") for col, key in RECORD_FIELDS.items()}
        values["licence"] = LICENCE_PD if record.get("isPublicDomain") is True else LICENCE_OTHER
        values["size"] = json.dumps(size_of_record(record).to_dict())
        cols = ", ".join(f"{c} = :{c}" for c in values)
        self.db.execute(
            f"UPDATE objects SET {cols}, record_path = :record_path, image_url = :image_url, state = :state, "
            "reason = :reason, updated_at = :now WHERE object_id = :id",
            {**values, "record_path": record_path, "image_url": image_url, "state": state, "reason": reason,
             "now": _now(), "id": object_id})

    def set_image(self, object_id: int, image_path: str, size: int, sha256: str, etag: str) -> None:
        """Mark an object's image as validated and stored."""
        self.db.execute(
            "UPDATE objects SET state = 'image', reason = '', image_path = ?, bytes = ?, sha256 = ?, etag = ?, "
            "updated_at = ? WHERE object_id = ?", (image_path, size, sha256, etag, _now(), object_id))

    def clear_image(self, object_id: int) -> None:
        """Forget an object's stored image (its file was removed)."""
        self.db.execute("UPDATE objects SET image_path = NULL, bytes = NULL, sha256 = NULL, etag = NULL, "
                        "updated_at = ? WHERE object_id = ?", (_now(), object_id))

    def move_image(self, object_id: int, image_path: str) -> None:
        """Record that an object's stored image now lives at `image_path` (same bytes)."""
        self.db.execute("UPDATE objects SET image_path = ?, updated_at = ? WHERE object_id = ?",
                        (image_path, _now(), object_id))

    def set_size(self, object_id: int, size: ObjectSize) -> None:
        """Store an object's parsed size."""
        self.db.execute("UPDATE objects SET size = ? WHERE object_id = ?", (json.dumps(size.to_dict()), object_id))

    def sync_views(self, object_id: int, urls: list[str]) -> list[str]:
        """Make an object's additional views (1, 2, ...) the given URLs: new or changed ones become `pending`;
        views past the list are forgotten. Returns the image paths of the forgotten and changed views."""
        stale = []
        with self.db:
            self.db.execute("BEGIN")
            known = {r["view"]: r for r in self.db.execute("SELECT * FROM views WHERE object_id = ?", (object_id,))}
            for view, row in known.items():
                if (view > len(urls) or row["url"] != urls[view - 1]) and row["image_path"]:
                    stale.append(row["image_path"])
            self.db.execute("DELETE FROM views WHERE object_id = ? AND view > ?", (object_id, len(urls)))
            for view, url in enumerate(urls, 1):
                if view not in known or known[view]["url"] != url:
                    self.db.execute(
                        "INSERT OR REPLACE INTO views (object_id, view, url, state, updated_at) "
                        "VALUES (?, ?, ?, 'pending', ?)", (object_id, view, url, _now()))
        return stale

    def set_view(self, object_id: int, view: int, state: str, reason: str = "", image_path: str | None = None,
                 size: int | None = None, sha256: str | None = None, etag: str | None = None) -> None:
        """Move a view to `state`; with `image` also record its stored file (other states keep the old one)."""
        assert state in VIEW_STATES, state
        if state == "image":
            self.db.execute("UPDATE views SET state = 'image', reason = '', image_path = ?, bytes = ?, sha256 = ?, "
                            "etag = ?, updated_at = ? WHERE object_id = ? AND view = ?",
                            (image_path, size, sha256, etag, _now(), object_id, view))
        else:
            self.db.execute("UPDATE views SET state = ?, reason = ?, updated_at = ? WHERE object_id = ? AND view = ?",
                            (state, reason, _now(), object_id, view))

    def set_state(self, object_id: int, state: str, reason: str = "") -> None:
        """Move an object to `skipped` or `failed` (with its reason or error), or back to an earlier state."""
        assert state in STATES, state
        self.db.execute("UPDATE objects SET state = ?, reason = ?, updated_at = ? WHERE object_id = ?",
                        (state, reason, _now(), object_id))

    def mark_changed(self, object_ids: Iterable[int]) -> int:
        """Send known objects whose record changed back to `searched`. Returns the count.

        The image URL is cleared (so a failed refetch retries the record), the stored image's path, hash and
        ETag are kept (so an unchanged image is confirmed by a conditional GET instead of downloaded again).
        """
        n = 0
        with self.db:
            self.db.execute("BEGIN")
            for object_id in object_ids:
                n += self.db.execute(
                    "UPDATE objects SET state = 'searched', reason = '', image_url = NULL, updated_at = ? "
                    "WHERE object_id = ? AND state != 'searched'", (_now(), int(object_id))).rowcount
        return n

    def set_meta(self, key: str, value: str) -> None:
        """Store a run-level setting or fact."""
        self.db.execute("INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)", (key, value))

    # --- reading -------------------------------------------------------------------------------------------
    def get_meta(self, key: str, default: str | None = None) -> str | None:
        """Read a run-level setting or fact."""
        row = self.db.execute("SELECT value FROM meta WHERE key = ?", (key,)).fetchone()
        return default if row is None else row[0]

    def get(self, object_id: int) -> sqlite3.Row | None:
        """One object's row, or None."""
        return self.db.execute("SELECT * FROM objects WHERE object_id = ?", (object_id,)).fetchone()

    def pending_records(self) -> list[int]:
        """Ids whose record is still to fetch: `searched`, or `failed` before a record was stored."""
        return [r[0] for r in self.db.execute(
            "SELECT object_id FROM objects WHERE state = 'searched' "
            "OR (state = 'failed' AND image_url IS NULL) ORDER BY rank")]

    def pending_images(self) -> list[int]:
        """Ids whose image is still to fetch: `record`, or `failed` after the record was stored."""
        return [r[0] for r in self.db.execute(
            "SELECT object_id FROM objects WHERE state = 'record' "
            "OR (state = 'failed' AND image_url IS NOT NULL) ORDER BY rank")]

    def views(self, object_id: int | None = None) -> list[dict[str, Any]]:
        """The additional views of one object (or of all, in search order), as dicts."""
        where, args = ("WHERE v.object_id = ?", (object_id,)) if object_id is not None else ("", ())
        return [dict(r) for r in self.db.execute(
            f"SELECT v.* FROM views v JOIN objects o USING (object_id) {where} ORDER BY o.rank, v.view", args)]

    def view_counts(self) -> dict[str, int]:
        """Number of additional views per state (only the states present)."""
        return dict(self.db.execute("SELECT state, COUNT(*) FROM views GROUP BY state").fetchall())

    def counts(self) -> dict[str, int]:
        """Number of objects per state (every state present, zeros included)."""
        found = dict(self.db.execute("SELECT state, COUNT(*) FROM objects GROUP BY state").fetchall())
        return {s: found.get(s, 0) for s in STATES}

    def skip_reasons(self) -> Counter[str]:
        """Number of skipped objects per reason."""
        return Counter(dict(self.db.execute(
            "SELECT reason, COUNT(*) FROM objects WHERE state = 'skipped' GROUP BY reason").fetchall()))

    def rows(self) -> list[dict[str, Any]]:
        """Every row as a dict, in search order."""
        return [dict(r) for r in self.db.execute("SELECT * FROM objects ORDER BY rank")]


def open_catalog(data_dir: str | Path) -> Catalog:
    """Open (or create) the catalog of a harvest folder."""
    return Catalog(Path(data_dir) / CATALOG_NAME)


def iter_images(data_dir: str | Path) -> Iterator[ImageEntry]:
    """Yield every harvested image of a folder, in search order, with its attribution.

    Args:
        data_dir: the folder `radar fetch --out` wrote.

    Raises:
        InputError: no catalog in the folder.
    """
    data_dir = Path(data_dir)
    if not (data_dir / CATALOG_NAME).is_file():
        raise InputError(f"{data_dir / CATALOG_NAME}: no harvest catalog (run `radar fetch --out {data_dir}`)")
    with open_catalog(data_dir) as catalog:
        rows = catalog.db.execute(
            "SELECT object_id, image_path, title, credit_line, licence, object_url, size FROM objects "
            "WHERE state = 'image' ORDER BY rank").fetchall()
    for r in rows:
        yield ImageEntry(r["object_id"], data_dir / r["image_path"], r["title"], r["credit_line"], r["licence"],
                         r["object_url"], stored_size(r["size"]))


def stored_size(text: str | None) -> ObjectSize | None:
    """The size kept in a catalog's `size` column (JSON), or None when absent or malformed."""
    try:
        return ObjectSize.from_dict(json.loads(text)) if text else None
    except ValueError:
        return None


PHOTO_COLUMNS = ("object_id", "title", "object_name", "credit_line", "licence", "object_url", "size")
CATALOG_DEPTH = 4  # a photo lies at most this many folders below its harvest folder (met/<id>/<id>_1.jpg: 2)


def photo_row(photo: Path, catalogs: dict[Path, sqlite3.Connection]) -> dict[str, Any] | None:
    """The catalog row (PHOTO_COLUMNS) of the object a harvested photo shows, its primary image or one of its
    views, found through the catalog.sqlite of a folder above it (opened read-only once into `catalogs`, which
    the caller closes); None when the photo is not in a harvest.

    Raises:
        sqlite3.Error, OSError: an unreadable catalog.
    """
    for data_dir in list(photo.parents)[:CATALOG_DEPTH]:
        if not (data_dir / CATALOG_NAME).is_file():
            continue
        db = catalogs.get(data_dir)
        if db is None:
            db = catalogs[data_dir] = sqlite3.connect(f"file:{data_dir / CATALOG_NAME}?mode=ro", uri=True)
        have = {r[1] for r in db.execute("PRAGMA table_info(objects)")}
        columns = ", ".join(c if c in have else f"NULL AS {c}" for c in PHOTO_COLUMNS)
        rel = photo.relative_to(data_dir).as_posix()
        row = db.execute(f"SELECT {columns} FROM objects WHERE image_path = ?", (rel,)).fetchone()
        has_views = db.execute("SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = 'views'").fetchone()
        if row is None and has_views:
            row = db.execute(f"SELECT {columns} FROM objects WHERE object_id = "
                             "(SELECT object_id FROM views WHERE image_path = ?)", (rel,)).fetchone()
        return dict(zip(PHOTO_COLUMNS, row)) if row else None
    return None
