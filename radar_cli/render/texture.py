"""Texture rendering R_I(V, v, T) and unwrapping eta(V, v, I) (paper Eq. 3-4), in image and unwrapped space.

Texture maps are B x C x Ht x Wt. A frontal map covers phi in [-60, 60] deg; a full map covers 360 deg with
3 * Wt columns, and its middle third is the frontal map.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F

from radar_cli.checks import check_finite, check_shape
from radar_cli.config import CameraConfig
from radar_cli.render.raycast import Hits
from radar_cli.sor.camera import project
from radar_cli.sor.profile import check_sor
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import FRONT_SPAN, SurfaceGrid, surface_grid


def front_third(texture: torch.Tensor, extra: int = 0) -> torch.Tensor:
    """The frontal third (B x C x Ht x Wt) of a full 360 deg map (B x C x Ht x 3Wt), with `extra` columns more on
    each side (B x C x Ht x Wt + 2 extra: full_from_front's wide map)."""
    w = texture.shape[-1] // 3
    return texture[..., w - extra : 2 * w + extra]


def full_from_front(front: torch.Tensor, third: int | None = None) -> torch.Tensor:
    """A 360 deg map from a frontal map by mirroring it onto the sides and back: [mirror | front | mirror],
    B x C x Ht x 3 third, seamless at both joins (the paper mirrors the frontal third so, for visualisation).

    Args:
        front: B x C x Ht x W: the frontal third (W = third), or a wider frontal map (W = third + 2k) whose
            columns are the full map's middle ones (the frontal third and k more on each side).
        third: the columns of a third of the full map; default W.
    """
    third = front.shape[-1] if third is None else third
    side = third - (front.shape[-1] - third) // 2  # columns of each mirrored part
    return torch.cat([front[..., :side].flip(-1), front, front[..., -side:].flip(-1)], dim=-1)


def render_texture(
    hits: Hits,
    texture: torch.Tensor,
    front_only: bool = False,
    inside_dim: float = 0.5,
    background: float | torch.Tensor = 0.0,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Render a texture map onto the image through the ray-casting result.

    Args:
        hits: Hits of B images of size H x W.
        texture: B x C x Ht x Wt' map; a frontal third if front_only, otherwise a full 360 deg map.
        front_only: render only the frontal third of the outer surface (for L_im); other pixels get background.
        inside_dim: brightness factor for the inside of the vase (full renders).
        background: value of pixels without surface (a number, or a tensor broadcasting to B x C x 1 x 1).

    Returns:
        image: B x C x H x W; full renders are blended over the background by the soft silhouette, so they are
            anti-aliased and continuous in the shape at the outline.
        mask: B x 1 x H x W float, the pixels that carry texture (the rendered frontal silhouette if front_only).
    """
    dims = check_shape(hits.sil, "B H W", "hits.sil")
    check_shape(texture, "B C T U", "texture", {"B": dims["B"]})
    u, v = hits.uv[..., 0], hits.uv[..., 1]
    if front_only:
        u = u * (torch.pi / FRONT_SPAN)
        mask = hits.mask & ~hits.inner & (u.abs() <= 1.0)
        color = F.grid_sample(texture, torch.stack([u, v], -1), mode="bilinear", padding_mode="border",
                              align_corners=False)
        m = mask[:, None].to(texture.dtype)
        return color * m + background * (1 - m), m
    # wrap around the seam: pad one column from the other side, then map u onto the padded width
    w = texture.shape[-1]
    padded = torch.cat([texture[..., -1:], texture, texture[..., :1]], dim=-1)
    u_pad = u * (w / (w + 2))
    color = F.grid_sample(padded, torch.stack([u_pad, v], -1), mode="bilinear", padding_mode="border",
                          align_corners=False)
    dim = torch.where(hits.inner, inside_dim, 1.0).to(texture.dtype)[:, None]
    # the soft silhouette is the coverage: ~1 inside, anti-aliased and continuous across the outline
    alpha = hits.sil[:, None]
    image = color * dim * alpha + background * (1 - alpha)
    return image, hits.mask[:, None].to(texture.dtype)


def unwrap(
    solid: Solid,
    image: torch.Tensor,
    tex_size: tuple[int, int],
    camera: CameraConfig = CameraConfig(),
    span: float = FRONT_SPAN,
) -> torch.Tensor:
    """Unwrap the frontal third (or the angles within +- span) of the surface from an image into texture space
    (Eq. 4).

    Every texel's surface point is known in closed form; it is projected into the image and sampled bilinearly.
    Differentiable in the image, the shape and the pose.

    Args:
        solid: B solids (see cast_rays).
        image: B x C x H x W.
        tex_size: (Ht, Wt) of the frontal texture.

    Returns:
        B x C x Ht x Wt frontal texture.
    """
    radius, height, pose = solid.radius, solid.height, solid.pose
    check_sor(radius, height, pose)
    check_shape(image, "B C H W", "image", {"B": radius.shape[0]})
    check_finite(image, "image")
    rows, cols = tex_size
    return sample_surface(image, surface_grid(solid, rows, cols, camera, span), camera)


def sample_surface(image: torch.Tensor, grid: SurfaceGrid, camera: CameraConfig = CameraConfig()) -> torch.Tensor:
    """The image at a surface grid's points, projected and sampled bilinearly (unwrap's sampling, for a caller
    that also needs the grid's normals).

    Args:
        image: B x C x H x W, or 1 x C x H x W shared by every grid of the batch (not copied).
        grid: the surface samples, B x rows x cols.

    Returns:
        B x C x rows x cols.
    """
    xy = project(grid.points, camera)  # B x rows x cols x 2
    image = image.expand(xy.shape[0], -1, -1, -1)
    return F.grid_sample(image, xy, mode="bilinear", padding_mode="border", align_corners=False)
