"""Digitise the catalogue's profile drawings of ../shared/data/cva10: the exterior outline of each drawing's left
half as radius against height, in cm from the drawing's 10 cm scale bar.

    python -m experiments.digitise_profiles OUT [--data ../shared/data/cva10] [--overlay DIR]

writes OUT/<object>.csv (`height_cm,radius_cm`, height from the foot's underside up, one row per 0.1 cm) and,
with --overlay, DIR/<object>.png: the drawing with the read outline in red, the axis in blue and the scale bar in
green, to look at.

How it reads a drawing: dark pixels (grey < 128) in parts of at least MIN_PART pixels (specks left out); the
axis is the column holding the longest vertical run; the scale bar is the longest horizontal run with a tick
rising at both ends (its length is 10 cm); the vessel runs from the first to the last row whose dark run
reaches the axis (the rim's top and the foot's underside). Per row the outline is the dark pixel nearest the
axis (the interior of the left half is blank; the handles are drawn beside the neck, outside it, and the neck
seen between them is the outline); rows crossed by a line that runs to the axis (a band, a moulding) are read
from their neighbours, and so are single readings far from their neighbours' median (a line's anti-aliased
edge).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np

from radar_cli.fileio import read_image, write_image, write_text

MIN_PART = 60  # px: dark parts smaller than this are specks
TICK_PX = 8  # a scale-bar tick rises at least this far
BAR_CM = 10.0
STEP_CM = 0.1
SPIKE_ROWS = 41  # rows a reading is compared with (running median)
SPIKE_FRACTION = 0.05  # ... and dropped where it is further than this fraction of the axis' column from it


def dark_pixels(path: Path) -> np.ndarray:
    """H x W bool: the drawing's lines, specks left out."""
    grey = read_image(path, "L")
    dark = grey < 128
    n, labels, stats, _ = cv2.connectedComponentsWithStats(dark.astype(np.uint8), connectivity=8)
    keep = np.zeros(n, bool)
    keep[1:] = stats[1:, cv2.CC_STAT_AREA] >= MIN_PART
    return keep[labels]


def longest_runs(lines: np.ndarray) -> np.ndarray:
    """Per column of an H x W bool array, the length of its longest vertical run of True."""
    best = np.zeros(lines.shape[1], int)
    run = np.zeros(lines.shape[1], int)
    for row in lines:
        run = np.where(row, run + 1, 0)
        best = np.maximum(best, run)
    return best


def find_axis(dark: np.ndarray) -> int:
    """The axis' column: the longest vertical run in the left 70% of the drawing."""
    runs = longest_runs(dark[:, : int(0.7 * dark.shape[1])])
    return int(np.argmax(runs))


def find_scale(dark: np.ndarray, axis: int) -> tuple[int, int, int]:
    """(row, first column, last column) of the scale bar: the longest horizontal run right of the axis with a
    tick rising at both ends."""
    best = (0, 0, -1)
    height = dark.shape[0]
    for y in range(TICK_PX, height):
        row = np.concatenate([[False], dark[y, axis + 5 :], [False]])
        edges = np.diff(row.astype(np.int8))
        for start, end in zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]):
            a, b = start + axis + 5, end - 1 + axis + 5
            if b - a <= best[2] - best[1]:
                continue
            ticks = [dark[y - TICK_PX : y, max(c - 1, 0) : c + 2].any(axis=1).all() for c in (a, b)]
            if all(ticks):
                best = (y, a, b)
    if best[2] < 0:
        raise ValueError("no scale bar (a horizontal line with a tick at both ends) found")
    return best


def vessel_rows(dark: np.ndarray, axis: int) -> tuple[int, int]:
    """The first and last rows whose dark run reaches the axis from the left (at least 20 px long)."""
    reach = np.array([_run_to_axis(dark[y], axis) for y in range(dark.shape[0])])
    rows = np.nonzero(reach >= 20)[0]
    if len(rows) < 2:
        raise ValueError("no line reaches the axis (rim top, foot underside)")
    return int(rows[0]), int(rows[-1])


def _run_to_axis(row: np.ndarray, axis: int, gap: int = 3, reach: int = 15) -> int:
    """Length of the longest dark run left of the axis that ends within `reach` px of it (past the `gap` px of
    the axis line itself)."""
    best = 0
    for end in range(axis - gap, axis - reach, -1):
        if end <= 0 or not row[end]:
            continue
        x = end
        while x > 0 and row[x]:
            x -= 1
        best = max(best, end - x)
    return best


def outline_columns(dark: np.ndarray, axis: int, top: int, bottom: int) -> np.ndarray:
    """Per row top..bottom, the column of the exterior outline (NaN on rows a line to the axis crosses, then
    filled from their neighbours)."""
    cols = np.full(bottom - top + 1, np.nan)
    gap = 3  # px beside the axis line
    for i, y in enumerate(range(top, bottom + 1)):
        row = dark[y, : axis - gap]
        xs = np.nonzero(row)[0]
        if len(xs) == 0 or _run_to_axis(dark[y], axis) >= 20:
            continue
        cols[i] = xs[-1]
    known = np.nonzero(~np.isnan(cols))[0]
    cols = np.interp(np.arange(len(cols)), known, cols[known])
    # a line's anti-aliased edge next to a crossing row reads as a few rows reaching towards the axis
    median = median_filter(cols, SPIKE_ROWS)
    spikes = np.abs(cols - median) > SPIKE_FRACTION * axis
    good = np.nonzero(~spikes)[0]
    return np.interp(np.arange(len(cols)), good, cols[good])


def median_filter(values: np.ndarray, size: int) -> np.ndarray:
    """Running median of a 1-D array over `size` samples (odd), the ends repeated."""
    half = size // 2
    padded = np.pad(values, half, mode="edge")
    return np.median(np.lib.stride_tricks.sliding_window_view(padded, size), axis=1)


def digitise(path: Path) -> tuple[np.ndarray, dict]:
    """(K x 2 array of height_cm, radius_cm every STEP_CM from the foot up; what was found, in px)."""
    dark = dark_pixels(path)
    axis = find_axis(dark)
    bar_y, bar_a, bar_b = find_scale(dark, axis)
    px_per_cm = (bar_b - bar_a) / BAR_CM
    top, bottom = vessel_rows(dark, axis)
    cols = outline_columns(dark, axis, top, bottom)
    height_cm = (bottom - np.arange(top, bottom + 1)) / px_per_cm
    radius_cm = (axis - cols) / px_per_cm
    grid = np.arange(0.0, height_cm.max() + 1e-9, STEP_CM)
    profile = np.stack([grid, np.interp(grid, height_cm[::-1], radius_cm[::-1])], 1)
    found = {"axis": axis, "bar": (bar_y, bar_a, bar_b), "top": top, "bottom": bottom, "cols": cols}
    return profile, found


def overlay(path: Path, found: dict) -> np.ndarray:
    """The drawing with the read outline (red), the axis (blue) and the scale bar (green) drawn thick."""
    image = read_image(path, "RGB").copy()
    rows = np.arange(found["top"], found["bottom"] + 1)
    points = np.stack([found["cols"], rows], 1).round().astype(np.int32)
    cv2.polylines(image, [points[:, None]], False, (230, 0, 0), 5)
    cv2.line(image, (found["axis"], 0), (found["axis"], image.shape[0] - 1), (0, 0, 230), 3)
    y, a, b = found["bar"]
    cv2.line(image, (a, y), (b, y), (0, 180, 0), 7)
    return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--data", type=Path, default=Path(__file__).resolve().parents[1] / ".." / "shared" / "data"
                        / "cva10")
    parser.add_argument("--overlay", type=Path)
    args = parser.parse_args()
    drawings = sorted((args.data / "drawings").glob("*-profile.png"))
    if not drawings:
        raise SystemExit(f"{args.data / 'drawings'}: no *-profile.png drawings")
    for path in drawings:
        name = path.name.removesuffix("-profile.png")
        profile, found = digitise(path)
        lines = ["height_cm,radius_cm"] + [f"{h:.1f},{r:.2f}" for h, r in profile]
        write_text(args.out / f"{name}.csv", "\n".join(lines) + "\n")
        if args.overlay:
            write_image(args.overlay / f"{name}.png", overlay(path, found))
        px = (found["bar"][2] - found["bar"][1]) / BAR_CM
        print(f"{name}: {px:.1f} px/cm, height {profile[-1, 0]:.1f} cm, max radius {profile[:, 1].max():.2f} cm")


if __name__ == "__main__":
    main()
