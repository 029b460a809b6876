"""What the catalogue says of each input: its real size and its description (title, object name, kind, shape),
from `radar derender --dimensions FILE` first, else from the harvest the photo came from (the meta.json `radar
masks` wrote beside it, or the catalog of the `radar fetch` folder it lies in)."""

from __future__ import annotations

import json
import sqlite3
from dataclasses import dataclass
from pathlib import Path

from radar_cli.derender.run.inputs import InputItem
from radar_cli.harvest.catalog import photo_row, stored_size
from radar_cli.sizes import ObjectSize, SizeTable, description_of, read_size_table

META_FILE = "meta.json"
MAX_META_BYTES = 1024 * 1024  # meta.json beside an input is untrusted: refuse larger files


@dataclass(frozen=True)
class ObjectRecord:
    """What the catalogue says of one input.

    Attributes:
        size: its catalogued size (None: no table row or harvested record knows the object).
        description: its table row's title, object name, kind and shape, or its harvested record's title and
            object name ('' where none is known).
    """

    size: ObjectSize | None = None
    description: str = ""


class RecordFinder:
    """Looks inputs up in the dimensions table and their harvests (one thread: it holds the catalogs'
    connections; close it after use).

    Args:
        table: the --dimensions file, or None.
    """

    def __init__(self, table: Path | None = None):
        self.table: SizeTable | None = read_size_table(table) if table is not None else None
        self.catalogs: dict[Path, sqlite3.Connection] = {}

    def close(self) -> None:
        """Close the catalogs opened."""
        for db in self.catalogs.values():
            db.close()
        self.catalogs.clear()

    def __enter__(self) -> "RecordFinder":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def find(self, item: InputItem) -> ObjectRecord:
        """The item's size and description: the table's row for its name or folder, else its harvested record's
        (whose size may say `none` or `ambiguous`)."""
        size, description = None, ""
        if self.table is not None:
            size = self.table.lookup(item.name, item.image_path)
            description = self.table.describe(item.name, item.image_path)
        harvested = None if size is not None and description else self._harvested(item.image_path)
        if harvested is None:
            return ObjectRecord(size, description)
        if size is None:
            size = stored_size(harvested["size"]) if isinstance(harvested.get("size"), str) else (
                ObjectSize.from_dict(harvested.get("size")))
        if not description:
            description = description_of(harvested.get(key) for key in ("title", "object_name"))
        return ObjectRecord(size, description)

    def _harvested(self, photo: Path) -> dict | None:
        """The input's harvested record (meta.json's attribution, or its catalog row), None if it has none."""
        meta = photo.parent / META_FILE
        try:
            if meta.is_file():
                if meta.stat().st_size > MAX_META_BYTES:
                    return None
                found = json.loads(meta.read_text("utf-8")).get("attribution")
                return found if isinstance(found, dict) else None
            return photo_row(photo, self.catalogs)
        except (OSError, ValueError, AttributeError, sqlite3.Error):
            return None
