"""Each input's real size: from `radar derender --dimensions FILE` first, else from the harvest the photo came
from (the meta.json `radar masks` wrote beside it, or the catalog of the `radar fetch` folder it lies in)."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

from radar_cli.derender.run.inputs import InputItem
from radar_cli.harvest.catalog import photo_row, stored_size
from radar_cli.sizes import ObjectSize, SizeTable, read_size_table

META_FILE = "meta.json"
MAX_META_BYTES = 1024 * 1024  # meta.json beside an input is untrusted: refuse larger files


class SizeFinder:
    """Looks sizes up for inputs (one thread: it holds the catalogs' connections; close it after use).

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

    def __enter__(self) -> "SizeFinder":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def find(self, item: InputItem) -> ObjectSize | None:
        """The item's size: the table's row for its name or folder, else its harvested record's (which may say
        `none` or `ambiguous`); None when neither knows the object."""
        if self.table is not None:
            size = self.table.lookup(item.name, item.image_path)
            if size is not None:
                return size
        return self._harvested(item.image_path)

    def _harvested(self, photo: Path) -> ObjectSize | None:
        meta = photo.parent / META_FILE
        try:
            if meta.is_file():
                if meta.stat().st_size > MAX_META_BYTES:
                    return None
                found = json.loads(meta.read_text("utf-8")).get("attribution")
                return ObjectSize.from_dict(found.get("size")) if isinstance(found, dict) else None
            row = photo_row(photo, self.catalogs)
        except (OSError, ValueError, AttributeError, sqlite3.Error):
            return None
        return stored_size(row["size"]) if row else None
