"""The results root's overview files: summary.csv (one row per object), failures.csv (one row per input that
could not be de-rendered) and the gallery (index.html, see radar_cli.derender.present.gallery)."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

from radar_cli.derender.present.gallery import write_gallery
from radar_cli.derender.run.inputs import Failure
from radar_cli.fileio import write_text
from radar_cli.results import FAILURES_FILE, MATERIAL_FILE, SUMMARY_FILE, list_results

SUMMARY_COLUMNS = ("object", "status", "reason", "source", "pitch", "roll", "tx", "ty", "height", "alpha", "rho",
                   "roughness", "crop_box", "crop_turn", "model", "silhouette_iou", "symmetry", "recon_psnr",
                   "appendage_fraction", "outline_support", "object_symmetry", "outline_residual", "foot_asymmetry",
                   "foot_aside", "edge_roughness", "top_dome", "base_width", "base_spread", "painted_fill", "roundness",
                   "rim_contrast", "shading_range", "mouth_error", "highlight_excess", "glaring_highlights",
                   "colour_shift", "face", "cut_edges", "resolution", "refine", "refine_reason", "refine_iou")
QUALITY_COLUMNS = ("silhouette_iou", "symmetry", "recon_psnr", "appendage_fraction", "outline_support",
                   "object_symmetry", "outline_residual", "foot_asymmetry", "foot_aside", "edge_roughness", "top_dome",
                   "base_width", "base_spread", "painted_fill", "roundness", "rim_contrast", "shading_range",
                   "mouth_error", "highlight_excess", "glaring_highlights", "colour_shift", "face")
STATUS_ORDER = {"failed": 0, "review": 1, "ok": 2}  # worst first; objects without a quality record come last


def read_records(root: Path) -> list[tuple[str, dict]]:
    """(object name, material.json record) of every complete object folder under `root`, sorted by name."""
    records = []
    for paths in list_results(root):
        try:
            records.append((paths.folder.name, json.loads((paths.folder / MATERIAL_FILE).read_text("utf-8"))))
        except (OSError, ValueError):
            continue  # an unfinished folder: not part of the report until it is complete
    return records


def by_status(records: list[tuple[str, dict]]) -> list[tuple[str, dict]]:
    """The records with `failed` first, then `review`, then `ok` (by name within each)."""
    def rank(item: tuple[str, dict]) -> tuple[int, str]:
        quality = item[1].get("quality")
        status = quality.get("status") if isinstance(quality, dict) else None
        return STATUS_ORDER.get(str(status), len(STATUS_ORDER)), item[0]

    return sorted(records, key=rank)


def write_summary(root: Path, records: list[tuple[str, dict]]) -> None:
    """summary.csv: one row per object with its status and quality scores, pose, shape and material, and what
    the refinement did."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for name, rec in records:
        row = {k: rec.get(k, "") for k in SUMMARY_COLUMNS}
        row["object"] = name
        row["crop_box"] = " ".join(str(v) for v in rec.get("crop_box", []))
        refine = rec.get("refine") or {}
        row["refine"], row["refine_reason"] = refine.get("status", ""), refine.get("reason", "")
        iou = (refine.get("silhouette_iou") or {}).get("refined")
        row["refine_iou"] = "" if iou is None else f"{iou:.4f}"
        quality = rec.get("quality")
        if not isinstance(quality, dict):
            quality = {}
        row.update({k: quality.get(k) for k in QUALITY_COLUMNS}, status=quality.get("status", ""),
                   reason="; ".join(quality.get("reasons", [])), cut_edges=" ".join(quality.get("cut_edges", [])))
        for k in ("pitch", "roll", "tx", "ty", "height", "alpha", "rho", "roughness") + QUALITY_COLUMNS:
            if isinstance(row[k], float):
                row[k] = f"{row[k]:.4g}"
            elif row[k] is None:
                row[k] = ""
        writer.writerow(row)
    write_text(root / SUMMARY_FILE, buf.getvalue())


def write_failures(root: Path, failures: list[Failure]) -> None:
    """failures.csv: every input of the run that could not be de-rendered (header only if none)."""
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(("source", "problem"))
    for f in failures:
        writer.writerow((f.source, f.problem))
    write_text(root / FAILURES_FILE, buf.getvalue())


def write_report(root: str | Path, failures: list[Failure]) -> Path:
    """Write summary.csv, failures.csv and index.html for every complete object under `root`."""
    root = Path(root)
    records = by_status(read_records(root))
    write_summary(root, records)
    write_failures(root, failures)
    return write_gallery(root, records, len(failures))
