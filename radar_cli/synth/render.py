"""Render one synthetic vase and all its ground-truth maps with the project's renderer (forward only).

The image is the whole object: the full 360 deg albedo shaded over the full span, drawn with its inside dimmed
by RenderConfig.inside_dim, over a plain background (every pixel off the hard mask is the background). Ground-truth
maps are drawn through the same ray-casting result so they line up with the image pixel for pixel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from radar_cli.config import CameraConfig, RenderConfig
from radar_cli.render.lighting import TINY, power, tone_map
from radar_cli.render.material import Material
from radar_cli.render.scene import render_synthetic
from radar_cli.render.texture import render_texture
from radar_cli.sor.solid import Solid


@dataclass(frozen=True)
class RenderedSample:
    """Everything drawn for one sample, numpy, image space H x W unless said otherwise.

    Attributes:
        image: H x W x 3 float in [0, 1], tone-mapped, over the background.
        mask: H x W bool silhouette (inside of the mouth included).
        mask_front: H x W bool, frontal third of the outer surface.
        albedo_rendered: H x W x 3 tone-mapped albedo, 0 outside the object.
        normal: H x W x 3 camera-space unit normals of the seen surface, 0 outside.
        depth: H x W camera-space z, 0 outside.
        diffuse, specular: H x W linear shading factors I_d, I_s, 0 outside.
    """

    image: np.ndarray
    mask: np.ndarray
    mask_front: np.ndarray
    albedo_rendered: np.ndarray
    normal: np.ndarray
    depth: np.ndarray
    diffuse: np.ndarray
    specular: np.ndarray


def _hwc(x: torch.Tensor) -> np.ndarray:
    """1 x C x H x W -> H x W x C (or H x W for C = 1) numpy float32."""
    arr = x[0].permute(1, 2, 0).numpy().astype(np.float32)
    return arr[..., 0] if arr.shape[-1] == 1 else arr


@torch.no_grad()
def render_sample(
    radius: np.ndarray,
    height: float,
    pose: tuple[float, float, float, float],
    albedo_display: np.ndarray,
    env: np.ndarray,
    alpha: float,
    rho: float,
    size: int,
    render: RenderConfig,
    camera: CameraConfig = CameraConfig(),
    background: float = 1.0,
) -> RenderedSample:
    """Render one vase.

    Args:
        radius: L radius column; height: half-height; pose: (pitch, roll, tx, ty).
        albedo_display: Ht x 3Wt x 3 tone-mapped (display) 360 deg albedo in [0, 1]; column 0 at the back.
        env: He x We environment map; alpha: shininess; rho: specular albedo.
        size: image side in pixels. render: shading grid, gamma, inside dimming. background: grey level.

    Returns:
        RenderedSample.
    """
    r = torch.from_numpy(np.asarray(radius, dtype=np.float32))[None]  # 1 x L
    h = torch.tensor([height], dtype=torch.float32)
    v = torch.tensor([pose], dtype=torch.float32)  # 1 x 4
    display = torch.from_numpy(np.ascontiguousarray(albedo_display, dtype=np.float32)).permute(2, 0, 1)[None]
    linear = power(display.clamp_min(TINY), render.gamma)  # 1 x 3 x Ht x 3Wt
    e = torch.from_numpy(np.asarray(env, dtype=np.float32))[None]  # 1 x He x We
    a, p = torch.tensor([alpha], dtype=torch.float32), torch.tensor([rho], dtype=torch.float32)

    image, hits, shading = render_synthetic(Solid(r, h, v), Material(linear, e, a, p), size, render, camera, background)
    albedo_img, _ = render_texture(hits, display, inside_dim=1.0, background=0.0)
    maps = torch.cat([shading.diffuse, shading.specular], dim=1)  # 1 x 2 x Ht x 3Wt
    maps_img, _ = render_texture(hits, maps, inside_dim=1.0, background=0.0)
    ones = torch.ones_like(display[:, :1])
    _, front = render_texture(hits, ones[..., : ones.shape[-1] // 3], front_only=True)
    hard = hits.mask[:, None].to(torch.float32)
    return RenderedSample(
        image=np.clip(_hwc(image), 0.0, 1.0),
        mask=hits.mask[0].numpy().copy(),
        mask_front=_hwc(front) > 0.5,
        albedo_rendered=np.clip(_hwc(albedo_img * hard), 0.0, 1.0),
        normal=hits.normal[0].numpy().astype(np.float32),
        depth=hits.depth[0].numpy().astype(np.float32),
        diffuse=_hwc(maps_img[:, :1] * hard),
        specular=_hwc(maps_img[:, 1:] * hard),
    )


def env_preview(env: np.ndarray, gamma: float = 2.2) -> np.ndarray:
    """He x We map -> He x We float preview in [0, 1] (normalised by its maximum, tone-mapped)."""
    peak = max(float(env.max()), 1e-8)
    return tone_map(torch.from_numpy(env / peak), gamma).numpy()
