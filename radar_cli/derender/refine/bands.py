"""Painted bands as a pitch cue (radar's addition; step 1 of `radar derender --refine`, docs/refinement.md).

Pottery is decorated in horizontal bands: a band's edge is a circle of the surface, which the photograph shows as
an ellipse arc whose bend depends on pitch. Unwrapped at the right pitch (and the shape that the outline gives at
that pitch), those edges run straight across the texture; at a wrong pitch they bow. So each candidate's frontal
texture is unwrapped from the photograph, high-passed first so that the smooth shading does not count, and scored
by how coherent its vertical gradient is across the columns: sum over rows of (mean over columns of d/dv)^2,
over sum of the mean of (d/dv)^2. Rows near the rim and the foot are left out (the mouth's inside and the
outline's own edge would count as bands), and so are texels the silhouette does not cover or that face away.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.render.texture import sample_surface
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import surface_grid


@dataclass(frozen=True)
class BandCue:
    """How the bands are read (chosen on `radar synth --size 512` seeds 5 and 7; docs/refinement.md).

    Attributes:
        rows, cols: texel grid of the frontal third the photograph is unwrapped onto.
        sigma_px: the high-pass removes a Gaussian blur of this width (px at 512, scaled with the crop).
        trim: share of rows left out at the rim and at the foot.
        min_facing: texels whose normal faces the camera less than this (cosine) are left out.
    """

    rows: int = 192
    cols: int = 48
    sigma_px: float = 3.0
    trim: float = 0.1
    min_facing: float = 0.3


def high_pass(grey: np.ndarray, mask: np.ndarray, sigma_px: float) -> tuple[np.ndarray, np.ndarray]:
    """The N x N grey image less its Gaussian blur (sigma_px at 512, scaled to N), and the N x N silhouette eroded
    by that width (the blur mixes in the backdrop near the outline). Both float32."""
    sigma = sigma_px * grey.shape[0] / 512
    grey = np.asarray(grey, np.float32)
    detail = grey - cv2.GaussianBlur(grey, (0, 0), sigma)
    side = 2 * int(round(sigma)) + 1
    inner = cv2.erode(np.asarray(mask, np.float32), np.ones((side, side), np.uint8))
    return detail, (inner > 0.5).astype(np.float32)


def band_coherence(detail: np.ndarray, inner: np.ndarray, radius: torch.Tensor, height: torch.Tensor,
                   pose: torch.Tensor, cue: BandCue, camera: CameraConfig) -> torch.Tensor:
    """How straight the photograph's band edges run when unwrapped at each candidate shape.

    Args:
        detail, inner: N x N high-passed grey image and eroded silhouette (high_pass).
        radius: B x L; height: B; pose: B x 4: the candidates (float64).

    Returns:
        B coherences in [0, 1] (1: every vertical gradient is the same across its row). Only texels usable at
        every candidate count, so the candidates are scored on the same part of the surface.
    """
    image = torch.from_numpy(np.stack([detail, inner])).to(radius.dtype)[None]  # 1 x 2 x N x N
    grid = surface_grid(Solid(radius, height, pose), cue.rows, cue.cols, camera)
    tex = sample_surface(image, grid, camera)  # B x 2 x R x C, one image shared by every candidate
    facing = (grid.normals * grid.view).sum(-1)  # B x R x C
    usable = (tex[:, 1] > 0.999) & (facing > cue.min_facing)
    usable = usable & usable.all(0, keepdim=True)
    cut = int(cue.rows * cue.trim)
    usable[:, :cut] = False
    usable[:, cue.rows - cut :] = False
    grad = tex[:, 0, 1:] - tex[:, 0, :-1]  # B x x C
    both = (usable[:, 1:] & usable[:, :-1]).to(grad.dtype)
    count = both.sum(2)  # B x
    mean = (grad * both).sum(2) / count.clamp_min(1)
    power = (grad * grad * both).sum(2) / count.clamp_min(1)
    rows = (count >= cue.cols / 4).to(grad.dtype)  # rows with a quarter of their columns usable
    return (mean**2 * rows).sum(1) / (power * rows).sum(1).clamp_min(1e-12)
