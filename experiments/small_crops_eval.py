"""Locate the vessel of every small-crop case (`experiments.small_crops`) as `radar derender` does and measure
the located silhouette against the reference.

    python -m experiments.small_crops_eval data/small_crops [--sheet docs/images/small-crops.png]
    python -m experiments.small_crops_eval data/small_crops --results RESULTS   # a `radar derender` run's folder

The located object is the core and the appendages together (the vessel's whole outline, like the reference);
the IoU is read in the located crop at 256 px, the reference's parts outside the crop counted as missed. With
--results, the silhouette.png and appendages.png that `radar derender data/small_crops/images --out RESULTS`
wrote are read instead, mapped with the crop_box of material.json.
"""

from __future__ import annotations

import argparse
import csv
import json
import time
from pathlib import Path

import cv2
import numpy as np

from radar_cli.errors import InputError
from radar_cli.fileio import read_image, write_image
from radar_cli.masks import crop as crops
from radar_cli.masks.locate import locate_object

EVAL_SIZE = 256
PASS_IOU = 0.9


def located(image: np.ndarray, name: str) -> tuple[crops.CropBox, np.ndarray, np.ndarray] | None:
    """(crop box, located object EVAL_SIZE^2 bool, its core) or None if nothing was located."""
    try:
        found = locate_object(image, EVAL_SIZE, name)
    except InputError:
        return None
    return found.box, found.silhouette | found.appendages, found.silhouette


def from_results(folder: Path) -> tuple[crops.CropBox, np.ndarray, np.ndarray] | None:
    """The same read from a `radar derender` object folder (None if it failed)."""
    record = folder / "material.json"
    if not record.is_file():
        return None
    box = crops.CropBox.from_record(json.loads(record.read_text()))
    core = read_image(folder / "silhouette.png", "L") > 127
    extra = folder / "appendages.png"
    whole = core | (read_image(extra, "L") > 127) if extra.is_file() else core
    k = EVAL_SIZE / core.shape[0]
    grow = (lambda m: cv2.resize(m.astype(np.float32), (EVAL_SIZE, EVAL_SIZE)) > 0.5) if k != 1 else (lambda m: m)
    return box, grow(whole), grow(core)


def measure(cases: Path, results: Path | None) -> list[dict]:
    """One row per case: case, kind, IoU (0 if nothing located), seconds."""
    rows = []
    with open(cases / "cases.tsv", newline="") as f:
        for case in csv.DictReader(f, delimiter="\t"):
            image = read_image(cases / "images" / f"{case['case']}.jpg", "RGB")
            reference = read_image(cases / "reference" / f"{case['case']}.png", "L") > 127
            t0 = time.process_time()
            found = from_results(results / case["case"]) if results else located(image, case["case"])
            seconds = time.process_time() - t0
            score = 0.0
            if found is not None:
                score = crops.reference_iou(found[1], reference, found[0])
            rows.append({**case, "iou": score, "seconds": seconds, "found": found, "image": image,
                         "reference": reference})
    return rows


def table(rows: list[dict]) -> str:
    """Markdown: per kind n, mean, min, share >= PASS_IOU; then all."""
    lines = ["| kind | n | mean IoU | min IoU | IoU >= 0.9 |", "|---|---|---|---|---|"]
    kinds = list(dict.fromkeys(r["kind"] for r in rows))
    for kind in [*kinds, "all"]:
        s = np.array([r["iou"] for r in rows if kind in ("all", r["kind"])])
        passed = int((s >= PASS_IOU).sum())
        lines.append(f"| {kind} | {len(s)} | {s.mean():.3f} | {s.min():.3f} | {passed} of {len(s)} |")
    return "\n".join(lines)


def _tile(image: np.ndarray, side: int, mask: np.ndarray | None = None, colour=(255, 0, 0)) -> np.ndarray:
    k = side / max(image.shape[:2])
    small = cv2.resize(image, (round(image.shape[1] * k), round(image.shape[0] * k)), interpolation=cv2.INTER_AREA)
    if mask is not None:
        m = cv2.resize(mask.astype(np.uint8), small.shape[1::-1], interpolation=cv2.INTER_NEAREST) > 0
        small = small.copy()
        small[m] = (0.5 * small[m] + 0.5 * np.array(colour)).astype(np.uint8)
    tile = np.full((side, side, 3), 255, np.uint8)
    tile[: small.shape[0], : small.shape[1]] = small
    return tile


def sheet(rows: list[dict], path: Path, side: int = 150, columns: int = 2) -> None:
    """PNG: per case the photo, the reference (green) and the located silhouette in the photo (red)."""
    tiles = []
    for r in rows:
        h, w = r["reference"].shape
        photo_mask = np.zeros((h, w), bool)
        if r["found"] is not None:
            box, whole, _ = r["found"]
            affine = np.vstack([crops.crop_affine(box, EVAL_SIZE), [0, 0, 1]])
            photo_mask = cv2.warpAffine(whole.astype(np.float32), np.linalg.inv(affine)[:2], (w, h)) > 0.5
        group = np.concatenate([_tile(r["image"], side), _tile(r["image"], side, r["reference"], (0, 200, 0)),
                                _tile(r["image"], side, photo_mask)], axis=1)
        cv2.putText(group, f"{r['case']} {r['iou']:.2f}", (3, side - 5), cv2.FONT_HERSHEY_SIMPLEX, 0.4,
                    (0, 0, 255), 1)
        tiles.append(np.pad(group, ((2, 2), (2, 2), (0, 0)), constant_values=255))
    while len(tiles) % columns:
        tiles.append(np.full_like(tiles[0], 255))
    write_image(path, np.concatenate([np.concatenate(tiles[i : i + columns], axis=1)
                                      for i in range(0, len(tiles), columns)], axis=0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", type=Path, help="the folder experiments.small_crops wrote")
    parser.add_argument("--results", type=Path, help="read a `radar derender` results folder instead")
    parser.add_argument("--sheet", type=Path, help="also write a contact sheet PNG")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    rows = measure(args.cases, args.results)
    for r in rows:
        print(f"  {r['case']:14s} {r['source']:22s} IoU {r['iou']:.3f}  {r['seconds']:.2f} s")
    print(table(rows))
    if args.sheet:
        sheet(rows, args.sheet)


if __name__ == "__main__":
    main()
