"""`radar eval-catalog`: de-rendering results of real photographs measured against a museum catalogue's table of
dimensions (and, where given, its digitised profile drawings and reference silhouettes).

Result folders are matched to catalogue rows by object id: a folder named `<id>` or `<id>_<view>` (also `-` or
`.` after the id) belongs to row `<id>`; the longest matching id wins. Per result: the fitted ratios body/height,
rim/body and foot/body beside the catalogue's and their % errors, the pitch, the quality status; the IoU of the
drawn silhouette (mask.png) with a reference silhouette (`--silhouettes DIR`: `<result>.png` or
`<id>_<view>.png` in the photo's pixels); the radius error against a digitised drawing (`--drawings DIR`:
`<id>.csv`, `height_cm,radius_cm`) in % of the height, mean, worst and at neck, shoulder and foot.
"""

from __future__ import annotations

import csv
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from radar_cli.errors import InputError
from radar_cli.evaluate import profiles as P
from radar_cli.fileio import read_image, read_json
from radar_cli.masks.crop import CropBox, cut
from radar_cli.masks.refine import iou
from radar_cli.results import MASK_FILE, list_results

DIMENSIONS = ("height_cm", "rim_cm", "body_cm", "foot_cm")
MAX_TABLE_BYTES = 10 * 1024 * 1024
SEPARATORS = "_-."
RATIO_NAMES = ("body/height", "rim/body", "foot/body")


@dataclass(frozen=True)
class CatalogueRow:
    """One object's catalogue dimensions in cm (None where the table leaves them blank)."""

    object_id: str
    height: float | None
    rim: float | None
    body: float | None
    foot: float | None

    def ratios(self) -> tuple[float | None, float | None, float | None]:
        div = lambda a, b: a / b if a is not None and b else None  # noqa: E731
        return div(self.body, self.height), div(self.rim, self.body), div(self.foot, self.body)


@dataclass
class ResultRecord:
    """What eval-catalog reports for one result folder."""

    result: str
    object_id: str
    view: str
    status: str = ""
    pitch: float | None = None
    fitted: list[float | None] = field(default_factory=lambda: [None] * 3)
    catalogue: list[float | None] = field(default_factory=lambda: [None] * 3)
    error_pct: list[float | None] = field(default_factory=lambda: [None] * 3)
    iou: float | None = None
    profile: dict[str, float] | None = None
    problem: str = ""


@dataclass(frozen=True)
class CatalogueReport:
    records: list[ResultRecord]
    unmatched_results: list[str]
    unmatched_rows: list[str]


def _number(value: str, path: Path, line: int, column: str) -> float | None:
    value = value.strip()
    if not value:
        return None
    try:
        number = float(value)
    except ValueError:
        raise InputError(f"{path}: line {line}: {column} is not a number ({value!r})") from None
    if not math.isfinite(number) or number <= 0:
        raise InputError(f"{path}: line {line}: {column} must be positive, got {value!r}")
    return number


def read_catalogue(path: str | Path) -> dict[str, CatalogueRow]:
    """The rows of a tab-separated catalogue table with the columns `object` and DIMENSIONS (others ignored).

    Raises:
        InputError: missing, too large, a missing column, a repeated object id or a bad number.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such catalogue table")
    if path.stat().st_size > MAX_TABLE_BYTES:
        raise InputError(f"{path}: larger than {MAX_TABLE_BYTES // 2**20} MiB, not a catalogue table")
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f, delimiter="\t")
        missing = [c for c in ("object", *DIMENSIONS) if c not in (reader.fieldnames or [])]
        if missing:
            raise InputError(f"{path}: missing column(s) {', '.join(missing)} (tab-separated, with a header)")
        rows: dict[str, CatalogueRow] = {}
        for line, row in enumerate(reader, start=2):
            oid = (row["object"] or "").strip()
            if not oid:
                continue
            if oid in rows:
                raise InputError(f"{path}: line {line}: object {oid!r} listed twice")
            rows[oid] = CatalogueRow(oid, *(_number(row[c] or "", path, line, c) for c in DIMENSIONS))
    return rows


def match(name: str, ids: list[str]) -> tuple[str, str] | None:
    """(object id, view) of a result folder name: the longest id that is the whole name or followed by one of
    SEPARATORS; None if none is."""
    best = None
    for oid in ids:
        if name == oid or (name.startswith(oid) and name[len(oid)] in SEPARATORS):
            if best is None or len(oid) > len(best):
                best = oid
    return None if best is None else (best, name[len(best) + 1 :])


def _reference_iou(folder: Path, material: dict, silhouettes: Path, object_id: str, view: str) -> float | None:
    """IoU of the drawn silhouette with the reference one cut by the result's crop box (None: no reference)."""
    names = [folder.name] + ([f"{object_id}_{view}"] if view else [])
    found = [silhouettes / f"{n}.png" for n in names if (silhouettes / f"{n}.png").is_file()]
    if not found:
        return None
    reference = read_image(found[0], "L") > 127
    drawn = read_image(folder / MASK_FILE, "L") > 127
    box = material.get("crop_box")
    if not (isinstance(box, list) and len(box) == 3):
        raise ValueError("material.json has no crop_box to place the reference silhouette")
    window = cut(reference.astype(np.float32), CropBox(*(int(v) for v in box)), drawn.shape[0], fill=0.0)
    return iou(drawn, window > 0.5)


def measure(folder: Path, row: CatalogueRow, view: str, drawings: Path | None,
            silhouettes: Path | None) -> ResultRecord:
    """One result folder against its catalogue row (problems recorded, not raised)."""
    record = ResultRecord(folder.name, row.object_id, view)
    try:
        material = read_json(folder / "material.json")
        record.status = str((material.get("quality") or {}).get("status", ""))
        record.pitch = float(material["pitch"])
        fitted = P.profile_from_material(material["radius"], float(material["height"]))
        record.fitted = list(P.ratios(*fitted).as_tuple())
        record.catalogue = list(row.ratios())
        record.error_pct = [None if c is None else abs(f - c) / c * 100.0
                            for f, c in zip(record.fitted, record.catalogue)]
        drawing = None if drawings is None else drawings / f"{row.object_id}.csv"
        if drawing is not None and drawing.is_file():
            record.profile = P.profile_error(fitted, P.read_drawn_profile(drawing.read_text(encoding="utf-8")))
        if silhouettes is not None:
            record.iou = _reference_iou(folder, material, silhouettes, row.object_id, view)
    except (OSError, KeyError, TypeError, ValueError, InputError) as e:
        record.problem = f"{type(e).__name__}: {e}"
    return record


def evaluate_catalogue(results: str | Path, dimensions: str | Path, drawings: str | Path | None = None,
                       silhouettes: str | Path | None = None) -> CatalogueReport:
    """Every result folder under `results` matched to `dimensions`' rows and measured."""
    rows = read_catalogue(dimensions)
    root = Path(results)
    if not root.is_dir():
        raise InputError(f"{root}: no such results folder")
    for folder, what in ((drawings, "--drawings"), (silhouettes, "--silhouettes")):
        if folder is not None and not Path(folder).is_dir():
            raise InputError(f"{folder}: {what} folder does not exist")
    ids = sorted(rows)
    records, unmatched, seen = [], [], set()
    for paths in list_results(root):
        found = match(paths.folder.name, ids)
        if found is None:
            unmatched.append(paths.folder.name)
            continue
        seen.add(found[0])
        records.append(measure(paths.folder, rows[found[0]], found[1], None if drawings is None else Path(drawings),
                               None if silhouettes is None else Path(silhouettes)))
    with_dimensions = [oid for oid in ids if rows[oid].height is not None]
    return CatalogueReport(records, unmatched, [oid for oid in with_dimensions if oid not in seen])


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def table(report: CatalogueReport) -> str:
    """A markdown table, one row per result: ratios fitted / catalogue (error %), pitch, status, IoU and the
    profile error against the drawing (% of height)."""
    head = ["result", "status", "pitch"] + list(RATIO_NAMES) + ["IoU", "profile mean / worst", "neck", "shoulder",
                                                               "foot"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in report.records:
        if r.problem:
            lines.append(f"| {r.result} | {r.problem} |" + " |" * (len(head) - 2))
            continue
        cells = [r.result, r.status or "-", _fmt(r.pitch, ".1f")]
        cells += [f"{_fmt(f, '.3f')} / {_fmt(c, '.3f')} ({_fmt(e, '.1f')}%)"
                  for f, c, e in zip(r.fitted, r.catalogue, r.error_pct)]
        cells.append(_fmt(r.iou, ".3f"))
        p = r.profile or {}
        cells.append(f"{_fmt(p.get('mean'), '.1f')} / {_fmt(p.get('worst'), '.1f')}")
        cells += [_fmt(p.get(k), ".1f") for k in ("neck", "shoulder", "foot")]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def summary(report: CatalogueReport) -> str:
    """One line: how many results, mean pitch and how many above 8 deg, ratio errors (mean, worst), IoU and
    the profile's landmark errors."""
    good = [r for r in report.records if not r.problem]
    errors = [e for r in good for e in r.error_pct if e is not None]
    pitches = [r.pitch for r in good if r.pitch is not None]
    parts = [f"{len(good)} results of {len({r.object_id for r in good})} objects"]
    if pitches:
        parts.append(f"pitch mean {np.mean(pitches):.1f} deg, {sum(p > 8 for p in pitches)} above 8")
    if errors:
        parts.append(f"ratio error mean {np.mean(errors):.1f}%, worst {np.max(errors):.1f}%")
    ious = [r.iou for r in good if r.iou is not None]
    if ious:
        parts.append(f"IoU mean {np.mean(ious):.3f}")
    drawn = [r.profile for r in good if r.profile]
    if drawn:
        parts.append("profile (% of height) mean " + ", ".join(
            f"{k} {np.mean([p[k] for p in drawn]):.1f}" for k in ("mean", "neck", "shoulder", "foot")))
    ok = sum(r.status == "ok" for r in good)
    parts.append(f"{ok} ok")
    return "eval-catalog: " + "; ".join(parts)


def report_json(report: CatalogueReport) -> dict:
    return {"results": [asdict(r) for r in report.records], "unmatched_results": report.unmatched_results,
            "unmatched_rows": report.unmatched_rows, "summary": summary(report)}
