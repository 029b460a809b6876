"""Shape and pose refined against the photograph at the crop's resolution (radar's addition, `radar derender
--refine`; docs/refinement.md).

The silhouette alone does not fix pitch: a profile whose rows bend near the rim and the base draws the arcs that
another pitch draws. So pitch is searched over a grid, and at each candidate the rest follows from the outline
in closed form (the axis from the rows' midpoints, the profile from the rows' widths, height and vertical offset
from the outline's top and bottom); each candidate is scored by how well it draws the outline plus how much its
profile has to bend. Where the open mouth is visible, the rim's front arc is an edge in the image (the inside is
darker than the outer wall below the lip) and its contrast picks the pitch; where the pot is painted in
horizontal bands, their edges run straight across the texture unwrapped at the right pitch
(derender.refine.bands), which picks the pitch or bounds the lip's search. A fine grid then narrows it, and the
profile, height, roll and offset are polished by Adam at full resolution with the pitch held.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.adam import Adam
from radar_cli.derender.refine.bands import band_coherence, high_pass
from radar_cli.derender.refine.hidden_rows import smooth_hidden
from radar_cli.derender.refine.pitch_cues import lip_contrast, pick_cue, straight_contrast, top_error
from radar_cli.derender.refine.shape_config import ShapeFitConfig
from radar_cli.sor.outline import Outline, mask_outline, outline, vertical_extent
from radar_cli.sor.pose import rotation_matrix, translation
from radar_cli.sor.solid import Solid


@dataclass(frozen=True)
class ShapeFit:
    """A fitted shape and pose, batch of one.

    Attributes:
        radius: 1 x rows radius column (fractions of r_max); height: 1; pose: 1 x 4 (pitch, roll, tx, ty).
        outline_error: mean distance in px (at the fitted resolution) between the fitted and the target outline.
        pitch_cue: what picked the pitch: `band` (painted bands), `lip` (the rim's front arc), `dark_lip` (the
            same arc, its contrast taken relative to its grey level) or `outline`.
        drawn: the fitted solid's outline at the fitted resolution (what outline_error was read from).
    """

    radius: torch.Tensor
    height: torch.Tensor
    pose: torch.Tensor
    outline_error: float
    pitch_cue: str
    drawn: Outline


def huber(d: torch.Tensor, delta: float = 1.0) -> torch.Tensor:
    """Huber's loss of distances d (px): quadratic within delta, linear beyond (a stray mask pixel costs little)."""
    a = d.abs()
    return torch.where(a < delta, 0.5 * a * a, delta * (a - 0.5 * delta))


def outline_score(model: Outline, target: Outline, absolute: bool = False) -> torch.Tensor:
    """B scores: mean Huber (1 px) distance between a batch of outlines and one target over the rows and columns
    both cover, plus 2 per row or column only one of them covers (absolute=True: the mean |distance| instead)."""
    total: torch.Tensor | float = 0.0
    count = torch.zeros((), dtype=torch.long)
    for name in ("left", "right", "top", "bottom"):
        a = getattr(model, name)
        b = getattr(target, name).expand_as(a)
        both = ~(a.isnan() | b.isnan())
        diff = torch.where(both, a - b, torch.zeros_like(a))
        total = total + (diff.abs() if absolute else huber(diff)).sum(1)
        if not absolute:
            total = total + 2.0 * (a.isnan() ^ b.isnan()).sum(1)
        count = count + both.sum(1)
    return total / count.clamp_min(1)


def roughness(radius: torch.Tensor, corner: float | None = None) -> torch.Tensor:
    """B bending energies of B x L profiles: sum of squared second differences (each at most corner^2 where a
    corner is given), x 1e3, scaled to 64 rows."""
    d2 = radius[:, 2:] - 2 * radius[:, 1:-1] + radius[:, :-2]
    if corner is not None:
        cap = corner * (64 / radius.shape[1]) ** 2  # a smooth curve's second differences scale with 1 / L^2
        d2 = d2.clamp(-cap, cap)
    return (d2**2).sum(1) * 1e3 * (radius.shape[1] / 64) ** 3


def downsample(mask: np.ndarray, size: int) -> np.ndarray:
    """An H x H coverage map (bool or float) area-averaged to size x size (float64)."""
    m = torch.from_numpy(np.asarray(mask, np.float32))[None, None]
    return F.interpolate(m, size=(size, size), mode="area")[0, 0].double().numpy()


def _tan(camera: CameraConfig) -> float:
    return math.tan(math.radians(camera.fov_deg) / 2.0)


def axis_from_outline(target: Outline, size: int, camera: CameraConfig) -> tuple[float, float]:
    """(roll deg, tx) of the line through the rows' midpoints (least squares, summed exactly: LAPACK's solver gave
    answers a few ulp apart for the same outline from one call to the next, and so other bytes for the same
    photo)."""
    rows = torch.nonzero(~target.left[0].isnan()).flatten()
    if len(rows) < 2:
        raise ValueError("the silhouette covers fewer than two rows")
    xs = rows.double().tolist()
    ys = ((target.left[0] + target.right[0]) / 2)[rows].tolist()
    mean_x, mean_y = math.fsum(xs) / len(xs), math.fsum(ys) / len(ys)
    slope = (math.fsum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys))
             / math.fsum((x - mean_x) ** 2 for x in xs))
    intercept = mean_y - slope * mean_x
    centre_x = slope * (size / 2 - 0.5) + intercept
    tx = ((centre_x + 0.5) * 2 / size - 1) * _tan(camera) * camera.distance / camera.r_max
    return math.degrees(math.atan(slope)), tx


def _disc_centres(height: torch.Tensor, pose: torch.Tensor, rows: int, camera: CameraConfig) -> torch.Tensor:
    """B x rows x 3 camera-space centres of the profile rows' discs."""
    v = torch.linspace(-1, 1, rows, dtype=torch.float64)
    y = -v[None] * height[:, None] * camera.r_max
    rot, shift = rotation_matrix(pose), translation(pose, camera)
    return y[..., None] * rot[:, None, :, 1] + shift[:, None, :]


def profile_from_widths(target: Outline, height: torch.Tensor, pose: torch.Tensor, rows: int, size: int,
                        camera: CameraConfig, end_px: float = 0.0) -> torch.Tensor:
    """B x rows radius column read off the target's row widths: each disc's radius is the half-width of the
    image row its centre projects to, scaled back by its depth (exact for a cylinder seen side on). Rows within
    end_px of the outline's first and last are read at that distance: an end disc seen nearly edge on projects
    onto the outline's first or last row, whose width the located silhouette's rounded corners shorten."""
    valid = torch.nonzero(~target.left[0].isnan()).flatten()
    half = ((target.right[0] - target.left[0]) / 2)[valid]
    centre = _disc_centres(height, pose, rows, camera)
    tan = _tan(camera)
    row = (1 - centre[..., 1] / centre[..., 2] / tan) * size / 2 - 0.5
    first, last = float(valid.min()), float(valid.max())
    if last - first > 4 * end_px:
        row = row.clamp(first + end_px, last - end_px)
    width = np.interp(row.numpy().ravel(), valid.numpy(), half.numpy()).reshape(row.shape)
    radius = torch.from_numpy(width) * (2 / size) * centre[..., 2] * tan / camera.r_max
    return radius.clamp(0.05, 0.9)


def closed_form(target: Outline, size: int, pitches: torch.Tensor, roll: float, tx: float,
                config: ShapeFitConfig, camera: CameraConfig) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The shape at each candidate pitch: profile from the widths, then height and vertical offset moved so that
    the outline's top and bottom rows match the target's (a few rounds).

    Returns:
        (radius B x rows, height B, pose B x 4), float64.
    """
    batch = len(pitches)
    pose = torch.zeros(batch, 4, dtype=torch.float64)
    pose[:, 0], pose[:, 1], pose[:, 2] = pitches, roll, tx
    height = torch.full((batch,), 0.7, dtype=torch.float64)
    top, bottom = np.nanmin(target.top[0].numpy()), np.nanmax(target.bottom[0].numpy())
    unit = 2.0 / size  # r_max fractions per pixel at the object's distance
    for _ in range(config.placement_iterations):
        radius = profile_from_widths(target, height, pose, config.rows, size, camera, config.end_px * size / 256)
        drawn_top, drawn_bottom = vertical_extent(Solid(radius, height, pose), size, camera)
        d_top, d_bottom = top - drawn_top, bottom - drawn_bottom
        height = (height + (d_bottom - d_top) / 2 * unit / torch.cos(torch.deg2rad(pose[:, 0]))).clamp(0.3, 1.2)
        pose[:, 3] = pose[:, 3] - (d_top + d_bottom) / 2 * unit
    radius = profile_from_widths(target, height, pose, config.rows, size, camera, config.end_px * size / 256)
    return radius, height, pose


def _search(target: Outline, grey: torch.Tensor, size: int, pitches: torch.Tensor, roll: float, tx: float,
            config: ShapeFitConfig, camera: CameraConfig, lip_offset_px: float, straight: bool = False
            ) -> tuple[tuple[torch.Tensor, torch.Tensor, torch.Tensor], torch.Tensor, torch.Tensor, torch.Tensor,
                       torch.Tensor, torch.Tensor]:
    """Score a grid of candidate pitches: (shapes, outline + bending scores B, lip contrasts B (0 where a level
    line draws the edge as well, `straight`: _not_straight), top-edge errors B, outline + uncapped bending B, lip
    contrasts relative to their sides' grey level B, 0 where less than config.lip_share of the arc is darker
    above)."""
    radius, height, pose = closed_form(target, size, pitches, roll, tx, config, camera)
    score, top, smooth = _outline_scores(target, size, radius, height, pose, config, camera)
    contrast, level, share = lip_contrast(grey, radius, height, pose, lip_offset_px, camera)
    if straight:
        contrast = _not_straight(contrast, grey, (radius, height, pose), lip_offset_px, config, camera)
    relative = torch.where(share >= config.lip_share, contrast / (level + config.lip_dark), torch.zeros_like(level))
    return (radius, height, pose), score, contrast, top, smooth, relative


def _not_straight(contrast: torch.Tensor, grey: torch.Tensor, shapes: tuple[torch.Tensor, torch.Tensor, torch.Tensor],
                  offset_px: float, config: ShapeFitConfig, camera: CameraConfig) -> torch.Tensor:
    """B lip contrasts, 0 for the candidates whose arc rises at least config.straight_rise_px and whose contrast a
    level line across it reaches config.straight_ratio times (pitch_cues.straight_contrast: the edge is straight,
    as the rim and neck of a level photograph are, not the rim's front arc). Only candidates with a positive
    contrast are looked at."""
    if config.straight_ratio is None:
        return contrast
    some = torch.nonzero(contrast > 0).flatten()
    if not len(some):
        return contrast
    radius, height, pose = shapes
    line, rise = straight_contrast(grey, radius[some], height[some], pose[some], offset_px, camera)
    straight = (rise >= config.straight_rise_px) & (line >= config.straight_ratio * contrast[some])
    return contrast.index_put((some[straight],), torch.zeros_like(contrast[some[straight]]))


def _outline_scores(target: Outline, size: int, radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor,
                    config: ShapeFitConfig, camera: CameraConfig) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """B candidates' (outline + bending capped at corners, top-edge error, outline + uncapped bending)."""
    drawn = outline(Solid(radius, height, pose), size, camera)
    fit = outline_score(drawn, target)
    return (fit + config.roughness_weight * roughness(radius, config.corner), top_error(drawn, target),
            fit + config.roughness_weight * roughness(radius))


def _second_look(target: Outline, size: int, shapes: tuple[torch.Tensor, torch.Tensor, torch.Tensor],
                 scores: tuple[torch.Tensor, torch.Tensor, torch.Tensor], contrast: torch.Tensor,
                 relative: torch.Tensor, config: ShapeFitConfig, camera: CameraConfig
                 ) -> tuple[tuple[torch.Tensor, torch.Tensor, torch.Tensor], tuple[torch.Tensor, ...]]:
    """The candidates whose lip is strong enough to pick (plain or relative), with their profiles' widths
    corrected (correct_widths, config.lip_width_rounds) and scored again: seen steeply, a bulging body's silhouette
    is wider than the discs under it (each row also shows the ellipses of the discs above and below), so the
    closed-form profile of the true pitch is drawn too wide, its rim too, and left out of the basins with the lip
    it shows, or kept in them with a top edge drawn worse than a painted band's pitch draws it. Level photographs
    keep their candidates: their steep ones show no strong lip, and their own lips (near level) are drawn as
    before (the same picks on the 20 krater views and the 12 Met photographs).

    Args:
        shapes: (radius B x L, height B, pose B x 4) of the candidates; scores: (outline + bending B, top-edge
            errors B, outline + uncapped bending B); contrast, relative: B lip contrasts (pick_cue).

    Returns:
        The shapes and scores with those candidates' entries replaced (new tensors).
    """
    strong = contrast > config.lip_contrast
    if config.lip_relative is not None:
        strong = strong | (relative > config.lip_relative)
    redo = torch.nonzero(strong).flatten()
    if not len(redo) or config.lip_width_rounds < 1:
        return shapes, scores
    radius, height, pose = shapes
    better = correct_widths(target, size, radius[redo].clone(), height[redo], pose[redo], config.lip_width_rounds,
                            camera, config.end_px * size / 256)
    values = _outline_scores(target, size, better, height[redo], pose[redo], config, camera)
    radius = radius.index_copy(0, redo, better)
    return (radius, height, pose), tuple(t.index_copy(0, redo, v) for t, v in zip(scores, values))


def search_pitch(target: Outline, grey: torch.Tensor, size: int, config: ShapeFitConfig, camera: CameraConfig,
                 prior_pitch: float | None = None,
                 bands: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[tuple[torch.Tensor, ...], str]:
    """Coarse then fine pitch grids; the fine one keeps the coarse one's cue. `grey`: 1 x 2 x N x N image and
    coverage (lip_contrast); `bands`: the high-passed image and eroded silhouette (bands.high_pass), or None to
    leave the bands out. Returns ((radius, height, pose) of the chosen candidate, batch of one, float64; the cue:
    `band`, `lip` or `outline`). Without bands or a lip, the outline alone picks the pitch no more than
    config.prior_reach above `prior_pitch` (the network's) where one is given: a real rim's thickness and a foot's
    bevel draw arcs that the outline reads as a higher pitch. Lower picks are free: the network leans towards the
    middle of the range, so it reads the low pitches where the mouth is a sliver too high."""
    roll, tx = axis_from_outline(target, size, camera)
    coarse = torch.arange(0.0, config.pitch_max + 1e-6, config.coarse_step, dtype=torch.float64)
    shapes, score, contrast, top, smooth, relative = _search(target, grey, size, coarse, roll, tx, config, camera,
                                                             config.lip_offset_px, straight=True)
    shapes, (score, top, smooth) = _second_look(target, size, shapes, (score, top, smooth), contrast, relative,
                                                config, camera)
    coherence = None if bands is None else band_coherence(bands[0], bands[1], *shapes, config.bands, camera)
    best, cue = pick_cue(score, contrast, coherence, coarse, config, top, smooth, relative)
    if cue == "outline" and prior_pitch is not None:
        near = coarse - prior_pitch <= config.prior_reach
        if near.any():
            best = int(torch.where(near, score, torch.full_like(score, math.inf)).argmin())
    centre = float(coarse[best])
    fine = torch.arange(centre - config.coarse_step, centre + config.coarse_step + 1e-6, config.fine_step,
                        dtype=torch.float64).clamp(0.0, config.pitch_max)
    shapes, score, contrast, _, _, relative = _search(target, grey, size, fine, roll, tx, config, camera,
                                                      config.fine_lip_offset_px)
    place = {"lip": contrast, "dark_lip": relative}.get(cue, -score)  # bands place no finer than the outline
    best = int(place.argmax())
    return tuple(t[best : best + 1] for t in shapes), cue


def polish(target: Outline, size: int, radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor,
           steps: int, config: ShapeFitConfig, camera: CameraConfig) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Adam on the profile, height, roll and offsets against the outline (plus the bending term), pitch held.
    (L-BFGS's line search stalls on the outline's kinks.) Parameters are scaled to comparable steps: radii and
    offsets x 100, roll in degrees."""
    rows = radius.shape[1]
    x = torch.cat([radius * 100, height[:, None] * 100, pose[:, 1:2], pose[:, 2:] * 100], 1).detach()
    x.requires_grad_(True)
    pitch = pose[:, :1].detach()

    def unpack(v: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        tail = torch.cat([pitch, v[:, rows + 1 : rows + 2], v[:, rows + 2 :] / 100], 1)
        return (v[:, :rows] / 100).clamp(0.02, 1.0), v[:, rows] / 100, tail

    opt = Adam([x], lr=config.polish_lr)
    for _ in range(steps):
        opt.zero_grad()
        r, h, p = unpack(x)
        drawn = outline(Solid(r, h, p), size, camera)
        loss = (outline_score(drawn, target) + config.roughness_weight * roughness(r, config.corner)).sum()
        loss.backward()
        opt.step()
    return unpack(x.detach())


def fit_shape(mask: np.ndarray, grey: np.ndarray, config: ShapeFitConfig = ShapeFitConfig(),
              camera: CameraConfig = CameraConfig(), prior_pitch: float | None = None) -> ShapeFit:
    """Fit shape and pose to one object's silhouette and image.

    Args:
        mask: N x N silhouette (bool or coverage in [0, 1]) of the crop.
        grey: N x N grey image in [0, 1] of the same crop (the lip's contrast and the painted bands).
        config: the fit's settings. camera: the fixed camera.
        prior_pitch: the network's pitch (degrees), bounding an outline-only pick (search_pitch).

    Returns:
        ShapeFit at resolution N (polished at N, searched at min(N, config.grid_size)).

    Raises:
        FloatingPointError: the fit diverged (derender.refine.driver.FIT_ERRORS: the caller keeps the network's).
    """
    size = mask.shape[0]
    grid = min(size, config.grid_size)
    coarse_target = mask_outline(downsample(mask, grid))
    grey_t = torch.from_numpy(np.stack([np.asarray(grey, np.float32), np.asarray(mask, np.float32)]))[None]
    bands = high_pass(grey, mask, config.bands.sigma_px)
    target = mask_outline(np.asarray(mask, np.float64))
    with torch.inference_mode():  # no gradients until the polish: less bookkeeping per operation
        (radius, height, pose), cue = search_pitch(coarse_target, grey_t, grid, config, camera, prior_pitch, bands)
        radius = correct_widths(target, size, radius, height, pose, config.width_rounds, camera,
                                config.end_px * size / 256)
    radius, height, pose = radius.clone(), height.clone(), pose.clone()  # tensors the polish can differentiate
    for level, steps in zip((grid, size), config.polish_steps):
        level_target = coarse_target if level == grid else target
        radius, height, pose = polish(level_target, level, radius, height, pose, steps, config, camera)
    if config.smooth_hidden:
        radius = smooth_hidden(radius, height, pose, target, size, camera, outline_score)
    if not all(bool(torch.isfinite(t).all()) for t in (radius, height, pose)):
        raise FloatingPointError("the shape fit diverged (its profile or pose is not finite)")
    drawn = outline(Solid(radius, height, pose), size, camera)
    error = float(outline_score(drawn, target, absolute=True)[0])
    return ShapeFit(radius.float(), height.float(), pose.float(), error, cue, drawn)


def correct_widths(target: Outline, size: int, radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor,
                   rounds: int, camera: CameraConfig, end_px: float = 0.0) -> torch.Tensor:
    """The profile rescaled row by row so that the drawn outline's width matches the target's at the image row
    of each disc's centre (this takes in the limb's offset on sloping walls and the perspective, which
    profile_from_widths ignores; the end rows are read end_px inside, as there). B x L."""
    target_width = (target.right - target.left)[0].numpy()
    covered = np.nonzero(np.isfinite(target_width))[0]
    tan = _tan(camera)
    for _ in range(rounds):
        drawn = outline(Solid(radius, height, pose), size, camera)
        width = (drawn.right - drawn.left).numpy()  # B x S
        centre = _disc_centres(height, pose, radius.shape[1], camera)
        row = ((1 - centre[..., 1] / centre[..., 2] / tan) * size / 2 - 0.5).numpy()
        if len(covered) and covered[-1] - covered[0] > 4 * end_px:
            row = np.clip(row, covered[0] + end_px, covered[-1] - end_px)
        ratio = target_width[None] / np.maximum(width, 1.0)
        for b in range(len(radius)):
            ok = np.isfinite(ratio[b]) & (width[b] >= 1.0)
            if ok.sum() >= 2:
                scale = np.interp(row[b], np.nonzero(ok)[0], ratio[b][ok])
                radius[b] = (radius[b] * torch.from_numpy(np.clip(scale, 0.5, 2.0))).clamp(0.05, 0.9)
    return radius
