"""The albedo over the full turn from several views: each view's photograph unwrapped over 360 deg at its own
shape and pose and divided by its own shading, turned into the object's frame, its exposure matched to the first
view's on the texels both see, and blended texel by texel with weights that favour the view seeing the texel most
squarely (foreshortening cosine to a power: the weights fall to zero at each view's limb, so seams blend). Texels no
view sees are mirrored from the other side, as a single view's map is (render.texture.full_from_front)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import torch

from radar_cli.config import CameraConfig, RenderConfig
from radar_cli.render.lighting import decompose
from radar_cli.render.material import Material
from radar_cli.render.scene import MAX_SPECULAR_SHARE, rotate_full_map, shade
from radar_cli.render.texture import sample_surface
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import FULL_SPAN, surface_grid

PALETTE = np.array([[230, 60, 50], [60, 180, 75], [50, 110, 230], [240, 200, 40], [190, 80, 200], [70, 200, 210],
                    [245, 130, 50], [150, 150, 150]], np.float32) / 255.0
"""coverage.png's colour of view k (k modulo its length); black: no view sees the texel (mirrored)."""


@dataclass(frozen=True)
class FuseConfig:
    """How the views are blended.

    Attributes:
        power: a view's weight is its foreshortening cosine to this power (higher: the best view dominates more,
            narrower blends at the seams).
        seen: (lo, hi) of the best view's cosine over which a texel goes from mirrored to seen.
        mirror_weight, mirror_below: where no view sees a texel more squarely than mirror_below (a ramp of the
            best view's cosine, from all to none), its mirror image about the first view's axis joins the blend as
            one more view, weighted mirror_weight x the views' weight at the mirror image: a texel seen only at
            the views' limbs (where glossy glaze reflects the studio) is drawn mostly by its mirror image where
            a view sees that squarely. Texels a view sees squarely are the views' alone.
        min_gain, max_gain: the exposure match's bounds on a view's gain per channel.
    """

    power: float = 4.0
    seen: tuple[float, float] = (0.08, 0.25)
    mirror_weight: float = 0.3
    mirror_below: tuple[float, float] = (0.25, 0.45)
    min_gain: float = 0.5
    max_gain: float = 2.0


@dataclass(frozen=True)
class ViewTexture:
    """One view's photograph unwrapped over the full turn.

    Attributes:
        albedo: 1 x 3 x Ht x 3Wt linear albedo (column 0 at -180 deg; the view's own frame unless turned).
        weight: 1 x 1 x Ht x 3Wt: how squarely the view sees each texel (the cosine between the normal and the
            view direction, times the silhouette's coverage; 0 where it is not seen).
    """

    albedo: torch.Tensor
    weight: torch.Tensor

    def turned(self, yaw_deg: float) -> "ViewTexture":
        """The texture in a frame turned by yaw_deg (render.scene.rotate_full_map)."""
        return ViewTexture(rotate_full_map(self.albedo, yaw_deg), rotate_full_map(self.weight, yaw_deg))


@torch.no_grad()
def unwrap_view(photo: torch.Tensor, coverage: torch.Tensor, solid: Solid, material: Material, rows: int,
                render: RenderConfig, camera: CameraConfig) -> ViewTexture:
    """A view's 360 deg albedo: the photograph sampled at the surface and divided by the view's shading.

    Args:
        photo: 1 x 3 x N x N tone-mapped image in [0, 1]; coverage: 1 x 1 x N x N object coverage.
        solid: the view's fitted solid (batch of one); material: its light and gloss (its albedo unused).
        rows: Ht; the map is Ht x 3 Ht.
        render: its shading grid and gamma; camera: the fixed camera.
    """
    cols = 3 * rows
    grid = surface_grid(solid, rows, cols, camera, FULL_SPAN)
    sampled = sample_surface(torch.cat([photo, coverage], 1), grid, camera)  # 1 x 4 x Ht x 3Wt
    facing = (grid.normals * grid.view).sum(-1).clamp_min(0.0)[:, None]  # 1 x 1 x Ht x 3Wt
    on_object = ((sampled[:, 3:] - 0.5) * 2).clamp(0.0, 1.0)
    lit = material.with_albedo(torch.ones(1, 3, rows, cols))
    shading = shade(solid, lit, render, camera, span=FULL_SPAN)
    albedo = decompose(sampled[:, :3], shading.diffuse, shading.specular, material.rho, render.gamma,
                       MAX_SPECULAR_SHARE)
    return ViewTexture(albedo, facing * on_object)


def _log_mean(view: ViewTexture, where: torch.Tensor) -> torch.Tensor:
    """3 per-channel means of the log albedo over the texels `where` (1 x 1 x Ht x W bool) marks."""
    return view.albedo.clamp_min(1e-3).log().masked_select(where.expand_as(view.albedo)).view(3, -1).mean(1)


def match_exposure(views: list[ViewTexture], config: FuseConfig = FuseConfig()) -> list[ViewTexture]:
    """The views (in one frame) with each one's albedo scaled per channel so that the views agree on the texels
    two of them see (least squares of the log ratios over every overlapping pair; the first view's gain is 1)."""
    count = len(views)
    rows, rhs, weights = [], [], []
    lo = config.seen[1]
    for i in range(count):
        for j in range(i + 1, count):
            both = (views[i].weight > lo) & (views[j].weight > lo)  # 1 x 1 x Ht x W
            if int(both.sum()) < 20:
                continue
            row = np.zeros(count)
            row[i], row[j] = -1.0, 1.0
            rows.append(row)
            rhs.append((_log_mean(views[i], both) - _log_mean(views[j], both)).numpy())  # log g_j - log g_i
            weights.append(np.sqrt(float(both.sum())))
    if not rows:
        return views
    a = np.array(rows) * np.array(weights)[:, None]
    b = np.array(rhs) * np.array(weights)[:, None]
    a = np.vstack([a, np.eye(count)[:1] * 1e3])  # the first view's gain held at 1
    b = np.vstack([b, np.zeros((1, 3))])
    log_gain = np.linalg.lstsq(a, b, rcond=None)[0]  # V x 3
    gains = np.clip(np.exp(log_gain), config.min_gain, config.max_gain)
    return [dataclasses.replace(v, albedo=(v.albedo * torch.from_numpy(g).float()[None, :, None, None]).clamp(0, 1))
            for v, g in zip(views, gains)]


@dataclass(frozen=True)
class Fused:
    """The fused map.

    Attributes:
        albedo: 1 x 3 x Ht x 3Wt linear albedo over the full turn.
        share: V x Ht x 3Wt: each view's share of each texel (sums to `seen`).
        seen: Ht x 3Wt in [0, 1]: how much of the texel comes from the views (0: mirrored from the other side).
    """

    albedo: torch.Tensor
    share: torch.Tensor
    seen: torch.Tensor

    def coverage_image(self) -> np.ndarray:
        """Ht x 3Wt x 3 uint8: each texel in its views' colours (PALETTE) by their shares; black where no view
        sees it."""
        colours = torch.from_numpy(PALETTE[np.arange(len(self.share)) % len(PALETTE)])  # V x 3
        image = torch.einsum("vhw,vc->hwc", self.share, colours)
        return (image.clamp(0, 1).numpy() * 255 + 0.5).astype(np.uint8)

    def seen_fraction(self) -> float:
        """Share of the texels the views see (seen > 0.5)."""
        return float((self.seen > 0.5).float().mean())


def fuse(views: list[ViewTexture], config: FuseConfig = FuseConfig()) -> Fused:
    """Blend views already turned into the object's frame (and exposure-matched): weights cos^power, the texel's
    mirror image about the first view's axis weighted config.mirror_weight x the views' weight there; where no
    view sees a texel, its mirror image, or else its row's mean over the seen texels."""
    weight = torch.cat([v.weight for v in views])[:, 0]  # V x Ht x W
    albedo = torch.cat([v.albedo for v in views])  # V x 3 x Ht x W
    w = weight ** config.power
    own = w.sum(0)  # Ht x W
    views_blend = (albedo * w[:, None]).sum(0) / own.clamp_min(1e-12)  # 3 x Ht x W
    best = weight.max(0).values  # Ht x W
    a, b = config.mirror_below
    squarely = ((best - a) / (b - a)).clamp(0.0, 1.0)  # Ht x W: some view sees it squarely (no mirror)
    mirror = config.mirror_weight * own.flip(-1) * (1 - squarely)
    total = (own + mirror).clamp_min(1e-12)
    blended = (own * views_blend + mirror * views_blend.flip(-1)) / total
    lo, hi = config.seen
    reach = ((best - lo) / (hi - lo)).clamp(0.0, 1.0)  # Ht x W: some view sees it
    mirrored, mirror_reach = blended.flip(-1), reach.flip(-1)
    row_mean = (blended * reach).sum(-1, keepdim=True) / reach.sum(-1, keepdim=True).clamp_min(1e-6)
    fill = mirror_reach * mirrored + (1 - mirror_reach) * row_mean
    fused = reach * blended + (1 - reach) * fill
    share = w / total * reach  # each view's share; the rest is mirrored
    return Fused(fused[None].clamp(0, 1), share, share.sum(0))
