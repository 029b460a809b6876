"""How well objects are located in hard framings, and whether the quality status tells good results from bad.

    python -m experiments.framing_eval --synthetic 24      # the table in docs/real-photos.md

Sources: the real photographs of ../shared/data/real_vases (when present; the reference silhouette is the one
located on the original photo) and rendered vases pasted over studio backdrops (the truth is known). Each is
turned into every `variants.KINDS` framing; the located silhouette (core and appendages) is compared with the
reference in the located crop, the reference's parts outside the crop counted as missed. Pasted vases also get
handles: their located core is compared with the handle-free truth. Every variant is then de-rendered as
`radar derender` does (output side 512, `--refine`, full by default) and its `quality` status is set against
its silhouette IoU.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from radar_cli.derender.export.quality import assess
from radar_cli.derender.refine.driver import RefineMode
from radar_cli.derender.run.inputs import (
    Prepared,
    located_input,
    white_backdrop,
    whole_photo,
)
from radar_cli.derender.run.predictor import Predictor
from radar_cli.derender.run.upsample import full_resolution_state
from radar_cli.errors import InputError
from radar_cli.fileio import read_image, write_image
from radar_cli.masks import crop as crops
from radar_cli.masks.locate import locate_object
from radar_cli.masks.synthetic import composite, render_vases
from radar_cli.masks.variants import KINDS, Variant, make_variant, with_handles

REAL_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "real_vases"  # ../shared from the repo
EVAL_SIZE = 256  # silhouettes are compared in crops of this side
SOURCE_SIDE = 600  # real photos are brought to this long side first (speed; the framings are what is tested)


@dataclass
class Results:
    """Per item: kind, source, silhouette IoU, and (after `judge_status`) the quality status."""

    rows: list[dict] = field(default_factory=list)

    def add(self, **row: object) -> None:
        self.rows.append(dict(row))


def photo_mask(mask: np.ndarray, box: crops.CropBox, shape: tuple[int, int]) -> np.ndarray:
    """An S x S crop mask warped back to the H x W photo it was cut from."""
    affine = np.vstack([crops.crop_affine(box, mask.shape[0]), [0, 0, 1]])
    back = np.linalg.inv(affine)[:2]
    return cv2.warpAffine(mask.astype(np.float32), back, shape[::-1], flags=cv2.INTER_LINEAR) > 0.5


def real_sources(folder: Path) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, photo at SOURCE_SIDE, silhouette located on it) of every photo in `folder`."""

    out = []
    for path in sorted(folder.glob("*.jpg")):
        photo = read_image(path, "RGB")
        k = SOURCE_SIDE / max(photo.shape[:2])
        photo = cv2.resize(photo, None, fx=k, fy=k, interpolation=cv2.INTER_AREA)
        found = locate_object(photo, EVAL_SIZE, path.name)
        out.append((path.stem, photo, photo_mask(found.silhouette | found.appendages, found.box, photo.shape[:2])))
    return out


def synthetic_sources(n: int, seed: int) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, photo, truth) of n rendered vases pasted over plain or gradient studio backdrops."""
    vases, alpha, masks = render_vases(n, 192, seed)
    rng = np.random.default_rng(seed + 1)
    out = []
    for i in range(n):
        photo, truth = composite(vases[i], alpha[i], masks[i], ("plain", "gradient")[i % 2], rng)
        out.append((f"synthetic_{i:03d}", photo, truth))
    return out


def located_iou(variant: Variant) -> tuple[float, float]:
    """(IoU of the located object with the variant's truth, IoU of the located core with it), both in the
    located crop; (0, 0) if nothing is found."""

    try:
        found = locate_object(variant.image, EVAL_SIZE)
    except InputError:
        return 0.0, 0.0
    return (crops.reference_iou(found.silhouette | found.appendages, variant.truth, found.box),
            crops.reference_iou(found.silhouette, variant.truth, found.box))


def evaluate(sources: list[tuple[str, np.ndarray, np.ndarray]], seed: int, synthetic: set[str],
             kinds: tuple[str, ...] = (*KINDS, "handles")) -> tuple[Results, list[tuple[str, Variant]]]:
    """Locate every variant of every source (of `kinds` only; the others are drawn all the same, so a variant
    is the same whichever kinds are located); pasted vases also get handles. Each source draws its variants
    from its own generator: they do not change when another source's reference does."""
    results, items = Results(), []
    for n, (name, photo, truth) in enumerate(sources):
        rng = np.random.default_rng((seed + 2, n))
        for k, kind in enumerate(KINDS):
            variant = make_variant(kind, photo, truth, rng, index=n + k)
            if kind in kinds:
                results.add(kind=kind, source=name, iou=located_iou(variant)[0])
                items.append((name, variant))
        if name in synthetic:
            handled = Variant("handles", with_handles(photo, truth, rng)[0], truth)
            if "handles" in kinds:
                results.add(kind="handles", source=name, iou=located_iou(handled)[1])
                items.append((name, handled))
    return results, items


BROKEN = ("whole_frame", "shifted")  # silhouettes spoilt on purpose: what the status must not call ok


def spoilt_input(kind: str, variant: Variant, size: int):
    """The network's input of a variant with a wrong silhouette: `whole_frame` (no object located: the whole
    photo padded square, its silhouette the frame) or `shifted` (the located core moved sideways by a fifth of
    its width). Returns (Prepared, IoU of its silhouette with the truth)."""
    import dataclasses


    if kind == "whole_frame":
        rgb = variant.image[..., :3]
        box = whole_photo(rgb)
        frame = crops.cut(np.ones(rgb.shape[:2], np.float32), box, size, fill=0) > 0.5

        prepared = Prepared(crops.cut(rgb, box, size), box, rgb.shape[1::-1], silhouette=frame,
                            cut_edges=("top", "bottom", "left", "right"), frame_coverage=1.0)
    else:  # at both sides, as a locator that found it would give it
        prepared = located_input(variant.image, size, "shifted", backdrop="keep")
        cols = np.nonzero(prepared.silhouette.any(0))[0]
        shift = max(1, (cols.max() - cols.min()) // 5)
        moved = np.roll(prepared.silhouette, shift, axis=1)
        photo_moved = np.roll(prepared.photo_silhouette, round(shift * prepared.side / size), axis=1)
        prepared = dataclasses.replace(
            prepared, silhouette=moved, image=white_backdrop(prepared.image, moved),
            photo_silhouette=photo_moved, photo_image=white_backdrop(prepared.photo_scene, photo_moved),
            backdrop="white")
    return prepared, crops.reference_iou(prepared.silhouette, variant.truth, prepared.crop)


def add_spoilt(results: Results, items: list[tuple[str, Variant]], size: int) -> dict:
    """Append a `BROKEN` item per `tight` variant; returns their prepared inputs by row index."""
    spoilt = {}
    for name, variant in [item for item in items if item[1].kind == "tight"]:
        for kind in BROKEN:
            prepared, score = spoilt_input(kind, variant, size)
            results.add(kind=kind, source=name, iou=score)
            items.append((name, Variant(kind, variant.image, variant.truth)))
            spoilt[len(items) - 1] = prepared
    return spoilt


def judge_status(results: Results, items: list[tuple[str, Variant]], batch: int = 16,
                 refine: RefineMode = "full") -> None:
    """De-render every item as `radar derender --refine REFINE` does (bundled model, output side 512) and record
    its quality status; spoilt silhouettes (`BROKEN`) are added and judged as well."""

    predictor = Predictor.from_checkpoint(device="cpu", refine=refine)
    size = predictor.setup.render.image_size
    spoilt = add_spoilt(results, items, size)
    for start in range(0, len(items), batch):
        chunk = list(range(start, min(start + batch, len(items))))
        prepared = {}
        for i in chunk:
            try:
                prepared[i] = spoilt.get(i) or located_input(items[i][1].image, size, items[i][0])
            except InputError:
                results.rows[i].update(status="failed", reasons=["no object located"])
        keys = sorted(prepared)
        if not keys:
            continue
        dec = predictor.predict([prepared[i].image for i in keys], [prepared[i].silhouette for i in keys])
        for j, i in enumerate(keys):
            prep = prepared[i]
            assert prep.photo_image is not None
            refined, _ = predictor.refine_object(dec.select(j), prep.image, prep.photo_image, prep.photo_silhouette)
            quality = assess(prep, full_resolution_state(refined, prep, predictor.setup, predictor.albedo))
            results.rows[i].update(status=quality["status"], reasons=quality["reasons"], quality=quality)


def iou_table(results: Results) -> str:
    """Markdown: mean / min located-silhouette IoU per variant kind (handles: the core against the
    handle-free truth; `BROKEN`: the spoilt silhouettes, at the model's size)."""
    lines = ["| variant | n | mean IoU | min IoU | IoU >= 0.9 |", "|---|---|---|---|---|"]
    for kind in (*KINDS, "handles", *BROKEN):
        s = np.array([r["iou"] for r in results.rows if r["kind"] == kind])
        if len(s):
            lines.append(f"| {kind} | {len(s)} | {s.mean():.3f} | {s.min():.3f} | {(s >= 0.9).mean():.0%} |")
    return "\n".join(lines)


def status_table(results: Results) -> str:
    """Markdown: status counts by silhouette IoU band."""
    bands = (("IoU < 0.8", lambda v: v < 0.8), ("0.8 <= IoU <= 0.95", lambda v: 0.8 <= v <= 0.95),
             ("IoU > 0.95", lambda v: v > 0.95))
    lines = ["| silhouette | n | ok | review | failed |", "|---|---|---|---|---|"]
    for label, test in bands:
        rows = [r for r in results.rows if "status" in r and test(r["iou"])]
        counts = [sum(r["status"] == s for r in rows) for s in ("ok", "review", "failed")]
        lines.append(f"| {label} | {len(rows)} | " + " | ".join(str(c) for c in counts) + " |")
    return "\n".join(lines)


def support_table(results: Results) -> str:
    """Markdown: the outline support of the judged items per variant kind (None where not measurable)."""
    lines = ["| variant | n | min support | mean support | max support |", "|---|---|---|---|---|"]
    for kind in (*KINDS, "handles", *BROKEN):
        s = np.array([r["quality"]["outline_support"] for r in results.rows if r["kind"] == kind
                      and r.get("quality") and r["quality"].get("outline_support") is not None])
        if len(s):
            lines.append(f"| {kind} | {len(s)} | {s.min():.3f} | {s.mean():.3f} | {s.max():.3f} |")
    return "\n".join(lines)


def overlay(found_image: np.ndarray, core: np.ndarray, appendages: np.ndarray) -> np.ndarray:
    """The crop with its core tinted red and its appendages blue (S x S x 3 uint8)."""
    out = found_image.astype(np.float32)
    out[core] = 0.55 * out[core] + 0.45 * np.array([255, 0, 0])
    out[appendages] = 0.45 * out[appendages] + 0.55 * np.array([0, 0, 255])
    return out.astype(np.uint8)


def worst_sheet(results: Results, items: list[tuple[str, Variant]], path: Path, n: int = 8,
                side: int = 160) -> None:
    """A PNG of the n worst-located variants: the photo, then the located core (red) and appendages (blue)."""

    tiles = []
    for i in sorted(range(len(items)), key=lambda i: results.rows[i]["iou"])[:n]:
        image = items[i][1].image
        rgb = image[..., :3] if image.shape[2] == 3 else np.where(image[..., 3:] > 127, image[..., :3], 255)
        found = locate_object(image, side)
        thumb = np.full((side, side, 3), 255, np.uint8)
        k = side / max(rgb.shape[:2])
        small = cv2.resize(np.ascontiguousarray(rgb, np.uint8), None, fx=k, fy=k, interpolation=cv2.INTER_AREA)
        thumb[: small.shape[0], : small.shape[1]] = small
        label = f"{results.rows[i]['kind']} {results.rows[i]['iou']:.2f}"
        cv2.putText(thumb, label, (3, side - 6), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 0, 0), 1)
        tiles.append(np.concatenate([thumb, overlay(found.image, found.silhouette, found.appendages)], axis=1))
    write_image(path, np.concatenate(tiles, axis=0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--synthetic", type=int, default=24, help="pasted rendered vases")
    parser.add_argument("--real", type=Path, default=REAL_DIR, help="folder of real photos (skipped if absent)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-status", action="store_true", help="skip de-rendering (IoU table only)")
    parser.add_argument("--refine", choices=("none", "shape", "full"), default="full",
                        help="the refinement the status is judged after (radar derender's --refine)")
    parser.add_argument("--sheet", type=Path, help="also write a PNG of the worst-located variants")
    parser.add_argument("--kinds", default=",".join((*KINDS, "handles")),
                        help="comma-separated variant kinds to locate (default: all)")
    parser.add_argument("--worst", type=int, default=0, help="also list this many worst-located variants")
    args = parser.parse_args()
    kinds = tuple(args.kinds.split(","))
    unknown = set(kinds) - {*KINDS, "handles"}
    if unknown:
        parser.error(f"unknown kinds {', '.join(sorted(unknown))} (use {', '.join((*KINDS, 'handles'))})")
    cv2.setNumThreads(1)
    t0 = time.time()
    real = real_sources(args.real) if args.real.is_dir() else []
    synth = synthetic_sources(args.synthetic, args.seed) if args.synthetic else []
    results, items = evaluate(real + synth, args.seed, {name for name, _, _ in synth}, kinds)
    print(f"{len(real)} real photos, {len(synth)} pasted vases, {len(results.rows)} variants")
    print(iou_table(results))
    for r in sorted(results.rows, key=lambda r: r["iou"])[: args.worst]:
        print(f"  {r['kind']:8s} {r['source']:28s} IoU {r['iou']:.3f}")
    if args.sheet:
        worst_sheet(results, items, args.sheet)
    if not args.no_status:
        judge_status(results, items, refine=args.refine)
        print(status_table(results))
        print(iou_table(Results([r for r in results.rows if r["kind"] in BROKEN])))
        print(support_table(results))
        for r in results.rows:
            if r["iou"] < 0.8 and r.get("status") == "ok" or r["iou"] > 0.95 and r.get("status") != "ok":
                print(f"  {r['kind']:8s} {r['source']:28s} IoU {r['iou']:.3f} {r.get('status')}: "
                      f"{'; '.join(r.get('reasons', []))}")
    print(f"({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
