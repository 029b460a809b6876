"""The results root's overview files: index.html (a static gallery that needs no network), summary.csv (one
row per object) and failures.csv (one row per input that could not be de-rendered)."""

from __future__ import annotations

import csv
import html
import io
import json
from pathlib import Path

from radar_cli.derender.inputs import Failure
from radar_cli.fileio import write_text
from radar_cli.results import (ALBEDO_FILE, ALBEDO_RENDERED_FILE, ENV_PREVIEW_FILE, FAILURES_FILE, INDEX_FILE,
                               INPUT_FILE, MATERIAL_FILE, MATERIAL_SPHERE_FILE, MESH_GLB_FILE, MESH_OBJ_FILE,
                               NORMAL_RENDERED_FILE, RECON_FILE, RELIT_PREFIX, SUMMARY_FILE, TURNTABLE_GIF_FILE,
                               list_results)

SUMMARY_COLUMNS = ("object", "status", "reason", "source", "pitch", "roll", "tx", "ty", "height", "alpha", "rho",
                   "roughness", "crop_box", "model", "silhouette_iou", "symmetry", "recon_psnr", "appendage_fraction",
                   "cut_edges")
QUALITY_COLUMNS = ("silhouette_iou", "symmetry", "recon_psnr", "appendage_fraction")
STATUS_ORDER = {"failed": 0, "review": 1, "ok": 2}  # worst first; objects without a quality record come last
DECOMPOSITION = ((INPUT_FILE, "input"), (RECON_FILE, "reconstruction"), (ALBEDO_RENDERED_FILE, "albedo"),
                 (NORMAL_RENDERED_FILE, "normals"), (MATERIAL_SPHERE_FILE, "material"),
                 (ENV_PREVIEW_FILE, "lighting"), (TURNTABLE_GIF_FILE, "turntable"))
STYLE = """body{font-family:sans-serif;margin:1em;background:#fafafa}
table{border-collapse:collapse}td{padding:4px;text-align:center;vertical-align:top;font-size:12px}
tr.obj{border-top:1px solid #ccc}img{width:128px;image-rendering:auto;background:#fff}
img.wide{width:384px;height:128px}img.env{width:192px;height:64px}.name{text-align:left;max-width:14em}"""


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
        return STATUS_ORDER.get(status, len(STATUS_ORDER)), item[0]

    return sorted(records, key=rank)


def write_summary(root: Path, records: list[tuple[str, dict]]) -> None:
    """summary.csv: one row per object with its status and quality scores, pose, shape and material."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for name, rec in records:
        row = {k: rec.get(k, "") for k in SUMMARY_COLUMNS}
        row["object"] = name
        row["crop_box"] = " ".join(str(v) for v in rec.get("crop_box", []))
        quality = rec.get("quality") if isinstance(rec.get("quality"), dict) else {}
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


def _img(src: str, css: str = "") -> str:
    cls = f' class="{css}"' if css else ""
    return f'<img src="{html.escape(src)}"{cls} loading="lazy" alt="{html.escape(src)}">'


def _object_row(root: Path, name: str, rec: dict) -> str:
    """One gallery row: caption, decomposition, albedo map, relit views and mesh links."""
    q = html.escape(name)
    cells = [f'<td class="name"><b>{q}</b><br>pitch {rec.get("pitch", 0):.1f}&deg;, '
             f'shininess {rec.get("alpha", 0):.0f}, specular {rec.get("rho", 0):.2f}<br>'
             f'<a href="{q}/{MESH_GLB_FILE}">GLB</a> &middot; <a href="{q}/{MESH_OBJ_FILE}">OBJ</a> &middot; '
             f'<a href="{q}/{MATERIAL_FILE}">JSON</a></td>']
    for file, _ in DECOMPOSITION:
        css = "env" if file == ENV_PREVIEW_FILE else ""
        cells.append(f"<td>{_img(f'{name}/{file}', css)}</td>" if (root / name / file).is_file() else "<td></td>")
    cells.append(f"<td>{_img(f'{name}/{ALBEDO_FILE}', 'wide')}</td>")
    for env in rec.get("environments", []):
        cells.append(f"<td>{_img(f'{name}/{RELIT_PREFIX}{env}.png')}</td>")
    return f'<tr class="obj">{"".join(cells)}</tr>'


def write_index(root: Path, records: list[tuple[str, dict]], n_failed: int) -> Path:
    """index.html: one row per object; relative links only, so the folder can be copied or zipped."""
    envs = records[0][1].get("environments", []) if records else []
    head = ["object"] + [label for _, label in DECOMPOSITION] + ["albedo (360&deg;)"]
    head += [f"relit: {html.escape(e)}" for e in envs]
    rows = "\n".join(_object_row(root, name, rec) for name, rec in records)
    failed = (f'<p>{n_failed} input(s) could not be de-rendered: see <a href="{FAILURES_FILE}">{FAILURES_FILE}</a>'
              f"</p>" if n_failed else "")
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>radar: {len(records)} de-rendered objects</title>
<style>{STYLE}</style></head><body>
<h1>radar de-rendering results</h1>
<p>{len(records)} object(s). Per object: the input crop, the reconstruction, albedo and normals in the input view,
the recovered material on a sphere, the lighting (environment map), a turntable, the unwrapped 360&deg; albedo
(back mirrored from the front) and relit views. Table: <a href="{SUMMARY_FILE}">{SUMMARY_FILE}</a>.</p>{failed}
<table><tr>{"".join(f"<th>{h}</th>" for h in head)}</tr>
{rows}
</table></body></html>
"""
    write_text(root / INDEX_FILE, page)
    return root / INDEX_FILE


def write_report(root: str | Path, failures: list[Failure]) -> Path:
    """Write summary.csv, failures.csv and index.html for every complete object under `root`."""
    root = Path(root)
    records = by_status(read_records(root))
    write_summary(root, records)
    write_failures(root, failures)
    return write_index(root, records, len(failures))
