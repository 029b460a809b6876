"""Two de-renderings of the same photographs side by side: per object the photo, and from each results folder
the reconstruction, the albedo in the input view and a relit view (docs/real-photos.md, "Appearance").

    python -m experiments.appearance_sheet BEFORE AFTER docs/images/highlights.png --only NAME... [--side 160]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from PIL import Image, ImageDraw

from radar_cli.results import ALBEDO_RENDERED_FILE, INPUT_FILE, RECON_FILE

COMPARED = (RECON_FILE, ALBEDO_RENDERED_FILE, "relit_studio.png")


def sheet(before: Path, after: Path, names: list[str], side: int) -> Image.Image:
    """Rows of: photo | before's recon, albedo, relit | after's recon, albedo, relit; each `side` px."""
    label = 14
    columns = [(before, INPUT_FILE)] + [(before, f) for f in COMPARED] + [(after, f) for f in COMPARED]
    canvas = Image.new("RGB", (side * len(columns), label + side * len(names)), "white")
    draw = ImageDraw.Draw(canvas)
    for j, (root, name) in enumerate(columns):
        title = "photo" if j == 0 else f"{'before' if root == before else 'after'}: {Path(name).stem}"
        draw.text((j * side + 2, 1), title, fill=(0, 0, 0))
    for i, name in enumerate(names):
        for j, (root, file) in enumerate(columns):
            tile = Image.open(root / name / file).convert("RGB").resize((side, side))
            canvas.paste(tile, (j * side, label + i * side))
        draw.text((2, label + i * side + 2), name, fill=(200, 0, 0))
    return canvas


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--only", nargs="+", required=True, help="object folder names, in order")
    parser.add_argument("--side", type=int, default=160)
    args = parser.parse_args()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    sheet(args.before, args.after, args.only, args.side).save(args.out)


if __name__ == "__main__":
    main()
