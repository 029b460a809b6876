"""Whole-object rendering: shade an albedo map under an environment map (Eq. 5-8) and draw it, from the
original view (frontal third, for training) or from any new view and lighting (full 360 deg, for export).

Everything here composes the lower-level ops (ray casting, texture render/unwrap, shading); synthesis, the
model, de-rendering and relighting all call these functions so that they render the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import torch
import torch.nn.functional as F

from radar_cli.checks import check_shape
from radar_cli.config import CameraConfig, RenderConfig
from radar_cli.render.lighting import check_material, compose, decompose, shading_factors, upsample
from radar_cli.render.material import Material
from radar_cli.render.raycast import Hits, cast_rays
from radar_cli.render.texture import render_texture, sample_surface, unwrap
from radar_cli.sor.profile import check_sor
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import FRONT_SPAN, FULL_SPAN, SurfaceGrid, surface_grid


@dataclass(frozen=True)
class Shading:
    """Lighting factors and the shaded texture in unwrapped space (Eq. 5-7).

    Attributes:
        diffuse: B x 1 x Ht x Wt diffuse factor I_d (linear).
        specular: B x 1 x Ht x Wt specular factor I_s (linear, before rho).
        texture: B x 3 x Ht x Wt tone-mapped shaded texture T = tau(A * I_d + rho * I_s).
        grid_normals: B x rows x cols x 3 camera-space unit normals on the shading grid.
    """

    diffuse: torch.Tensor
    specular: torch.Tensor
    texture: torch.Tensor
    grid_normals: torch.Tensor

    @cached_property
    def normals(self) -> torch.Tensor:
        """B x 3 x Ht x Wt camera-space unit normals at the texels, upsampled from the shading grid on first use
        (synthesis never reads them)."""
        normals = upsample(self.grid_normals.permute(0, 3, 1, 2), (self.texture.shape[-2], self.texture.shape[-1]))
        return normals / normals.norm(dim=1, keepdim=True).clamp_min(1e-6)


def shade(
    solid: Solid,
    material: Material,
    render: RenderConfig = RenderConfig(),
    camera: CameraConfig = CameraConfig(),
    span: float = FRONT_SPAN,
) -> Shading:
    """Shade an unwrapped albedo map of the SoR under an environment map.

    Lighting is evaluated on a coarse (render.shading_height x shading_width * span / FRONT_SPAN) grid and
    upsampled bilinearly to the albedo's size, as the original implementation does.

    Args:
        solid: B solids (see cast_rays).
        material: albedo B x 3 x Ht x Wt linear in [0, 1], the frontal third if span = FRONT_SPAN, the whole
            360 deg map (column 0 at the back, -180 deg) if span = FULL_SPAN; env B x He x We (>= 0), camera
            frame; alpha B shininess; rho B specular albedo.
        span: half-width in radians of the angular range the albedo covers.

    Returns:
        Shading at the albedo's resolution.
    """
    radius, height, pose = solid.radius, solid.height, solid.pose
    albedo, env, alpha, rho = material.albedo, material.env, material.alpha, material.rho
    check_sor(radius, height, pose)
    dims = check_shape(albedo, "B 3 Ht Wt", "albedo", {"B": radius.shape[0]})
    check_shape(env, "B He We", "env", dims)
    check_material(alpha, rho, env)
    rows = render.shading_height
    cols = max(1, round(render.shading_width * span / FRONT_SPAN))
    grid = surface_grid(solid, rows, cols, camera, span)
    diffuse, specular = shading_factors(grid.normals, grid.view, env, alpha)  # B x rows x cols each
    size = (dims["Ht"], dims["Wt"])
    diffuse = upsample(diffuse[:, None], size)
    specular = upsample(specular[:, None], size)
    texture = compose(albedo, diffuse, specular, rho, render.gamma)
    return Shading(diffuse, specular, texture, grid.normals)


def render_front(hits: Hits, texture: torch.Tensor, background: float = 0.0) -> tuple[torch.Tensor, torch.Tensor]:
    """Draw a frontal-third texture map into the image: R_I(V_f, v, T) of Eq. 9.

    Args:
        hits: ray-casting result for B images.
        texture: B x C x Ht x Wt frontal map.

    Returns:
        (image B x C x H x W, frontal mask B x 1 x H x W float: the rendered silhouette of the frontal part).
    """
    return render_texture(hits, texture, front_only=True, background=background)


def render_frontal(
    solid: Solid,
    material: Material,
    render: RenderConfig,
    camera: CameraConfig,
) -> tuple[Hits, Shading, torch.Tensor, torch.Tensor]:
    """A prediction drawn as the training's losses see it: ray-cast, shade the frontal third, render it.

    Args:
        solid: B solids. material: its albedo B x 3 x Ht x Wt the frontal third, linear.

    Returns:
        (hits, shading, I^ B x 3 x H x W, S^_f B x 1 x H x W).
    """
    hits = cast_rays(solid, render.image_size, camera, render.sil_sigma_px)
    shading = shade(solid, material, render, camera)
    recon, front = render_front(hits, shading.texture)
    return hits, shading, recon, front


MAX_SPECULAR_SHARE = 0.8
"""divide_shading's cap on the share of a texel's radiance taken as highlight, so an overestimated highlight leaves
a dim texel rather than a black hole (how it was chosen: docs/derender.md)."""


def divide_shading(
    image: torch.Tensor,
    solid: Solid,
    albedo: torch.Tensor,
    rho: torch.Tensor,
    shading: Shading,
    render: RenderConfig,
    camera: CameraConfig,
    silhouette: torch.Tensor | None = None,
    max_specular_share: float = MAX_SPECULAR_SHARE,
    span: float = FRONT_SPAN,
    grid: SurfaceGrid | None = None,
) -> torch.Tensor:
    """The albedo as the image's unwrapped frontal texture divided by the shading of a predicted shape, lighting
    and material (Eq. 5 inverted, lighting.decompose): it keeps the image's detail and draws the image back (up to
    the highlight cap, the [0, 1] clamp and resampling), at the price of any shading the lighting does not explain.

    Args:
        image: B x 3 x S x S tone-mapped image in [0, 1].
        solid: the predicted shape and pose of B objects.
        albedo: B x 3 x Ht x Wt the predicted albedo, the fallback off the object.
        rho: B predicted specular albedo.
        shading: `shade` of that prediction over the same span (the caller usually has it already).
        render, camera: the model's settings (texture size, gamma).
        silhouette: B x 1 x S x S object coverage in [0, 1] if known: texels that unwrap from off the object
            (where the predicted outline overhangs the true one) would divide the backdrop, so they keep `albedo`,
            blended by the coverage.
        span: half-width in radians of the angles unwrapped (default the frontal third; `albedo`, `shading` and
            render.tex_width cover the same).
        grid: the solid's surface grid over that span at the texture's size, if the caller has it already.

    Returns:
        B x 3 x Ht x Wt linear albedo in [0, 1].
    """
    stacked = image if silhouette is None else torch.cat([image, silhouette], dim=1)  # B x (3 or 4) x S x S
    unwrapped = (unwrap(solid, stacked, (render.tex_height, render.tex_width), camera, span) if grid is None
                 else sample_surface(stacked, grid, camera))
    divided = decompose(unwrapped[:, :3], shading.diffuse, shading.specular, rho, render.gamma, max_specular_share)
    if silhouette is None:
        return divided
    on_object = unwrapped[:, 3:]  # B x 1 x Ht x Wt
    return on_object * divided + (1 - on_object) * albedo


def render_synthetic(
    solid: Solid,
    material: Material,
    size: int,
    render: RenderConfig,
    camera: CameraConfig,
    background: float | torch.Tensor,
) -> tuple[torch.Tensor, Hits, Shading]:
    """The whole object drawn as `radar synth` draws its images: shaded over the full 360 deg, the inside dimmed,
    anti-aliased by the soft silhouette within the hard one and the plain background everywhere off it (no soft
    halo outside the object). Synthesis and the training's two cycles draw through this.

    Args:
        solid: B solids.
        material: its albedo B x 3 x Ht x 3Wt the linear 360 deg map.
        size: image side in pixels. background: a grey level, or B x 3 x 1 x 1 colours.

    Returns:
        (image B x 3 x H x W tone-mapped, the hits (soft silhouette on the object only), the shading).
    """
    image, hard, hits, shading = _draw_whole(solid, material, size, render,
                                             camera, background, soft_outside=False)
    return image * hard + background * (1 - hard), hits, shading


def _draw_whole(solid: Solid, material: Material,
                size: int, render: RenderConfig,
                camera: CameraConfig, background: float | torch.Tensor,
                soft_outside: bool) -> tuple[torch.Tensor, torch.Tensor, Hits, Shading]:
    """Shade a 360 deg albedo, cast the rays (cast_rays' soft_outside) and draw the whole object, inside dimmed:
    (image B x 3 x H x W over `background` by the soft silhouette, that coverage B x 1 x H x W, hits, shading)."""
    shading = shade(solid, material, render, camera, span=FULL_SPAN)
    hits = cast_rays(solid, size, camera, render.sil_sigma_px, soft_outside=soft_outside)
    image, coverage = render_texture(hits, shading.texture, front_only=False, inside_dim=render.inside_dim,
                                     background=background)
    return image, coverage, hits, shading


def rotate_full_map(texture: torch.Tensor, yaw_deg: float) -> torch.Tensor:
    """Spin a 360 deg map about the axis: the content at angle phi moves to phi + yaw (B x C x Ht x 3Wt)."""
    width = texture.shape[-1]
    shift = yaw_deg / 360.0 * width
    whole = math.floor(shift)
    frac = shift - whole
    rolled = torch.roll(texture, shifts=whole, dims=-1)
    if frac == 0:
        return rolled
    return (1 - frac) * rolled + frac * torch.roll(rolled, shifts=1, dims=-1)


def render_view(
    solid: Solid,
    material: Material,
    size: int,
    yaw_deg: float = 0.0,
    render: RenderConfig = RenderConfig(),
    camera: CameraConfig = CameraConfig(),
    background: float = 1.0,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Render the whole object, shaded, from the given pose after spinning it by `yaw_deg` about its axis.

    New views: change pose (pitch, roll) and yaw. New lighting: pass another env (camera frame).
    The inside of an open vase is drawn dimmed by render.inside_dim.

    Args:
        solid: B solids.
        material: its albedo B x 3 x Ht x 3Wt the linear 360 deg map (middle third = the frontal view at yaw 0).
        size: output image side in pixels.

    Returns:
        (image B x 3 x H x W tone-mapped over `background`, mask B x 1 x H x W float coverage).
    """
    radius = solid.radius
    albedo_full = material.albedo
    check_shape(albedo_full, "B 3 Ht Wt", "albedo_full", {"B": radius.shape[0]})
    image, _, hits, _ = _draw_whole(solid, material.with_albedo(rotate_full_map(albedo_full, yaw_deg)),
                                    size, render, camera, background, soft_outside=True)
    return image, hits.sil[:, None]


def sample_env(env: torch.Tensor, size: tuple[int, int]) -> torch.Tensor:
    """Resample an environment map (B x He x We) to another equirectangular size, preserving mean radiance."""
    return F.interpolate(env[:, None], size=size, mode="bilinear", align_corners=False)[:, 0]
