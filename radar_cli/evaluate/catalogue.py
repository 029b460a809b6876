"""`radar eval-catalog`: de-rendering results of real photographs measured against a museum catalogue's table of
dimensions (and, where given, its digitised profile drawings and reference silhouettes).

Result folders are matched to the table's rows by object id as `radar derender --dimensions` matches them
(radar_cli.sizes: a folder named `<id>` or `<id>_<view>`, case-insensitive, the longest matching id); rows
without a height (fragments) are left out. Per result: the fitted ratios body/height,
rim/body and foot/body beside the catalogue's and their % errors, the pitch, the quality status; the IoU of the
drawn silhouette (mask.png) with a reference silhouette (`--silhouettes DIR`: `<result>.png` or
`<id>_<view>.png` in the photo's pixels); the radius error against a digitised drawing (`--drawings DIR`:
`<id>.csv`, `height_cm,radius_cm`) in % of the height, mean, worst and at neck, shoulder and foot.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from radar_cli.errors import InputError
from radar_cli.evaluate import profiles as P
from radar_cli.fileio import read_image, read_json
from radar_cli.masks.crop import CropBox, reference_iou
from radar_cli.results import MASK_FILE, list_results
from radar_cli.sizes import ObjectSize, read_size_table

RATIO_NAMES = ("body/height", "rim/body", "foot/body")


def catalogue_ratios(size: ObjectSize) -> list[float | None]:
    """The catalogue's body/height, rim/body and foot/body (None where a diameter is not given)."""
    div = lambda a, b: a / b if a is not None and b else None  # noqa: E731
    return [div(size.body_cm, size.height_cm), div(size.rim_cm, size.body_cm), div(size.foot_cm, size.body_cm)]


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


def _reference_iou(folder: Path, material: dict, silhouettes: Path, object_id: str, view: str) -> float | None:
    """IoU of the drawn silhouette with the reference one in the result's crop box, the reference's parts outside
    the crop counted as missed (None: no reference)."""
    names = [folder.name] + ([f"{object_id}_{view}"] if view else [])
    found = [silhouettes / f"{n}.png" for n in names if (silhouettes / f"{n}.png").is_file()]
    if not found:
        return None
    reference = read_image(found[0], "L") > 127
    drawn = read_image(folder / MASK_FILE, "L") > 127
    box = material.get("crop_box")
    if not (isinstance(box, list) and len(box) == 3):
        raise ValueError("material.json has no crop_box to place the reference silhouette")
    return reference_iou(drawn, reference, CropBox.from_record(material))


def measure(folder: Path, object_id: str, view: str, size: ObjectSize, drawings: Path | None,
            silhouettes: Path | None) -> ResultRecord:
    """One result folder against its catalogue row (problems recorded, not raised); `object_id` as the folder's
    name spells it (drawings and silhouettes are looked up by it)."""
    record = ResultRecord(folder.name, object_id, view)
    try:
        material = read_json(folder / "material.json")
        record.status = str((material.get("quality") or {}).get("status", ""))
        record.pitch = float(material["pitch"])
        fitted = P.profile_from_material(material["radius"], float(material["height"]))
        ratios = P.ratios(*fitted).as_tuple()
        record.fitted = list(ratios)
        record.catalogue = catalogue_ratios(size)
        record.error_pct = [None if c is None else abs(f - c) / c * 100.0 for f, c in zip(ratios, record.catalogue)]
        drawing = None if drawings is None else drawings / f"{object_id}.csv"
        if drawing is not None and drawing.is_file():
            record.profile = P.profile_error(fitted, P.read_drawn_profile(drawing.read_text(encoding="utf-8")))
        if silhouettes is not None:
            record.iou = _reference_iou(folder, material, silhouettes, object_id, view)
    except (OSError, KeyError, TypeError, ValueError, InputError) as e:
        record.problem = f"{type(e).__name__}: {e}"
    return record


def evaluate_catalogue(results: str | Path, dimensions: str | Path, drawings: str | Path | None = None,
                       silhouettes: str | Path | None = None) -> CatalogueReport:
    """Every result folder under `results` matched to `dimensions`' rows and measured."""
    table = read_size_table(dimensions)
    root = Path(results)
    if not root.is_dir():
        raise InputError(f"{root}: no such results folder")
    for folder, what in ((drawings, "--drawings"), (silhouettes, "--silhouettes")):
        if folder is not None and not Path(folder).is_dir():
            raise InputError(f"{folder}: {what} folder does not exist")
    records, unmatched, seen = [], [], set()
    for paths in list_results(root):
        name = paths.folder.name
        found = table.match(name)
        if found is None or found[0] not in table.sizes:  # no row, or one without a size (a fragment)
            unmatched.append(name)
            continue
        key, view = found
        seen.add(key)
        records.append(measure(paths.folder, name[: len(key)], view, table.sizes[key],
                               None if drawings is None else Path(drawings),
                               None if silhouettes is None else Path(silhouettes)))
    return CatalogueReport(records, unmatched, [key for key in table.sizes if key not in seen])


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
