"""A collection-sized `radar derender` run: N photos tiled from examples/, de-rendered in one command, its resident
memory sampled every few seconds into a CSV and drawn as a PNG (docs/performance.md).

    python -m experiments.collection_run OUT [--photos 1000] [--every 3] [--limit-s 0] [-- DERENDER OPTIONS...]

OUT/photos/ holds the collection (each example at 819 px, 1.6 x the 512 px output as `radar bench derender` draws
them, cycled, every other cycle mirrored), OUT/results/ the run's results, OUT/rss.csv (seconds; the resident and
the proportional set size, RSS and PSS, of the `radar derender` process and its worker processes together, in
MiB; objects finished) and OUT/rss.png. RSS counts the pages the processes share (torch's libraries) once per
process, PSS shares them out: PSS is the memory the run takes from the machine. --limit-s stops the run (SIGINT)
after that many seconds, for a machine that cannot finish it; 0 runs it to the end.
"""

from __future__ import annotations

import argparse
import csv
import signal
import subprocess
import sys
import time
from pathlib import Path

from PIL import Image, ImageDraw

from radar_cli.process_memory import tree_memory_mib

REPO = Path(__file__).resolve().parents[1]
PHOTO_SIDE = 819


def tile_examples(out: Path, n: int) -> None:
    """n JPEG photos in `out` made from the repository's examples."""
    found = sorted((REPO / "examples").glob("*.png")) + sorted((REPO / "examples").glob("*.jpg"))
    base = [Image.open(p).convert("RGB").resize((PHOTO_SIDE, PHOTO_SIDE)) for p in found]
    out.mkdir(parents=True, exist_ok=True)
    for k in range(n):
        image = base[k % len(base)]
        if (k // len(base)) % 2:
            image = image.transpose(Image.Transpose.FLIP_LEFT_RIGHT)
        image.save(out / f"photo_{k:04d}.jpg", quality=92)


def run(photos: Path, results: Path, table: Path, every: float, limit_s: float, options: list[str]) -> int:
    """`radar derender photos --out results options`, sampled into `table`; its exit code."""
    cmd = [sys.executable, "-m", "radar_cli", "derender", str(photos), "--out", str(results), *options]
    start = time.monotonic()
    proc = subprocess.Popen(cmd)
    with open(table, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(("t_s", "rss_mib", "pss_mib", "objects_done"))
        while proc.poll() is None:
            memory = tree_memory_mib(proc.pid)
            elapsed = time.monotonic() - start
            if memory is not None:
                writer.writerow((round(elapsed, 1), round(memory[0], 1), round(memory[1], 1),
                                 len(list(results.glob("*/material.json")))))
                f.flush()
            if limit_s and elapsed > limit_s:
                proc.send_signal(signal.SIGINT)
                proc.wait()
                break
            time.sleep(every)
    print(f"{len(list(results.glob('*/material.json')))} objects in {time.monotonic() - start:.1f} s")
    return proc.returncode


def plot(table: Path, out: Path) -> None:
    """RSS (light blue) and PSS (blue), MiB on the left, and objects finished (grey, on the right) against time."""
    rows = [(float(r[0]), float(r[1]), float(r[2]), int(r[3])) for r in list(csv.reader(open(table)))[1:]]
    t, rss, pss, done = zip(*rows) if rows else ((0.0,), (0.0,), (0.0,), (0,))
    width, height, left, bottom, top, right = 900, 420, 70, 50, 30, 70
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    t_max, r_max, d_max = max(max(t), 1.0), max(2048.0, 1.1 * max(rss)), max(max(done), 1)
    x = lambda v: left + (width - left - right) * v / t_max  # noqa: E731
    y = lambda v, top_value: height - bottom - (height - bottom - top) * v / top_value  # noqa: E731
    draw.rectangle([left, top, width - right, height - bottom], outline="black")
    for mib in range(0, int(r_max) + 1, 512):
        draw.text((5, y(mib, r_max) - 6), f"{mib} MiB", fill="blue")
    for s in range(0, int(t_max) + 1, max(60, int(t_max / 8) // 60 * 60)):
        draw.text((x(s) - 10, height - bottom + 8), f"{s} s", fill="black")
    for k in (0, d_max // 2, d_max):
        draw.text((width - right + 6, y(k, d_max) - 6), str(k), fill="gray")
    draw.line([(x(a), y(b, d_max)) for a, b in zip(t, done)], fill="gray", width=2)
    draw.line([(x(a), y(b, r_max)) for a, b in zip(t, rss)], fill="lightblue", width=2)
    draw.line([(x(a), y(b, r_max)) for a, b in zip(t, pss)], fill="blue", width=2)
    draw.text((left, 8), "radar derender and its workers: memory, RSS (light blue) and PSS (blue), left axis; "
              "objects finished (grey, right)", fill="black")
    image.save(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--photos", type=int, default=1000)
    parser.add_argument("--every", type=float, default=3.0)
    parser.add_argument("--limit-s", type=float, default=0.0)
    args, options = parser.parse_known_args()
    photos = args.out / "photos"
    if not photos.is_dir():
        tile_examples(photos, args.photos)
    code = run(photos, args.out / "results", args.out / "rss.csv", args.every, args.limit_s,
               [o for o in options if o != "--"])
    plot(args.out / "rss.csv", args.out / "rss.png")
    sys.exit(code)


if __name__ == "__main__":
    main()
