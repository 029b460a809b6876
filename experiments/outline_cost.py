"""CPU cost of the closed-form outline in the shapes the shape fit draws it (docs/performance.md):

    OMP_NUM_THREADS=1 python -m experiments.outline_cost [--repeats 5]

A vase at pitches 5-35 deg: the polish's single outlines at 256 and 512 px with their backward pass, the pitch
search's 51 candidates at 256 px, and their top and bottom rows (vertical_extent). Prints the best of `repeats`
CPU seconds of each and their sum.
"""

from __future__ import annotations

import argparse
import time

import torch

from radar_cli.config import CameraConfig
from radar_cli.sor.outline import outline, vertical_extent
from radar_cli.sor.solid import Solid


def _vases(pitches: torch.Tensor) -> Solid:
    y = torch.linspace(1, -1, 128, dtype=torch.float64)
    radius = (0.35 + 0.3 * torch.sin(2.4 * y + 0.6) ** 2 - 0.08 * y).clamp(0.08, 0.85)
    pose = torch.zeros(len(pitches), 4, dtype=torch.float64)
    pose[:, 0], pose[:, 1] = pitches, 2.0
    return Solid(radius.expand(len(pitches), -1).clone(), torch.full((len(pitches),), 0.8, dtype=torch.float64),
                 pose)


def _polish(size: int) -> None:
    for pitch in (5.0, 15.0, 25.0, 35.0):
        solid = _vases(torch.tensor([pitch], dtype=torch.float64))
        radius = solid.radius.requires_grad_(True)
        drawn = outline(Solid(radius, solid.height, solid.pose), size, CameraConfig())
        torch.nan_to_num(drawn.left + drawn.right + drawn.top + drawn.bottom).sum().backward()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    candidates = _vases(torch.arange(0.0, 51.0, dtype=torch.float64))
    parts = {
        "polish 256 px (4 outlines + backward)": lambda: _polish(256),
        "polish 512 px (4 outlines + backward)": lambda: _polish(512),
        "pitch search, 51 outlines at 256 px": lambda: outline(candidates, 256, CameraConfig()),
        "their top and bottom rows": lambda: vertical_extent(candidates, 256, CameraConfig()),
    }
    total = 0.0
    for name, run in parts.items():
        best = float("inf")
        for _ in range(args.repeats):
            start = time.process_time()
            run()
            best = min(best, time.process_time() - start)
        total += best
        print(f"{name}: {best:.3f} CPU s")
    print(f"sum: {total:.3f} CPU s")


if __name__ == "__main__":
    main()
