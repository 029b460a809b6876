"""`radar eval-views`: how well an object's other views predict a view left out. For every object with at least
3 side views, each side view in turn is left out; the object is fitted on the others (derender.multiview.fit),
and the left-out view is drawn at its own fitted shape, pose, turn and lighting (those of the fit on all side
views: only the albedo comes from the others) with the others' fused albedo, and with the single-view albedo of the
nearest other view (as `radar derender` draws it for that photo alone: its own texels within 75 deg of its view,
mirrored round beyond). Both are scored against the photograph inside its silhouette."""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import cv2
import numpy as np

from radar_cli.derender.export.maps import write_picture
from radar_cli.derender.export.quality import psnr
from radar_cli.derender.multiview.driver import read_views
from radar_cli.derender.multiview.fit import (
    MultiviewConfig,
    ViewFit,
    choose_side_views,
    fit_chosen,
    own_fits,
)
from radar_cli.derender.multiview.pictures import draw_view
from radar_cli.derender.run.inputs import Resolution, collect_inputs
from radar_cli.derender.run.predictor import Predictor
from radar_cli.derender.run.upsample import full_resolution_state
from radar_cli.fileio import write_text
from radar_cli.render.scene import rotate_full_map

MIN_SIDE_VIEWS = 3
PICTURE_SIDE = 256


@dataclass(frozen=True)
class HeldOut:
    """One left-out view's scores (PSNR dB, SSIM) inside its silhouette: the views' fused albedo (`multi`) and the
    nearest view's single-view one (`single`)."""

    object: str
    view: str
    turn_deg: float
    nearest: str
    multi_psnr: float
    multi_ssim: float
    single_psnr: float
    single_ssim: float


def masked_ssim(a: np.ndarray, b: np.ndarray, mask: np.ndarray, sigma: float = 1.5) -> float:
    """Mean SSIM (Gaussian window, grey levels of two N x N x 3 uint8 images) over the pixels of an N x N mask."""
    x, y = (cv2.cvtColor(im, cv2.COLOR_RGB2GRAY).astype(np.float64) / 255.0 for im in (a, b))
    blur = lambda im: cv2.GaussianBlur(im, (0, 0), sigma)  # noqa: E731
    mx, my = blur(x), blur(y)
    vx, vy, cxy = blur(x * x) - mx * mx, blur(y * y) - my * my, blur(x * y) - mx * my
    c1, c2 = 0.01**2, 0.03**2
    ssim = ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
    return float(ssim[mask].mean())


def _angle(a: float, b: float) -> float:
    return abs((a - b + 180) % 360 - 180)


def leave_out(views: list[ViewFit], held: ViewFit, full: dict[int, tuple], predictor: Predictor,
              config: MultiviewConfig) -> tuple[HeldOut, list[np.ndarray]]:
    """Fit on the side views but `held`, their turns as the fit on all of them found (`full`: per view id, its
    (turn, appearance) there); predict `held` at its shape, pose, lighting and turn from that fit, with both
    albedos. Returns (its scores, [photo, multi, single])."""
    held.used = False
    others = [v for v in views if v.used]
    reference = full[id(others[0])][0]
    fit = fit_chosen(views, predictor, config, turns=[full[id(v)][0] - reference for v in others])
    held.used = True
    turn, held.appearance = full[id(held)][0] - reference, full[id(held)][1]
    nearest = min(others, key=lambda v: _angle(v.turn, turn))
    alone = full_resolution_state(nearest.looks, nearest.crops, predictor.setup, "divided")
    single = rotate_full_map(alone.material.albedo, nearest.turn)
    photo, mask = held.photo, held.mask
    multi_image, single_image = (draw_view(held, albedo, turn, predictor) for albedo in (fit.fused_map.albedo, single))
    score = HeldOut("", Path(held.source).stem, round(turn % 360, 2), Path(nearest.source).stem,
                    psnr(multi_image[mask], photo[mask]), masked_ssim(multi_image, photo, mask),
                    psnr(single_image[mask], photo[mask]), masked_ssim(single_image, photo, mask))
    return score, [photo, multi_image, single_image]


def evaluate_object(item, predictor: Predictor, resolution: Resolution, say: Callable[[str], None],
                    config: MultiviewConfig = MultiviewConfig()) -> tuple[list[HeldOut], np.ndarray | None]:
    """Every side view of one multi-view object left out in turn: (rows, the picture) or ([], None) with fewer
    than MIN_SIDE_VIEWS side views."""
    views, _ = read_views(item, predictor.setup.render.image_size, "auto", "white", resolution, say)
    readable = [v for v in views if v.prepared is not None]
    dec = predictor.predict([v.crops.image for v in readable], [v.crops.silhouette for v in readable])
    own_fits(views, [dec.select(k) for k in range(len(readable))], config, predictor.setup.camera)
    choose_side_views(views, config)
    side = [v for v in views if v.used]
    if len(side) < MIN_SIDE_VIEWS:
        say(f"{item.name}: {len(side)} side views, fewer than {MIN_SIDE_VIEWS}: not evaluated")
        return [], None
    fit_chosen(views, predictor, config)
    full = {id(v): (v.turn, v.appearance) for v in side}
    rows, strips = [], []
    for held in side:
        score, images = leave_out(views, held, full, predictor, config)
        rows.append(HeldOut(item.name, *list(score.__dict__.values())[1:]))
        say(f"{item.name} {score.view}: multi-view {score.multi_psnr:.2f} dB SSIM {score.multi_ssim:.3f}, "
            f"single view ({score.nearest}) {score.single_psnr:.2f} dB SSIM {score.single_ssim:.3f}")
        strips.append(np.concatenate([cv2.resize(im, (PICTURE_SIDE, PICTURE_SIDE), interpolation=cv2.INTER_AREA)
                                      for im in images], axis=1))
    return rows, np.concatenate(strips, axis=0)


def summary_line(rows: list[HeldOut]) -> str:
    """The mean scores, the mean gain and on how many objects the multi-view prediction is better on average."""
    if not rows:
        return "no object with enough side views"
    mean = lambda name: float(np.mean([getattr(r, name) for r in rows]))  # noqa: E731
    objects = sorted({r.object for r in rows})
    better = sum(np.mean([r.multi_psnr - r.single_psnr for r in rows if r.object == o]) > 0 for o in objects)
    return (f"{len(rows)} held-out views of {len(objects)} objects: multi-view {mean('multi_psnr'):.2f} dB SSIM "
            f"{mean('multi_ssim'):.3f}, single view {mean('single_psnr'):.2f} dB SSIM {mean('single_ssim'):.3f}; "
            f"gain {mean('multi_psnr') - mean('single_psnr'):+.2f} dB, better on {better} of {len(objects)} objects")


def evaluate_views(root: Path, out: Path, predictor: Predictor, resolution: Resolution,
                   say: Callable[[str], None]) -> list[HeldOut]:
    """Evaluate every multi-view object under `root`: out/held_out.csv, out/<object>.png (per held-out view:
    photograph, multi-view prediction, single-view prediction)."""
    items, failures = collect_inputs([root], exclude=out)
    for failure in failures:
        say(failure.line())
    out.mkdir(parents=True, exist_ok=True)
    rows: list[HeldOut] = []
    for item in (i for i in items if i.multiview):
        found, picture = evaluate_object(item, predictor, resolution, say)
        rows.extend(found)
        if picture is not None:
            write_picture(out / f"{item.name}.png", picture)
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(list(HeldOut.__dataclass_fields__))
    writer.writerows([[round(v, 4) if isinstance(v, float) and math.isfinite(v) else v for v in r.__dict__.values()]
                      for r in rows])
    write_text(out / "held_out.csv", buf.getvalue())
    return rows
