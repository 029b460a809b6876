"""cProfile of `radar derender` (its defaults: 512 px, `--refine full`) over the photos `radar bench derender`
makes (819 px), one worker, one torch thread (docs/performance.md):

    OMP_NUM_THREADS=1 python -m experiments.profile_derender OUT [--photos 6] [--top 40] [--stats FILE]

Prints the CPU seconds per object and the top entries by cumulative time; --stats writes the profile for pstats.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import shutil
import tempfile
import time
from pathlib import Path

import torch

from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.benchmark import PHOTO_MARGIN, _photos
from radar_cli.derender.run.inputs import DEFAULT_RESOLUTION, output_side
from radar_cli.derender.run.predictor import Predictor
from radar_cli.fileio import write_image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--photos", type=int, default=6)
    parser.add_argument("--top", type=int, default=40)
    parser.add_argument("--stats", type=Path)
    args = parser.parse_args()
    shutil.rmtree(args.out, ignore_errors=True)
    predictor = Predictor.from_checkpoint(None, "cpu", "divided", "network", "full")
    torch.optim.Adam([torch.zeros(1, requires_grad=True)])  # torch._dynamo's import, once per process, left out
    side = round(PHOTO_MARGIN * output_side(DEFAULT_RESOLUTION, 1 << 30))
    with tempfile.TemporaryDirectory(prefix="radar-profile-") as tmp:
        for i, image in enumerate(_photos(args.photos, side)):
            write_image(Path(tmp) / f"bench_{i:03d}.png", image)
        options = DerenderOptions(out=args.out, batch_size=8, workers=1, threads=1)
        profile = cProfile.Profile()
        wall, cpu = time.perf_counter(), time.process_time()
        profile.enable()
        summary = derender([Path(tmp)], predictor, options, say=lambda line: None)
        profile.disable()
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    n = max(len(summary.done), 1)
    print(f"{len(summary.done)} de-rendered: wall {wall:.2f} s, CPU {cpu:.2f} s, {cpu / n:.2f} CPU s per object")
    if args.stats:
        profile.dump_stats(str(args.stats))
    pstats.Stats(profile).sort_stats("cumulative").print_stats(args.top)


if __name__ == "__main__":
    main()
