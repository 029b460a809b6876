"""The cues that pick the pitch among candidates scored by the outline (derender.refine.fit_shape,
docs/refinement.md): where the open mouth is visible, the rim's front arc is an edge (the inside darker than the
outer wall below the lip; `lip_contrast`, also relative to its grey level where mouth and neck are both dark);
painted bands (derender.refine.bands) pick the pitch or bound the lip's search; the top edge (`top_error`) keeps
the lip and the bands to candidates that draw the photograph's rim."""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.shape_config import ShapeFitConfig
from radar_cli.sor.conic_lines import roots
from radar_cli.sor.outline import Outline, disc_conics
from radar_cli.sor.solid import Solid


def _front_arc(radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, camera: CameraConfig, samples: int
               ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The rim's front arc: x (N normalised columns), y (B x N, normalised, up; NaN off the rim's ellipse) and
    the columns of its middle 80 % (B x N bool)."""
    q = disc_conics(Solid(radius, height, pose), 2, camera)[:, 0]  # B x 3 x 3, the top disc
    x = torch.linspace(-1, 1, samples, dtype=torch.float64)
    # per column, the lower root y of the top disc's conic (y up)
    front, _ = roots(q[:, 1, 1, None].expand(-1, samples), q[:, 0, 1, None] * x + q[:, 1, 2, None],
                     q[:, 0, 0, None] * x * x + 2 * q[:, 0, 2, None] * x + q[:, 2, 2, None])  # B x N
    covered = ~front.isnan()
    lo = torch.where(covered, x, torch.full_like(front, math.inf)).amin(1, keepdim=True)
    hi = torch.where(covered, x, torch.full_like(front, -math.inf)).amax(1, keepdim=True)
    return x, front, covered & ((x - (lo + hi) / 2).abs() <= 0.4 * (hi - lo))


def _edge(grey: torch.Tensor, x: torch.Tensor, y: torch.Tensor, use: torch.Tensor, offset_px: float
          ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Per curve (B x N heights y at columns x, normalised, up; its `use`d columns): the grey level just below
    minus just above (B x N), their mean (B x N) and where both sides lie well inside the silhouette (B x N bool).
    grey: 1 x 2 x S x S, the grey image and the object's coverage."""
    step = offset_px * 2 / 512
    y = torch.nan_to_num(y)
    points = torch.stack([torch.stack([x.expand_as(y), -(y + step)], -1),  # above the curve; rows down
                          torch.stack([x.expand_as(y), -(y - step)], -1)], 1)  # below it
    values = F.grid_sample(grey.expand(len(y), -1, -1, -1), points.float(), align_corners=False)  # B x 2 x 2 x N
    on_object = use & (values[:, 1].amin(dim=1) > 0.99)
    return ((values[:, 0, 1] - values[:, 0, 0]).double() * on_object,
            (values[:, 0, 1] + values[:, 0, 0]).double() / 2 * on_object, on_object)


def lip_contrast(grey: torch.Tensor, radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor,
                 offset_px: float, camera: CameraConfig, samples: int = 512
                 ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """B contrasts of the rim's front arc: the mean grey level just below it (outer wall) minus just above it
    (the inside, seen through the mouth), over the middle 80% of the arc, where both sides lie on the object;
    the mean grey level of both sides there; and the share of those samples where the side above is the darker
    (a mouth's inside is darker along the whole arc; a pattern or an edge that an arc crosses is not).

    Args:
        grey: 1 x 2 x S x S: the grey image in [0, 1] and the object's coverage. radius: B x L; height: B;
            pose: B x 4.

    Returns:
        (B contrasts, B levels, B shares), all 0 where the rim's ellipse has no width, i.e. seen edge on, or
        where less than half of the arc's samples lie on the object.
    """
    x, front, use = _front_arc(radius, height, pose, camera, samples)
    diff, level, on_object = _edge(grey, x, front, use, offset_px)
    enough = on_object.sum(1) >= 0.5 * use.sum(1).clamp_min(1)
    count = on_object.sum(1).clamp_min(1)
    share = ((diff > 0) & on_object).sum(1) / count
    zero = torch.zeros_like(diff[:, 0])
    return (torch.where(enough, diff.sum(1) / count, zero), torch.where(enough, level.sum(1) / count, zero),
            torch.where(enough, share, zero))


def straight_contrast(grey: torch.Tensor, radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor,
                      offset_px: float, camera: CameraConfig, samples: int = 512
                      ) -> tuple[torch.Tensor, torch.Tensor]:
    """The strongest contrast (as lip_contrast) of a level line across the columns of each candidate's front
    arc, at any height the arc spans (1 px steps at 512 px, offset_px beyond its ends), and the arc's rise over
    those columns (px at 512): B each. A level photograph's rim or neck has straight edges; an arc that crosses
    one has some contrast, which a line along the edge beats."""
    x, front, use = _front_arc(radius, height, pose, camera, samples)
    px = 2 / 512
    low = torch.where(use, front, torch.full_like(front, math.inf)).amin(1)  # B
    high = torch.where(use, front, torch.full_like(front, -math.inf)).amax(1)
    rise = ((high - low) / px).nan_to_num(0.0, posinf=0.0, neginf=0.0).clamp_min(0.0)
    steps = int(rise.max()) + 2 * math.ceil(offset_px) + 1 if use.any() else 0
    best = torch.zeros(len(front), dtype=torch.float64)
    for k in range(steps):
        level = (low - (math.ceil(offset_px) - k) * px).nan_to_num(0.0, posinf=0.0, neginf=0.0)  # B
        line = level[:, None].expand_as(front)
        inside = use & (level[:, None] <= high[:, None] + offset_px * px)
        diff, _, on_object = _edge(grey, x, line, inside, offset_px)
        enough = on_object.sum(1) >= 0.5 * use.sum(1).clamp_min(1)
        best = torch.where(enough, torch.maximum(best, diff.sum(1) / on_object.sum(1).clamp_min(1)), best)
    return best, rise


def top_error(model: Outline, target: Outline) -> torch.Tensor:
    """B mean |distances| (px) between the top ends of a batch of outlines and the target's, over the columns
    both cover: how well each candidate's rim (its back arc, where the mouth shows) draws the photograph's top
    edge."""
    both = ~(model.top.isnan() | target.top.isnan())
    diff = torch.where(both, (model.top - target.top.expand_as(model.top)).abs(), torch.zeros_like(model.top))
    return diff.sum(1) / both.sum(1).clamp_min(1)


def _lip_pick(lips: torch.Tensor, tie: torch.Tensor, config: ShapeFitConfig) -> int:
    """Among candidates B whose lip (B, -inf outside the basin) is at least config.lip_tie of the strongest,
    the best by `tie` (B): several arcs as strong as the best (an edge inside the mouth that many arcs cross),
    the outline decides."""
    strong = lips >= config.lip_tie * lips.max()
    return int(torch.where(strong, tie, torch.full_like(tie, math.inf)).argmin())


def _within(basin: torch.Tensor, values: torch.Tensor) -> torch.Tensor:
    """B values, -inf outside the basin (B bool)."""
    return torch.where(basin, values, torch.full_like(values, -math.inf))


def _lip_over_bands(band: int, basin: torch.Tensor, contrast: torch.Tensor, top: torch.Tensor | None,
                    pitches: torch.Tensor, config: ShapeFitConfig, relative: torch.Tensor | None = None) -> int:
    """Where the lip is looked for when painted bands peak at candidate `band`: round that peak, unless no lip
    lies within their reach while a strong one (config.lip_over_bands, or relative to its sides' grey level
    config.dark_lip_over_bands) elsewhere in the basin draws the photograph's top edge better than the bands'
    peak does, the best drawn of them (a few faint dots near the foot, a dotted band or a glaze's edge make a
    band; the open mouth's lip says otherwise). A krater's rim seen level shows a lip within its bands' reach
    or a worse top edge at the lip's pitch, and no dark lip (pick_cue's `relative` is 0 on arcs a decorated
    neck crosses)."""
    if top is None or config.lip_over_bands is None:
        return band
    reach = (pitches - pitches[band]).abs() <= config.band_reach
    if float(_within(basin & reach, contrast).max()) > config.lip_contrast:
        return band
    readings = [(contrast, config.lip_over_bands)]
    if relative is not None and config.dark_lip_over_bands is not None and config.lip_relative is not None:
        if float(_within(basin & reach, relative).max()) > config.lip_relative:
            return band
        readings.append((relative, config.dark_lip_over_bands))
    for values, limit in readings:
        lips = _within(basin, values)
        qualify = (lips > limit) & (top < top[band])
        if qualify.any():  # of the strong lips that draw the top edge better, the one that draws it best
            return int(torch.where(qualify, top, torch.full_like(top, math.inf)).argmin())
    return band


def pick_cue(score: torch.Tensor, contrast: torch.Tensor, coherence: torch.Tensor | None, pitches: torch.Tensor,
             config: ShapeFitConfig, top: torch.Tensor | None = None, smooth: torch.Tensor | None = None,
             relative: torch.Tensor | None = None) -> tuple[int, str]:
    """The cue that picks among candidates B (all within the outline's basin, and within config.cue_basin_px
    of the best top edge, `top`, where given):
    - painted bands, where their coherence peaks at least config.band_ratio x its lowest: they bound the lip's
      search to config.band_reach of their peak (an edge above or below the rim can pass for it), unless no lip
      lies there and a strong one elsewhere draws the top edge better (_lip_over_bands);
    - the strongest lip if that lip is strong enough (among near-ties, the best outline with the bending
      uncapped, `smooth`, where given: two arcs as strong, the smoother profile);
    - else, the same way, the strongest lip relative to its sides' grey level (`relative`, B, where given) if
      that is strong enough, among candidates the bands do not rule out (config.dark_lip_bands): a black mouth
      over a dark neck (cue `dark_lip`);
    - else the bands' peak, else the best outline score."""
    basin = score <= score.min() + config.basin
    if top is not None and config.cue_basin_px is not None:
        basin = basin & (top <= top.min() + config.cue_basin_px)
    band = None
    if coherence is not None:
        peaks = _within(basin, coherence)
        if float(peaks.max()) > config.band_ratio * max(float(coherence.min()), 1e-9):
            band = int(peaks.argmax())
            centre = _lip_over_bands(band, basin, contrast, top, pitches, config, relative)
            basin = basin & ((pitches - pitches[centre]).abs() <= config.band_reach)
    tie = score if smooth is None else smooth
    lips = _within(basin, contrast)
    if float(lips.max()) > config.lip_contrast:
        return _lip_pick(lips, tie, config), "lip"
    if relative is not None and config.lip_relative is not None:
        dark = _within(basin, relative)
        if coherence is not None and config.dark_lip_bands is not None:  # the bands rule out the pitches they fit worst
            dark = _within(coherence >= config.dark_lip_bands * _within(basin, coherence).max(), dark)
        if float(dark.max()) > config.lip_relative:
            return _lip_pick(dark, tie, config), "dark_lip"
    if band is not None:
        return band, "band"
    return int(score.argmin()), "outline"
