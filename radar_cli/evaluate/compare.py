"""Two de-renderings of the same photographs side by side (e.g. `--refine none` against the default), where
there is no ground truth: per object, the silhouette IoU against the located silhouette and the reconstruction's
PSNR inside it, and a contact sheet with both reconstructions and albedos.

    python -m radar_cli.evaluate.compare RESULTS_A RESULTS_B [--sheet compare.png] [--json out.json]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from radar_cli.derender.export.quality import psnr
from radar_cli.derender.present.contact_sheet import LABEL_H, NAME_W, TILE, tile
from radar_cli.derender.present.report import read_records
from radar_cli.errors import InputError
from radar_cli.fileio import read_image, write_image, write_json
from radar_cli.masks.refine import iou
from radar_cli.results import ALBEDO_RENDERED_FILE, INPUT_FILE, MASK_FILE, RECON_FILE, SILHOUETTE_FILE


def object_scores(folder: Path) -> dict[str, float]:
    """IoU of the drawn silhouette (mask.png) with the located one (silhouette.png), and the PSNR (dB) of
    recon.png against input.png inside the located silhouette."""
    located = read_image(folder / SILHOUETTE_FILE, "L") > 127
    drawn = read_image(folder / MASK_FILE, "L") > 127
    if drawn.shape != located.shape:
        raise InputError(f"{folder}: mask.png and silhouette.png differ in size")
    recon = read_image(folder / RECON_FILE, "RGB")
    image = read_image(folder / INPUT_FILE, "RGB")
    return {"iou": iou(drawn, located), "psnr": psnr(recon[located], image[located]) if located.any() else math.nan}


def compare(a: Path, b: Path) -> dict[str, dict[str, dict[str, float]]]:
    """{object: {"a": scores, "b": scores}} for the objects both folders hold with a located silhouette."""
    names = {name for name, _ in read_records(a)} & {name for name, _ in read_records(b)}
    out = {}
    for name in sorted(names):
        if (a / name / SILHOUETTE_FILE).is_file() and (b / name / SILHOUETTE_FILE).is_file():
            out[name] = {"a": object_scores(a / name), "b": object_scores(b / name)}
    if not out:
        raise InputError(f"{a}, {b}: no object with a located silhouette in both")
    return out


def summary_table(scores: dict, label_a: str, label_b: str) -> str:
    """Markdown: mean and worst IoU, mean PSNR, for each folder."""
    lines = ["| | objects | silhouette IoU mean | worst | recon PSNR in silhouette (dB) |", "|---|---|---|---|---|"]
    for key, label in (("a", label_a), ("b", label_b)):
        iou = [s[key]["iou"] for s in scores.values()]
        psnr = [s[key]["psnr"] for s in scores.values()]
        lines.append(f"| {label} | {len(iou)} | {np.mean(iou):.3f} | {np.min(iou):.3f} | {np.mean(psnr):.2f} |")
    return "\n".join(lines)


def side_by_side(a: Path, b: Path, names: list[str], out: Path, label_a: str, label_b: str) -> Path:
    """One row per object: input, then each folder's reconstruction and albedo."""
    columns = [(a, INPUT_FILE, "input"), (a, RECON_FILE, f"recon: {label_a}"), (b, RECON_FILE, f"recon: {label_b}"),
               (a, ALBEDO_RENDERED_FILE, f"albedo: {label_a}"), (b, ALBEDO_RENDERED_FILE, f"albedo: {label_b}")]
    sheet = Image.new("RGB", (NAME_W + TILE * len(columns), LABEL_H + TILE * len(names)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for c, (_, _, label) in enumerate(columns):
        draw.text((NAME_W + c * TILE + 4, 2), label, fill=(0, 0, 0))
    for r, name in enumerate(names):
        y = LABEL_H + r * TILE
        draw.text((4, y + TILE // 2), name[:24], fill=(0, 0, 0))
        for c, (root, file, _) in enumerate(columns):
            matte = root / name / MASK_FILE if file == ALBEDO_RENDERED_FILE else None
            sheet.paste(tile(root / name / file, matte), (NAME_W + c * TILE, y))
    write_image(out, np.asarray(sheet))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a", type=Path)
    parser.add_argument("b", type=Path)
    parser.add_argument("--labels", default="network,refined", help="Names of A and B in the table and sheet.")
    parser.add_argument("--sheet", type=Path, default=None, help="Write the side-by-side contact sheet here.")
    parser.add_argument("--json", type=Path, default=None, help="Write the per-object scores here.")
    args = parser.parse_args()
    label_a, label_b = args.labels.split(",", 1)
    scores = compare(args.a, args.b)
    print(summary_table(scores, label_a, label_b))
    if args.json:
        write_json(args.json, scores)
    if args.sheet:
        print(f"contact sheet: {side_by_side(args.a, args.b, sorted(scores), args.sheet, label_a, label_b)}")


if __name__ == "__main__":
    main()
