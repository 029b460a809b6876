"""Accuracy of the masks pipeline on generated material with known answers.

    python -m experiments.masks_eval --per-kind 50     # the table in the report (renders 50 vases, ~1 min)

- composites: rendered vases over each backdrop kind; IoU between the crop's mask and the ground truth
  warped by the same crop;
- symmetry: the SoR score's accept/reject decision on rendered vase silhouettes vs generated non-SoR shapes.
"""

from __future__ import annotations

import argparse
import time

import cv2
import numpy as np

from radar_cli.masks import crop as crops
from radar_cli.masks.pipeline import Settings, process_image
from radar_cli.masks.quality import Thresholds, sor_score
from radar_cli.masks.refine import iou
from radar_cli.masks.synthetic import (
    BACKDROPS,
    NON_SOR,
    composite,
    non_sor_mask,
    render_vases,
)


def composite_iou(photo: np.ndarray, truth: np.ndarray, settings: Settings) -> float:
    """IoU of the largest crop's mask with the ground truth cut by the same crop (0 if nothing was found)."""
    found = process_image(photo, settings)
    if not found:
        return 0.0
    best = max(found, key=lambda c: int(c.mask.sum()))
    truth_crop = crops.cut(truth.astype(np.float32), best.box, settings.size) > 0.5
    return iou(best.mask, truth_crop)


def evaluate_composites(per_kind: int, seed: int = 0, kinds: tuple[str, ...] = BACKDROPS,
                        render_size: int = 192) -> dict[str, dict[str, float]]:
    """Mean / min IoU per backdrop kind over `per_kind` composites (the same vases on every kind)."""
    vases, alpha, masks = render_vases(per_kind, render_size, seed)
    rng = np.random.default_rng(seed + 1)
    settings = Settings()
    table = {}
    for kind in kinds:
        scores = []
        for i in range(per_kind):
            photo, truth = composite(vases[i], alpha[i], masks[i], kind, rng)
            scores.append(composite_iou(photo, truth, settings))
        s = np.array(scores)
        table[kind] = {"n": per_kind, "mean_iou": float(s.mean()), "min_iou": float(s.min()),
                       "frac_over_0.9": float((s > 0.9).mean())}
    return table


def evaluate_symmetry(n: int, seed: int = 0, threshold: float | None = None,
                      render_size: int = 128) -> dict[str, float]:
    """Accuracy of `sor_score >= threshold` on n rendered SoR silhouettes and n non-SoR ones."""
    threshold = Thresholds().min_symmetry if threshold is None else threshold
    _, _, masks = render_vases(n, render_size, seed + 7)
    rng = np.random.default_rng(seed + 8)
    sor = np.array([sor_score(m) for m in masks])
    other = np.array([sor_score(non_sor_mask(NON_SOR[i % len(NON_SOR)], render_size, rng)) for i in range(n)])
    return {"n_sor": n, "n_other": n, "threshold": threshold,
            "sor_accepted": float((sor >= threshold).mean()), "other_rejected": float((other < threshold).mean()),
            "accuracy": float(((sor >= threshold).sum() + (other < threshold).sum()) / (2 * n))}


def format_table(table: dict[str, dict[str, float]]) -> str:
    """Markdown table of `evaluate_composites`' result."""
    lines = ["| backdrop | n | mean IoU | min IoU | IoU > 0.9 |", "|---|---|---|---|---|"]
    for kind, row in table.items():
        lines.append(f"| {kind} | {row['n']} | {row['mean_iou']:.3f} | {row['min_iou']:.3f} | "
                     f"{row['frac_over_0.9']:.0%} |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-kind", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    t0 = time.time()
    print(format_table(evaluate_composites(args.per_kind, args.seed)))
    print(evaluate_symmetry(max(args.per_kind, 50), args.seed))
    print(f"({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
