"""Small, tight, crowded crops of real photographs with known reference silhouettes: the test set of locating
a vessel as found on the web and in older catalogues (about 200 px, touching the frame, a grey sweep close to
the vessel's colour, a neighbouring vessel, flowers or a label in front, a greyscale JPEG scan).

    python -m experiments.small_crops --out data/small_crops          # write the cases
    python -m experiments.small_crops_eval data/small_crops            # locate them and measure

Sources (read at run time, never copied into the repository): the front, back and handle-side views of the
whole vessels of ../shared/data/cva10 (grey sweep, ~1,700 px) and four Met photographs of ../shared/data/
real_vases. Each source's reference silhouette is made at full resolution (`reference_silhouettes`); the cases
are cut, scaled and composited from it, so the reference of every case is known exactly. Where flowers or a
label hide part of the vessel, the reference keeps the vessel's full outline (the solid to reconstruct is the
vessel; the flowers and the label are not part of it, wherever they lie).

Output: OUT/images/<case>.jpg, OUT/reference/<case>.png (255 = vessel), OUT/cases.tsv (case, kind, source,
neighbour), OUT/sources/<source>.png (the full-resolution references, cached).
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from experiments.reference_silhouettes import cached_reference

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "data"
CVA_OBJECTS = ("73AE135", "77AE11", "81AE161", "83AE255", "86AE205")
CVA_VIEWS = ("front", "back", "side-ab", "side-ba")
MET_PHOTOS = ("met_es_DP269836", "met_gr_DP107005", "met_gr_DP107639", "met_gr_DP117199")
KINDS = ("tight", "plain", "sweep", "behind", "beside", "flowers", "label", "catalogue")
WORK_SIDE = 720  # sources are composited at this long side, then brought to the case's size
CASE_SIDE = (180, 230)  # a case's long side, drawn in this range


@dataclass(frozen=True)
class Source:
    """A photo at WORK_SIDE: H x W x 3 float RGB in [0, 1] and H x W float reference coverage in [0, 1]."""

    name: str
    image: np.ndarray
    cover: np.ndarray

    def box(self) -> tuple[int, int, int, int]:
        ys, xs = np.nonzero(self.cover > 0.5)
        return int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1

    def cutout(self) -> tuple[np.ndarray, np.ndarray]:
        """The vessel's bounding box: (h x w x 3 image, h x w coverage)."""
        x0, y0, x1, y1 = self.box()
        return self.image[y0:y1, x0:x1], self.cover[y0:y1, x0:x1]

    def vessel_colour(self) -> np.ndarray:
        return np.median(self.image[self.cover > 0.9], axis=0)


def load_sources(shared: Path, cache: Path) -> list[Source]:
    """Every source photo with its reference, at WORK_SIDE."""
    from radar_cli.fileio import read_image

    paths = [(f"{o}_{v}", shared / "cva10" / "photos" / o / f"{v}.jpg") for o in CVA_OBJECTS for v in CVA_VIEWS]
    paths += [(name, shared / "real_vases" / f"{name}.jpg") for name in MET_PHOTOS]
    cache.mkdir(parents=True, exist_ok=True)
    out = []
    for name, path in paths:
        photo = read_image(path, "RGB")
        mask = cached_reference(photo, name, cache)
        k = WORK_SIDE / max(photo.shape[:2])
        size = (round(photo.shape[1] * k), round(photo.shape[0] * k))
        image = cv2.resize(photo, size, interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0
        cover = cv2.resize(mask.astype(np.float32), size, interpolation=cv2.INTER_AREA)
        out.append(Source(name, image, cover))
    return out


def sweep(h: int, w: int, level: float, rng: np.random.Generator) -> np.ndarray:
    """H x W x 3 grey studio sweep around `level`: lighter above, a soft horizon, a light pool, faint noise."""
    y = np.linspace(0, 1, h)[:, None]
    x = np.linspace(-1, 1, w)[None, :]
    ramp = 1.08 - 0.16 * y + rng.uniform(-0.03, 0.03) * x
    pool = 0.06 * np.exp(-((x - rng.uniform(-0.4, 0.4)) ** 2 + (y - 0.4) ** 2) / 0.3)
    grey = np.clip(level * (ramp + pool), 0, 1)[..., None] * np.array([1.0, 1.0, 1.02 + rng.uniform(-0.03, 0.03)])
    return (grey + rng.normal(0, 0.004, (h, w, 3))).astype(np.float32)


def paste(canvas: np.ndarray, cover: np.ndarray, image: np.ndarray, alpha: np.ndarray, x: int, y: int,
          is_reference: bool) -> None:
    """Put `image` (h x w x 3) through `alpha` at (x, y) over `canvas`, clipped to it; the reference `cover`
    becomes the pasted vessel's where `is_reference`, else loses what the pasted object hides."""
    H, W = cover.shape
    h, w = alpha.shape
    xa, ya, xb, yb = max(0, x), max(0, y), min(W, x + w), min(H, y + h)
    if xa >= xb or ya >= yb:
        return
    a = alpha[ya - y : yb - y, xa - x : xb - x]
    canvas[ya:yb, xa:xb] = image[ya - y : yb - y, xa - x : xb - x] * a[..., None] + canvas[ya:yb, xa:xb] * (
        1 - a[..., None])
    region = cover[ya:yb, xa:xb]
    cover[ya:yb, xa:xb] = np.maximum(region, a) if is_reference else region * (1 - a)


def scaled(image: np.ndarray, alpha: np.ndarray, k: float) -> tuple[np.ndarray, np.ndarray]:
    size = (max(2, round(alpha.shape[1] * k)), max(2, round(alpha.shape[0] * k)))
    return (cv2.resize(image, size, interpolation=cv2.INTER_AREA),
            cv2.resize(alpha, size, interpolation=cv2.INTER_AREA))


def on_canvas(main: Source, level: float, rng: np.random.Generator, margins: tuple[float, float, float, float]):
    """The main vessel on a sweep, with margins (left, top, right, bottom; fractions of its size; negative cuts
    it). Returns (canvas, cover, the vessel's box on it)."""
    image, alpha = main.cutout()
    h, w = alpha.shape
    left, top, right, bottom = (round(m * s) for m, s in zip(margins, (w, h, w, h)))
    H, W = h + top + bottom, w + left + right
    canvas = sweep(max(H, h) + 2 * h, max(W, w) + 2 * w, level, rng)  # room for cutting and neighbours
    cover = np.zeros(canvas.shape[:2], np.float32)
    ox, oy = w, h
    paste(canvas, cover, image, alpha, ox, oy, True)
    return canvas, cover, (ox, oy, ox + w, oy + h), (ox - left, oy - top, ox + w + right, oy + h + bottom)


def _tight(main: Source, rng: np.random.Generator):
    """The photo itself cut into the vessel on three sides (both flanks and the foot or the rim)."""
    x0, y0, x1, y1 = main.box()
    w, h = x1 - x0, y1 - y0
    cut_x = rng.uniform(0.02, 0.07, 2) * w
    if rng.random() < 0.6:  # the foot cut, a margin above
        window = (x0 + cut_x[0], y0 - rng.uniform(0.04, 0.12) * h, x1 - cut_x[1], y1 - rng.uniform(0.02, 0.06) * h)
    else:
        window = (x0 + cut_x[0], y0 + rng.uniform(0.02, 0.05) * h, x1 - cut_x[1], y1 + rng.uniform(0.03, 0.08) * h)
    return main.image, main.cover, window


def _plain(main: Source, rng: np.random.Generator):
    """A flat grey close to the vessel's colour, the vessel nearly filling the frame."""
    level = float(np.clip(main.vessel_colour().mean() + rng.uniform(0.08, 0.2), 0.15, 0.85))
    canvas, cover, _, window = on_canvas(main, level, rng, tuple(rng.uniform(0.02, 0.07, 4)))
    canvas[:] = level + rng.normal(0, 0.003, canvas.shape)
    image, alpha = main.cutout()
    h, w = alpha.shape
    paste(canvas, cover, image, alpha, w, h, True)
    return canvas, cover, window


def _sweep(main: Source, rng: np.random.Generator):
    """A grey sweep of about the vessel's colour, the vessel touching the bottom and one side."""
    level = float(np.clip(main.vessel_colour().mean() + rng.uniform(0.05, 0.15), 0.15, 0.85))
    side = rng.uniform(0.08, 0.2, 2)
    side[rng.integers(0, 2)] = -rng.uniform(0.01, 0.04)
    canvas, cover, _, window = on_canvas(main, level, rng, (side[0], rng.uniform(0.05, 0.15), side[1],
                                                            -rng.uniform(0.01, 0.04)))
    return canvas, cover, window


def _neighbour(main: Source, other: Source, rng: np.random.Generator, behind: bool):
    """A second vessel behind the main one (smaller, higher, partly hidden) or beside it (about its size,
    just touching), cut by the frame."""
    level = float(rng.uniform(0.45, 0.7))
    canvas, cover, (vx0, vy0, vx1, vy1), window = on_canvas(main, level, rng, (0.15, 0.06, 0.15, 0.04))
    image, alpha = other.cutout()
    w, h = vx1 - vx0, vy1 - vy0
    k = (rng.uniform(0.7, 0.9) if behind else rng.uniform(0.85, 1.0)) * h / alpha.shape[0]
    image, alpha = scaled(image, alpha, k)
    side = 1 if rng.random() < 0.5 else -1
    gap = rng.uniform(0.25, 0.45) if behind else rng.uniform(0.02, 0.08)  # overlap, fraction of the main width
    x = vx1 - round(gap * w) if side > 0 else vx0 - alpha.shape[1] + round(gap * w)
    y = vy1 - alpha.shape[0] - round((rng.uniform(0.04, 0.1) if behind else 0.0) * h)
    back = canvas.copy()
    paste(back, np.zeros_like(cover), image, alpha, x, y, False)
    mine, cover_main = main.cutout()
    paste(back, np.zeros_like(cover), mine, cover_main, vx0, vy0, True)  # the main vessel in front
    return back, cover, window


def _flowers(main: Source, rng: np.random.Generator):
    """Flowers standing in the mouth and rising to the top edge, leaves hanging over the rim."""
    canvas, cover, (vx0, vy0, vx1, vy1), window = on_canvas(main, float(rng.uniform(0.5, 0.75)), rng,
                                                            (0.06, 0.45, 0.06, 0.05))
    w, h = vx1 - vx0, vy1 - vy0
    layer = np.zeros(canvas.shape, np.float32)
    alpha = np.zeros(cover.shape, np.float32)
    top = window[1]
    for _ in range(int(rng.integers(5, 9))):
        x_base = vx0 + w * rng.uniform(0.3, 0.7)
        x_tip = vx0 + w * rng.uniform(0.0, 1.0)
        y_tip = top + h * rng.uniform(-0.05, 0.3)
        pts = np.array([[x_base, vy0 + 0.08 * h], [(x_base + x_tip) / 2, (vy0 + y_tip) / 2], [x_tip, y_tip]], np.int32)
        green = tuple(float(c) for c in (0.15, rng.uniform(0.3, 0.5), 0.1))
        cv2.polylines(layer, [pts], False, green, max(2, round(0.012 * w)))
        cv2.polylines(alpha, [pts], False, 1.0, max(2, round(0.012 * w)))
        r = max(3, round(rng.uniform(0.05, 0.09) * w))
        colour = tuple(float(c) for c in rng.choice([[0.9, 0.85, 0.2], [0.85, 0.2, 0.25], [0.95, 0.95, 0.9],
                                                     [0.6, 0.3, 0.7]]))
        cv2.circle(layer, (int(x_tip), int(y_tip)), r, colour, -1)
        cv2.circle(alpha, (int(x_tip), int(y_tip)), r, 1.0, -1)
    for side in (-1, 1):  # leaves over the rim
        cx = (vx0 if side < 0 else vx1) - side * rng.uniform(0.05, 0.15) * w
        axes = (round(rng.uniform(0.08, 0.14) * w), round(rng.uniform(0.03, 0.05) * w))
        angle = float(side * rng.uniform(20, 50))
        cv2.ellipse(layer, (int(cx), int(vy0 + 0.03 * h)), axes, angle, 0, 360, (0.2, 0.45, 0.15), -1)
        cv2.ellipse(alpha, (int(cx), int(vy0 + 0.03 * h)), axes, angle, 0, 360, 1.0, -1)
    alpha = cv2.GaussianBlur(alpha, (0, 0), 0.8)
    canvas = layer * alpha[..., None] + canvas * (1 - alpha[..., None])
    return canvas, cover, window  # the reference keeps the vessel's full outline


def _label(main: Source, rng: np.random.Generator):
    """A museum label card standing in front of the foot, reaching past the vessel's outline."""
    canvas, cover, (vx0, vy0, vx1, vy1), window = on_canvas(main, float(rng.uniform(0.5, 0.75)), rng,
                                                            (0.1, 0.05, 0.1, 0.03))
    w, h = vx1 - vx0, vy1 - vy0
    cw, ch = round(rng.uniform(0.35, 0.5) * w), round(rng.uniform(0.12, 0.18) * h)
    card = np.full((ch, cw, 3), rng.uniform(0.85, 0.97), np.float32) * np.array([1.0, 0.97, 0.9], np.float32)
    for k in range(3):
        y = round((0.25 + 0.22 * k) * ch)
        cv2.line(card, (round(0.08 * cw), y), (round(rng.uniform(0.5, 0.92) * cw), y), (0.1, 0.1, 0.1),
                 max(1, ch // 14))
    side = 1 if rng.random() < 0.5 else -1
    x = (vx1 - round(rng.uniform(0.55, 0.8) * cw)) if side > 0 else (vx0 - round(rng.uniform(0.2, 0.45) * cw))
    y = vy1 - ch + round(rng.uniform(0.0, 0.03) * h)
    hidden = np.zeros_like(cover)
    paste(canvas, hidden, card, np.ones((ch, cw), np.float32), x, y, False)
    return canvas, cover, window  # the reference keeps the vessel's full outline behind the card


def _catalogue(main: Source, rng: np.random.Generator):
    """An older catalogue's plate: the photo cut at the vessel's top and bottom (greyscale, low contrast and
    JPEG blocks are added when the case is finished)."""
    x0, y0, x1, y1 = main.box()
    w = x1 - x0
    return main.image, main.cover, (x0 - rng.uniform(0.02, 0.1) * w, y0, x1 + rng.uniform(0.02, 0.1) * w, y1)


def finish(image: np.ndarray, cover: np.ndarray, window, rng: np.random.Generator, old: bool):
    """Cut the window (clipped to the image), bring it to a CASE_SIDE long side, and give it a web photo's
    JPEG (an older catalogue's: greyscale, low contrast, soft, coarse JPEG). Returns (uint8 RGB, bool ref)."""
    H, W = cover.shape
    x0, y0, x1, y1 = (int(round(v)) for v in window)
    x0, y0, x1, y1 = max(0, x0), max(0, y0), min(W, x1), min(H, y1)
    image, cover = image[y0:y1, x0:x1], cover[y0:y1, x0:x1]
    k = rng.integers(*CASE_SIDE) / max(cover.shape)
    size = (max(8, round(cover.shape[1] * k)), max(8, round(cover.shape[0] * k)))
    image = cv2.resize(image, size, interpolation=cv2.INTER_AREA)
    reference = cv2.resize(cover, size, interpolation=cv2.INTER_AREA) > 0.5
    quality = int(rng.integers(75, 91))
    if old:
        grey = image @ np.array([0.299, 0.587, 0.114], np.float32)
        grey = 0.5 + (grey - grey.mean()) * rng.uniform(0.4, 0.6) + rng.uniform(-0.05, 0.05)
        image = np.repeat(cv2.GaussianBlur(grey, (0, 0), 0.7)[..., None], 3, axis=2)
        quality = int(rng.integers(20, 36))
    out = (np.clip(image, 0, 1) * 255 + 0.5).astype(np.uint8)
    ok, data = cv2.imencode(".jpg", cv2.cvtColor(out, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, quality])
    return cv2.cvtColor(cv2.imdecode(data, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB), reference, data.tobytes()


def make_case(kind: str, main: Source, other: Source, rng: np.random.Generator):
    """(image, cover, window) of one case before `finish`."""
    if kind == "tight":
        return _tight(main, rng)
    if kind == "plain":
        return _plain(main, rng)
    if kind == "sweep":
        return _sweep(main, rng)
    if kind in ("behind", "beside"):
        return _neighbour(main, other, rng, kind == "behind")
    if kind == "flowers":
        return _flowers(main, rng)
    if kind == "label":
        return _label(main, rng)
    if kind == "catalogue":
        return _catalogue(main, rng)
    raise ValueError(f"unknown kind {kind!r}")


def write_cases(sources: list[Source], out: Path, per_kind: int, seed: int) -> list[dict]:
    """Draw `per_kind` cases of every kind (each kind from its own generator; main vessels drawn without
    repeats within a kind, the neighbour from another object) and write them."""
    from radar_cli.fileio import write_bytes, write_image

    rows = []
    for k, kind in enumerate(KINDS):
        rng = np.random.default_rng((seed, k))
        order = rng.permutation(len(sources))
        for j in range(per_kind):
            main = sources[order[j % len(order)]]
            others = [s for s in sources if s.name.split("_")[0] != main.name.split("_")[0]]
            other = others[int(rng.integers(len(others)))]
            image, cover, window = make_case(kind, main, other, rng)
            photo, reference, data = finish(image, cover, window, rng, kind == "catalogue")
            name = f"{kind}_{j:02d}"
            write_bytes(out / "images" / f"{name}.jpg", data)
            write_image(out / "reference" / f"{name}.png", reference.astype(np.uint8) * 255)
            rows.append({"case": name, "kind": kind, "source": main.name,
                         "neighbour": other.name if kind in ("behind", "beside") else "",
                         "size": f"{photo.shape[1]}x{photo.shape[0]}"})
    lines = ["\t".join(rows[0])] + ["\t".join(str(v) for v in r.values()) for r in rows]
    write_bytes(out / "cases.tsv", ("\n".join(lines) + "\n").encode())
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("data/small_crops"))
    parser.add_argument("--shared", type=Path, default=SHARED, help="the shared data folder")
    parser.add_argument("--per-kind", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    sources = load_sources(args.shared, args.out / "sources")
    rows = write_cases(sources, args.out, args.per_kind, args.seed)
    print(f"{len(rows)} cases of {len(KINDS)} kinds from {len(sources)} photos in {args.out}")


if __name__ == "__main__":
    main()
