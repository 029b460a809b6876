"""One profile of revolution for all side views of an object: each view keeps its own pitch (from its own search,
derender.refine.fit_shape), roll, offsets and scale (its half-height), and the profile's shape (the radii over the
half-height) is shared; Adam polishes all views' outlines at once, the way fit_shape.polish polishes one."""

from __future__ import annotations

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.adam import Adam
from radar_cli.derender.refine.fit_shape import ShapeFit, downsample, outline_score, roughness
from radar_cli.derender.refine.shape_config import ShapeFitConfig
from radar_cli.sor.outline import Outline, mask_outline, outline
from radar_cli.sor.solid import Solid

OUTLINE_FIELDS = ("left", "right", "top", "bottom")
Geometry = Solid
"""One view's solid: radius 1 x L, height 1, pose 1 x 4."""


def stacked(outlines: list[Outline]) -> Outline:
    """Outlines of batch one -> one outline of batch V."""
    return Outline(*(torch.cat([getattr(o, n) for o in outlines]) for n in OUTLINE_FIELDS))


def _view(o: Outline, k: int) -> Outline:
    """View k of a batch-V outline, batch of one."""
    return Outline(*(getattr(o, n)[k:k + 1] for n in OUTLINE_FIELDS))


def shared_profile(fits: list[ShapeFit]) -> torch.Tensor:
    """The starting shared profile: the row-wise median of the views' radii over their half-heights, 1 x L."""
    ratios = torch.cat([f.radius.double() / f.height.double()[:, None] for f in fits])  # V x L
    return ratios.median(dim=0).values[None]


def profile_spread(fits: list[ShapeFit]) -> list[float]:
    """How far each view's own profile (radii over half-height) lies from the views' median: the mean absolute
    difference over the rows, relative to the median's mean (0.1: 10%)."""
    ratios = torch.cat([f.radius.double() / f.height.double()[:, None] for f in fits])
    median = ratios.median(dim=0).values
    return [float((r - median).abs().mean() / median.mean()) for r in ratios]


def _polish(target: Outline, size: int, profile: torch.Tensor, height: torch.Tensor, pose: torch.Tensor, steps: int,
            config: ShapeFitConfig, camera: CameraConfig) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Adam on the shared profile (1 x L, radii over half-height) and each view's half-height (V), roll and offsets
    (V x 4 pose, pitch held) against the V views' outlines; scaled as fit_shape.polish."""
    views = len(height)
    shape = (profile[0] * 100).detach().clone().requires_grad_(True)
    own = torch.cat([height[:, None] * 100, pose[:, 1:2], pose[:, 2:] * 100], 1).detach().clone().requires_grad_(True)
    pitch = pose[:, :1].detach()

    def unpack() -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        h = own[:, 0] / 100
        radius = ((shape / 100)[None] * h[:, None]).clamp(0.02, 1.0)
        return radius, h, torch.cat([pitch, own[:, 1:2], own[:, 2:] / 100], 1)

    opt = Adam([shape, own], lr=config.polish_lr)
    for _ in range(steps):
        opt.zero_grad()
        r, h, p = unpack()
        fit = outline_score(outline(Solid(r, h, p), size, camera), target).sum()
        loss = fit + config.roughness_weight * views * roughness(r.mean(0, keepdim=True), config.corner).sum()
        loss.backward()
        opt.step()
    with torch.no_grad():
        r, h, p = unpack()
    return (r[:1] / h[0]).detach(), h.detach(), p.detach()


def fit_jointly(masks: list[np.ndarray], fits: list[ShapeFit], config: ShapeFitConfig = ShapeFitConfig(),
                camera: CameraConfig = CameraConfig()) -> tuple[list[Geometry], list[float]]:
    """One profile drawn through every view's silhouette.

    Args:
        masks: V silhouettes, N x N bool each (the same N).
        fits: each view's own fit (fit_shape) at N: its pitch is kept, the rest is the start.

    Returns:
        (per view its Solid (radius 1 x L, height 1, pose 1 x 4), float32, the radii the shared profile times the
        view's half-height; per view the mean outline distance in px at N).
    """
    size = masks[0].shape[0]
    grid = min(size, config.grid_size)
    height = torch.cat([f.height.double() for f in fits])
    pose = torch.cat([f.pose.double() for f in fits])
    profile = shared_profile(fits)
    for level, steps in zip((grid, size), config.polish_steps):
        target = stacked([mask_outline(downsample(m, level) if level != size else np.asarray(m, np.float64))
                          for m in masks])
        profile, height, pose = _polish(target, level, profile, height, pose, steps, config, camera)
    radius = profile * height[:, None]
    with torch.no_grad():
        full = stacked([mask_outline(np.asarray(m, np.float64)) for m in masks])
        drawn = outline(Solid(radius, height, pose), size, camera)
        errors = [float(outline_score(_view(drawn, k), _view(full, k), absolute=True)[0]) for k in range(len(masks))]
    geos = [Solid(radius[k:k + 1].float(), height[k:k + 1].float(), pose[k:k + 1].float()) for k in range(len(masks))]
    return geos, errors
