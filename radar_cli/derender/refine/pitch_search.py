"""Test-time pitch by analysis by synthesis (radar's addition; `radar derender --pitch search`).

f_S reads pitch from the image in one pass and leans towards the middle of the range (docs/accuracy.md). Given
the object's silhouette, the search tries pitches over the whole range: at each, f_L and f_A re-read the texture
unwrapped at that pitch (f_S's radius, height, roll and translation held), the prediction is rendered and scored
with the training's own terms (silhouette, reconstruction, mean-colour reconstruction), plus a weak pull towards
f_S's pitch; a coarse grid, a fine grid round the best coarse pitch, then a parabola through the best fine pitch
and its neighbours. Weights chosen on 256 training vases (docs/derender.md), not on the test set.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from radar_cli.model import losses as L
from radar_cli.model.outputs import Decomposition
from radar_cli.model.radar import RadarModel
from radar_cli.render.lighting import compose
from radar_cli.render.scene import render_front, render_frontal
from radar_cli.sor.solid import Solid


@dataclass(frozen=True)
class PitchSearch:
    """How the search scores and steps (degrees; the loss weights as the CPU training presets'). The default
    grids cost 6 + 5 evaluations; 2 deg and 0.5 deg grids (11 + 7) scored the same on training vases.

    Attributes:
        coarse_step: spacing of the grid over the whole pitch range.
        fine_step, fine_reach: the fine grid, +- fine_reach round the best coarse pitch.
        sil_weight, dt_weight, dt_margin_px: L_sil as in training (Eq. 3 with the sharp stages' margin).
        im_weight, alb_weight: L_im and L_alb (mean-colour albedo) on the true and rendered frontal masks.
        prior_weight: per squared degree away from f_S's pitch.
        max_pixels: image pixels redrawn in one pass (samples x candidates x H x W), bounding its memory: 64
            redraws at 64 px, 4 at 256 px (but always one sample's whole grid).
    """

    coarse_step: float = 4.0
    fine_step: float = 1.0
    fine_reach: float = 2.0
    sil_weight: float = 10.0
    dt_weight: float = 100.0
    dt_margin_px: float = 1.0
    im_weight: float = 1.0
    alb_weight: float = 2.0
    prior_weight: float = 3e-4
    max_pixels: int = 64 * 64 * 64


def score(model: RadarModel, image: torch.Tensor, mask: torch.Tensor, dt: torch.Tensor, first: Decomposition,
          pitch: torch.Tensor, search: PitchSearch) -> torch.Tensor:
    """How well the prediction re-read at `pitch` redraws the image, lower is better.

    Args:
        image: B x 3 x H x W. mask, dt: B x H x W target silhouette and its distance transform.
        first: f_S's prediction (radius, height, the rest of the pose). pitch: B degrees.

    Returns:
        B scores: the weighted L_sil + L_im + L_alb of each sample, plus the pull towards f_S's pitch.
    """
    c = model.config
    pose = first.pose.clone()
    pose[:, 0] = pitch
    pred = model.read_appearance(image, Solid(first.radius, first.height, pose))
    hits, shading, recon, front = render_frontal(pred.solid, pred.material, c.render, c.camera)
    tex_mu = compose(L.mean_color(pred.albedo), shading.diffuse, shading.specular, pred.rho, c.render.gamma)
    recon_mu, _ = render_front(hits, tex_mu)
    weight = mask[:, None] * front  # B x 1 x H x W
    total = L.silhouette_loss(hits.sil, mask, dt, search.sil_weight, search.dt_weight, search.dt_margin_px,
                              per_sample=True)
    total = total + search.im_weight * L.masked_l1(recon, image, weight, per_sample=True)
    total = total + search.alb_weight * L.masked_l1(recon_mu, image, weight, per_sample=True)
    return total + search.prior_weight * (pitch - first.pose[:, 0]) ** 2


def _grid_scores(model: RadarModel, image: torch.Tensor, mask: torch.Tensor, dt: torch.Tensor,
                 first: Decomposition, candidates: torch.Tensor, search: PitchSearch) -> torch.Tensor:
    """B x G scores of the candidate pitches B x G (each clamped to the model's range).

    The candidates are scored as one batch of B * G redraws (each sample repeated G times), at most
    `search.max_pixels` at a time: one pass per chunk instead of one per candidate.
    """
    lo, hi = model.config.geometry.pitch_range
    batch, grid = candidates.shape
    per_call = max(1, search.max_pixels // (grid * image.shape[-2] * image.shape[-1]))
    chunks = []
    for start in range(0, batch, per_call):
        part = slice(start, start + per_call)
        # each of the chunk's n samples repeated G times, candidate-minor: (n * G) x ...
        image_g, mask_g, dt_g = (t[part].repeat_interleave(grid, dim=0) for t in (image, mask, dt))
        first_g = first.map(lambda t: t[part].repeat_interleave(grid, dim=0))  # noqa: B023 (applied here)
        pitch = candidates[part].clamp(lo, hi).reshape(-1)  # (n * G)
        scores = score(model, image_g, mask_g, dt_g, first_g, pitch, search)
        chunks.append(scores.view(-1, grid))
    return torch.cat(chunks)


def parabola_vertex(scores: torch.Tensor, step: float) -> torch.Tensor:
    """Offset of the minimum of each row of B x G scores on a grid of `step`, from its best column, by a parabola
    through the best and its two neighbours (0 at either end of the grid or where the three are not convex)."""
    best = scores.argmin(dim=1)
    inner = best.clamp(1, scores.shape[1] - 2)
    rows = torch.arange(scores.shape[0])
    a, b, c = scores[rows, inner - 1], scores[rows, inner], scores[rows, inner + 1]
    curvature = a - 2 * b + c
    offset = torch.where(curvature > 1e-12, 0.5 * (a - c) / curvature.clamp_min(1e-12), torch.zeros_like(a))
    return torch.where(best == inner, offset.clamp(-1.0, 1.0) * step, torch.zeros_like(a))


@torch.no_grad()
def search_pitch(model: RadarModel, image: torch.Tensor, masks: list[np.ndarray], first: Decomposition,
                 search: PitchSearch = PitchSearch()) -> Decomposition:
    """The prediction at the searched pitch, f_L and f_A re-read there.

    Args:
        image: B x 3 x S x S in [0, 1]. masks: B S x S bool object silhouettes. first: model(image).

    Returns:
        Decomposition with the new pitch; radius, height, roll and translation are f_S's.
    """
    lo, hi = model.config.geometry.pitch_range
    mask = torch.from_numpy(np.stack(masks).astype(np.float32)).to(image.device)  # B x S x S
    dt = torch.from_numpy(np.stack([L.distance_transform(m) for m in masks])).to(image.device)
    batch = image.shape[0]
    coarse = torch.arange(lo, hi + 1e-6, search.coarse_step, device=image.device).expand(batch, -1)  # B x G
    centre = coarse.gather(1, _grid_scores(model, image, mask, dt, first, coarse, search).argmin(1, keepdim=True))
    offsets = torch.arange(-search.fine_reach, search.fine_reach + 1e-6, search.fine_step, device=image.device)
    fine = centre + offsets  # B x F
    scores = _grid_scores(model, image, mask, dt, first, fine, search)
    best = fine.gather(1, scores.argmin(1, keepdim=True))[:, 0]
    pitch = (best + parabola_vertex(scores, search.fine_step)).clamp(lo, hi)
    pose = first.pose.clone()
    pose[:, 0] = pitch
    return model.read_appearance(image, Solid(first.radius, first.height, pose))
