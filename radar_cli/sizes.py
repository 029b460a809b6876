"""An object's real size in cm (catalogue height and diameters), where it came from, and the dimensions table
`radar derender --dimensions FILE` reads (TSV or CSV: an id column, height_cm, optional rim/body/foot diameters).

Ids are matched to results by name: a result `<id>`, `<id>_<view>`, or a photo in a folder named `<id>`.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Iterable, Literal

from radar_cli.errors import InputError

SizeStatus = Literal["ok", "none", "ambiguous"]
ID_COLUMNS = ("object", "object_id", "id")
HEIGHT_COLUMN = "height_cm"
DIAMETER_COLUMNS = {"rim_cm": "rim_cm", "body_cm": "body_cm", "foot_cm": "foot_cm", "diameter_cm": "diameter_cm"}
DESCRIPTION_COLUMNS = ("title", "object_name", "kind", "shape", "classification")
"""Columns whose words describe the object (joined with ' / '), read by the status (catalogue_terms)."""
MAX_DESCRIPTION = 500  # characters of a description kept
MAX_TABLE_BYTES = 16 * 1024 * 1024
MAX_CM = 100_000.0  # 1 km: anything larger is a typo or a unit mix-up


@dataclass(frozen=True)
class ObjectSize:
    """A catalogued size, in cm (None where not given).

    Attributes:
        height_cm: overall height; meshes are scaled to it.
        rim_cm, body_cm, foot_cm: diameters of the mouth, of the widest part, of the foot.
        diameter_cm: a diameter the catalogue does not place (`Diam.`).
        width_cm: width (with handles, where the catalogue says `W.`).
        status: `ok` (a height is known), `none` (the record gives no size) or `ambiguous` (it gives sizes but
            not which one is the height).
        source: where it came from (`table FILE`, `met record measurements`, `met record dimensions`).
        note: what the parser left out or chose (several heights, a range, a missing record).
    """

    height_cm: float | None = None
    rim_cm: float | None = None
    body_cm: float | None = None
    foot_cm: float | None = None
    diameter_cm: float | None = None
    width_cm: float | None = None
    status: SizeStatus = "none"
    source: str = ""
    note: str = ""

    @property
    def known(self) -> bool:
        """True when the height is known (the mesh can be put in metres)."""
        return self.status == "ok" and self.height_cm is not None

    def to_dict(self) -> dict:
        """The JSON form (every field, None as null)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: object) -> "ObjectSize | None":
        """The size stored by `to_dict` (from a catalog or meta.json: untrusted), or None if malformed."""
        if not isinstance(data, dict):
            return None
        values: dict = {}
        for key in ("height_cm", "rim_cm", "body_cm", "foot_cm", "diameter_cm", "width_cm"):
            v = data.get(key)
            if v is not None and not (isinstance(v, (int, float)) and not isinstance(v, bool) and 0 < v < MAX_CM):
                return None
            values[key] = None if v is None else float(v)
        status = data.get("status")
        if status not in ("ok", "none", "ambiguous") or (status == "ok" and values["height_cm"] is None):
            return None
        return cls(**values, status=status, source=str(data.get("source") or "")[:200],
                   note=str(data.get("note") or "")[:500])

    def lengths(self) -> dict[str, float]:
        """The known lengths by name without the `_cm` suffix (height, rim, body, foot, diameter, width)."""
        names = ("height", "rim", "body", "foot", "diameter", "width")
        return {n: getattr(self, f"{n}_cm") for n in names if getattr(self, f"{n}_cm") is not None}


def centimetres(text: str, where: str, column: str) -> float | None:
    """A table cell as a length in cm; None when empty."""
    text = text.strip()
    if not text:
        return None
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{where}: {column} {text!r} is not a number") from None
    if not (math.isfinite(value) and 0 < value < MAX_CM):
        raise InputError(f"{where}: {column} {text!r} is not a length in cm")
    return value


def description_of(words: Iterable[object]) -> str:
    """A catalogue description from its parts (title, object name, kind, ...): the non-empty texts joined with
    ' / ', at most MAX_DESCRIPTION characters."""
    texts = (w.strip() for w in words if isinstance(w, str))
    return " / ".join(t for t in texts if t)[:MAX_DESCRIPTION]


def _id_column(header: list[str], path: Path) -> str:
    for name in ID_COLUMNS:
        if name in header:
            return name
    raise InputError(f"{path}: no object id column (one of {', '.join(ID_COLUMNS)}) in the header")


@dataclass(frozen=True)
class SizeTable:
    """Sizes by object id (case-insensitive), read from a dimensions table."""

    path: Path
    sizes: dict[str, ObjectSize]
    descriptions: dict[str, str] = field(default_factory=dict)

    def lookup(self, name: str, photo: Path | None = None) -> ObjectSize | None:
        """The size of the result `name` (`<id>` or `<id>_<view>`, the longest matching id), else of the folder
        the photo lies in (`<id>/<view>.jpg`); None if no id matches or its row has no height."""
        return self.sizes.get(self._key(name, photo))

    def describe(self, name: str, photo: Path | None = None) -> str:
        """The description (DESCRIPTION_COLUMNS) of the object matched as by `lookup`, '' if none."""
        return self.descriptions.get(self._key(name, photo), "")

    def _key(self, name: str, photo: Path | None) -> str:
        """The id `name` matches, else the folder the photo lies in ('' without a photo)."""
        found = self.match(name)
        if found is not None:
            return found[0]
        return photo.parent.name.casefold() if photo is not None else ""


    def match(self, name: str) -> tuple[str, str] | None:
        """(id key, view) of the result `name`: `<id>` (view '') or `<id>_<view>`, the longest matching id;
        None if none matches."""
        key = name.casefold()
        known = self.sizes.keys() | self.descriptions.keys()
        if key in known:
            return key, ""
        prefixed = [i for i in known if key.startswith(i + "_")]
        if not prefixed:
            return None
        best = max(prefixed, key=len)
        return best, name[len(best) + 1 :]


def read_size_table(path: str | Path) -> SizeTable:
    """Read a dimensions table: tab-separated if its header has a tab, else comma-separated; rows without a
    height (fragments) give no size, their description (DESCRIPTION_COLUMNS) is kept; other columns are ignored.

    Raises:
        InputError: unreadable, no id column, neither a height_cm nor a description column, a bad number, or an
            id given twice.
    """
    path = Path(path)
    try:
        if path.stat().st_size > MAX_TABLE_BYTES:
            raise InputError(f"{path}: dimensions table larger than {MAX_TABLE_BYTES} bytes")
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: cannot read the dimensions table ({e})") from None
    first = text.split("\n", 1)[0]
    rows = list(csv.reader(io.StringIO(text), delimiter="\t" if "\t" in first else ","))
    header = [h.strip().casefold() for h in rows[0]] if rows else []
    id_column = _id_column(header, path)
    if HEIGHT_COLUMN not in header and not set(DESCRIPTION_COLUMNS) & set(header):
        raise InputError(f"{path}: no {HEIGHT_COLUMN} column (nor {', '.join(DESCRIPTION_COLUMNS)}) in the header")
    sizes: dict[str, ObjectSize] = {}
    descriptions: dict[str, str] = {}
    for line, row in enumerate(rows[1:], 2):
        if not any(cell.strip() for cell in row):
            continue
        cells = dict(zip(header, row))
        where = f"{path}:{line}"
        object_id = cells.get(id_column, "").strip()
        if not object_id:
            raise InputError(f"{where}: no object id")
        if object_id.casefold() in sizes.keys() | descriptions.keys():
            raise InputError(f"{where}: object {object_id!r} is given twice")
        description = description_of(cells.get(c) for c in DESCRIPTION_COLUMNS)
        if description:
            descriptions[object_id.casefold()] = description
        height = centimetres(cells.get(HEIGHT_COLUMN, ""), where, HEIGHT_COLUMN)
        if height is None:
            continue
        diameters: dict[str, Any] = {field: centimetres(cells.get(col, ""), where, col)
                                     for col, field in DIAMETER_COLUMNS.items()}
        sizes[object_id.casefold()] = ObjectSize(height_cm=height, **diameters, status="ok",
                                                 source=f"table {path.name}")
    return SizeTable(path, sizes, descriptions)
