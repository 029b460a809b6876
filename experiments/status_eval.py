"""The quality status against truth: how many wrong results are `ok` and how many right ones are not, per set
(docs/real-photos.md, "What `ok` means").

    python -m experiments.status_eval RESULTS... [--truth-tsv data/status_cases/truth.tsv] [--rescore]

Each object folder's name says its set: `<object>_<view>` for ../shared/data/cva10 (objects.tsv: fragments and
top views must not be `ok`; a whole vessel's side view must be `ok` unless its result is wrong: pitch over 8 deg
on these level photographs, a catalogue ratio off by over 10 %, its solid's IoU with the silhouette under 0.85),
`met_*` for ../shared/data/real_vases (EXPECTED_MET), names in a generated cases' truth.tsv
(experiments.status_cases). `--rescore` judges the written files again with the code as it is (the same
scores `radar derender` records; the outline support, the photo-edge and the neighbour records, which need the
photo before cropping, kept from material.json).
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path

import cv2
import numpy as np

from radar_cli.derender.export.likeness import glaring_highlights, highlight_excess, luminance
from radar_cli.derender.export.quality import fit_scores, judge, psnr
from radar_cli.derender.export.renders import ViewRenderer
from radar_cli.derender.run.state import read_state
from radar_cli.fileio import read_image
from radar_cli.results import (
    ALBEDO_RENDERED_FILE,
    APPENDAGES_FILE,
    INPUT_FILE,
    MATERIAL_FILE,
    RECON_FILE,
    SILHOUETTE_FILE,
    SPECULAR_RENDERED_FILE,
)

MAX_PITCH, MAX_RATIO_ERROR, MIN_IOU = 8.0, 0.10, 0.85
# the glass vessels blown or moulded as (two) heads and the urn with a head for a lid (SOURCES.tsv's titles): not
# solids of revolution
EXPECTED_MET = {key: "not" for key in ("DP107005", "DP107356", "DP107639", "DP117537", "DP233495", "DP250469")}
KEPT = ("outline_support", "cut_edges", "frame_coverage", "neighbour_cut", "base_off_axis", "above_rim",
        "above_rim_rise", "above_rim_mirrored", "painted_fill", "greyscale", "views_outline")


def drawn_highlight(folder: Path) -> np.ndarray | None:
    """specular_rendered.png of an object folder (H x W uint8), None where it was not written."""
    path = folder / SPECULAR_RENDERED_FILE
    return read_image(path, "L") if path.is_file() else None


def rescore(folder: Path) -> dict:
    """The quality record of a written object folder, judged again with the current scores."""
    record = json.loads((folder / MATERIAL_FILE).read_text())
    photo, recon = read_image(folder / INPUT_FILE), read_image(folder / RECON_FILE)
    mask = lambda name: (read_image(folder / name, "L") > 127) if (folder / name).is_file() else None  # noqa: E731
    view = ViewRenderer(read_state(folder), photo.shape[0])
    rendered, mouth = view.hits.mask[0].numpy(), view.hits.inner[0].numpy()
    highlight = drawn_highlight(folder)
    quality = {**fit_scores(photo, mask(SILHOUETTE_FILE), mask(APPENDAGES_FILE), rendered, recon, mouth, highlight),
               **{k: record["quality"].get(k) for k in KEPT}}
    status, reasons = judge(quality)
    return {**quality, "status": status, "reasons": reasons}


def appearance(folder: Path) -> dict[str, float]:
    """How true recon.png and the albedo are to the photo inside the silhouette: the share of pixels the
    reconstruction draws much brighter (invented highlights), the share it draws far brighter away from the
    outline (white spots, `glaring_highlights`), its PSNR, and the correlation of the albedo
    (albedo_rendered.png) with the photo's highlight map (the photo's luminance above its 15 px median: the
    studio's reflections; near 0 when they left the albedo)."""
    photo, recon = read_image(folder / INPUT_FILE), read_image(folder / RECON_FILE)
    albedo = read_image(folder / ALBEDO_RENDERED_FILE)
    sil = read_image(folder / SILHOUETTE_FILE, "L") > 127
    lum = luminance(photo)
    highlights = np.clip(lum - cv2.medianBlur((lum * 255).astype(np.uint8), 15) / 255.0, 0, None)[sil]
    corr = np.corrcoef(highlights, luminance(albedo)[sil])[0, 1] if highlights.std() > 0 else 0.0
    highlight = drawn_highlight(folder)
    return {"brighter": highlight_excess(photo, recon, sil),
            "white_spots": glaring_highlights(photo, recon, sil, highlight),
            "psnr": psnr(recon[sil], photo[sil]),
            "albedo_vs_highlights": float(corr)}


def sheet(rows: list[tuple[Path, str, str, str]], path: Path, tile: int = 128) -> None:
    """A contact sheet: per object the photo, recon.png, the albedo, the normals and a relit view, labelled
    with its name, what it should be and its status (first reason). rows: (folder, expected, status, reason)."""
    from PIL import Image, ImageDraw

    files = (INPUT_FILE, RECON_FILE, ALBEDO_RENDERED_FILE, "normal_rendered.png", "relit_studio.png")
    height = tile + 14
    canvas = Image.new("RGB", (tile * len(files), height * len(rows)), "white")
    draw = ImageDraw.Draw(canvas)
    for i, (folder, expected, status, reason) in enumerate(rows):
        for j, name in enumerate(files):
            if (folder / name).is_file():
                canvas.paste(Image.open(folder / name).convert("RGB").resize((tile, tile)), (j * tile, i * height + 14))
        colour = (0, 110, 0) if (status == "ok") == (expected == "ok") else (200, 0, 0)
        draw.text((2, i * height + 1), f"{folder.name}: should be {expected}, is {status}. {reason}"[:110], fill=colour)
    path.parent.mkdir(parents=True, exist_ok=True)
    canvas.quantize(256).save(path)


def catalogue(path: Path) -> dict[str, dict[str, str]]:
    """objects.tsv rows by object id."""
    lines = path.read_text().splitlines()
    head = lines[0].split("\t")
    return {row[0]: dict(zip(head, row)) for row in (line.split("\t") for line in lines[1:])}


def ratios(radius: list[float], height: float) -> dict[str, float]:
    """body/height, rim/body, foot/body of a fitted profile (rows top first; rim and foot: the widest of the
    top and bottom 8 % of rows; body: the widest below the top quarter)."""
    r = np.asarray(radius)
    n = len(r)
    edge = max(1, int(0.08 * n))
    body = r[n // 4:].max()
    return {"body/height": body / height, "rim/body": r[:edge].max() / body, "foot/body": r[-edge:].max() / body}


def cva_truth(name: str, record: dict, table: dict) -> tuple[str, str, str]:
    """(set, expected `ok`/`not`, why) of a cva10 result."""
    obj, view = name.rsplit("_", 1)
    row = table[obj]
    if row["kind"] == "fragment":
        return "cva10 fragments", "not", "fragment"
    if view == "top":
        return "cva10 top views", "not", "top view"
    fitted = ratios(record["radius"], record["height"])
    h, rim, body, foot = (float(row[k]) for k in ("height_cm", "rim_cm", "body_cm", "foot_cm"))
    truth = {"body/height": body / h, "rim/body": rim / body, "foot/body": foot / body}
    worst = max(abs(fitted[k] / truth[k] - 1) for k in truth)
    sil_iou = record["quality"].get("silhouette_iou") or 0.0
    wrong = [w for w, bad in ((f"pitch {record['pitch']:.1f}", record["pitch"] > MAX_PITCH),
                              (f"ratio {worst:.0%}", worst > MAX_RATIO_ERROR),
                              (f"IoU {sil_iou:.2f}", sil_iou < MIN_IOU)) if bad]
    return "cva10 side views", ("not" if wrong else "ok"), ", ".join(wrong) or "right"


def truth_of(name: str, record: dict, table: dict, cases: dict[str, str]) -> tuple[str, str, str]:
    if name in cases:
        return "generated", cases[name], name.rsplit("_", 1)[0]
    if name.startswith("met_"):
        key = next((k for k in EXPECTED_MET if k in name), None)
        return "Met photos", EXPECTED_MET.get(key, "ok"), "head vessel" if key else "vessel"
    return cva_truth(name, record, table)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("results", type=Path, nargs="+")
    parser.add_argument("--truth-tsv", type=Path, help="truth.tsv of experiments.status_cases")
    parser.add_argument("--catalogue", type=Path, default=Path("../shared/data/cva10/objects.tsv"))
    parser.add_argument("--rescore", action="store_true")
    parser.add_argument("--verbose", action="store_true")
    parser.add_argument("--appearance", action="store_true", help="also the appearance figures per set")
    parser.add_argument("--sheet", type=Path, help="write a contact sheet of the objects here")
    parser.add_argument("--top", metavar="SCORE", help="also the 6 highest values of this quality score")
    args = parser.parse_args()
    cases = {}
    if args.truth_tsv:
        lines = args.truth_tsv.read_text().splitlines()[1:]
        cases = {row[0]: row[2] for row in (line.split("\t") for line in lines)}
    table = catalogue(args.catalogue)
    counts = defaultdict(lambda: [0, 0, 0, 0])  # n, expected not ok, wrong ones `ok`, right ones not `ok`
    looks = defaultdict(list)
    shown, values = [], []
    for root in args.results:
        for folder in sorted(p for p in root.iterdir() if (p / MATERIAL_FILE).is_file()):
            record = json.loads((folder / MATERIAL_FILE).read_text())
            quality = rescore(folder) if args.rescore else record["quality"]
            group, expected, why = truth_of(folder.name, record, table, cases)
            c = counts[group]
            c[0] += 1
            c[1] += expected == "not"
            c[2] += expected == "not" and quality["status"] == "ok"
            c[3] += expected == "ok" and quality["status"] != "ok"
            shown.append((folder, expected, quality["status"], (quality["reasons"] or [""])[0]))
            if args.top and quality.get(args.top) is not None:
                values.append((quality[args.top], f"{root.name}/{folder.name}"))
            if args.appearance:
                looks[group].append(appearance(folder))
            if args.verbose:
                reasons = "; ".join(quality["reasons"])
                print(f"{folder.name:28s} {expected:4s} {quality['status']:7s} {why:22s} {reasons}")
    if args.sheet:
        sheet(shown, args.sheet)
    print("| set | n | should not be `ok` | wrong ones `ok` | right ones not `ok` |\n|---|---|---|---|---|")
    for group, (n, bad, wrong_ok, right_not) in sorted(counts.items()):
        print(f"| {group} | {n} | {bad} | {wrong_ok} | {right_not} of {n - bad} |")
    if args.top:
        print(f"{args.top} over {len(values)} objects, highest: " +
              ", ".join(f"{name} {value:.2f}" for value, name in sorted(values, reverse=True)[:6]))
    for group, rows in sorted(looks.items()):
        means = {k: np.mean([r[k] for r in rows]) for k in rows[0]}
        print(f"{group}: " + ", ".join(f"{k} {v:.4f}" for k, v in means.items()))


if __name__ == "__main__":
    main()
