"""Exact, differentiable ray casting of a solid of revolution: soft and hard silhouettes, depth, normals, texture
coordinates and the inside of an open vase seen through its mouth.

The solid is the implicit function F(p) = max(rho(p) - r(y), |y| - h) in the canonical frame (F < 0 inside).
The search along each ray runs without autograd; gradients come from re-evaluating F at the found points:
- soft silhouette: g = min_s F(o + s d); by the envelope theorem dg/dtheta = dF/dtheta at the minimiser, so pixels
  just outside the object pull the shape outward;
- hit points: one implicit-differentiation step s = s0 - (G - G.detach()) / dG/ds makes the hit move with the shape.
The wall is thin and the top is open: a ray entering through the mouth is shaded where it meets the inner wall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch

from radar_cli.config import CameraConfig
from radar_cli.sor.camera import pixel_rays, pixel_size
from radar_cli.sor.pose import rotation_matrix, translation
from radar_cli.sor.profile import check_sor, lerp_rows, row_slopes

N_COARSE = 48  # coarse samples per ray span; the thinnest missed chord is ~1/3 pixel at 128 px
N_REFINE = 8  # samples per refinement round of the silhouette minimum
N_BISECT = 22  # bisection steps for first hit and exit (bracket shrinks by 4e6)


@dataclass(frozen=True)
class Hits:
    """Per-pixel result of casting one ray per pixel, channel-last.

    Attributes:
        sil: B x H x W soft silhouette in [0, 1], differentiable in shape and pose.
        mask: B x H x W bool, the ray meets the surface.
        inner: B x H x W bool, the surface met is the inside of the vase (seen through the mouth).
        depth: B x H x W camera-space z of the hit, 0 where there is none; differentiable.
        points: B x H x W x 3 camera-space hit points (closest approach where there is no hit).
        normal: B x H x W x 3 camera-space unit normal of the side that is seen (0 where no hit).
        uv: B x H x W x 2 texture coordinates (u = angle / pi in [-1, 1], 0 facing the camera; v in [-1, 1],
            -1 at the top) of the hit, or of the closest approach for rays that miss (for anti-aliasing).
    """

    sil: torch.Tensor
    mask: torch.Tensor
    inner: torch.Tensor
    depth: torch.Tensor
    points: torch.Tensor
    normal: torch.Tensor
    uv: torch.Tensor


@dataclass(frozen=True)
class _Rays:
    """The active rays of a batch in the canonical frame, flattened: M rays."""

    b: torch.Tensor  # M batch index
    o: torch.Tensor  # M x 3 origin (differentiable in pose)
    d: torch.Tensor  # M x 3 unit direction (differentiable in pose)
    r: torch.Tensor  # M x L radius column, world units (differentiable)
    h: torch.Tensor  # M half-height, world units (differentiable)

    def field(self, s: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Lateral term rho - r(y), cap term |y| - h, and points p, at ray parameters s (M x S)."""
        p = self.o[:, None, :] + s[..., None] * self.d[:, None, :]  # M x S x 3
        rho = torch.sqrt(p[..., 0] ** 2 + p[..., 2] ** 2 + 1e-20)
        v = -p[..., 1] / self.h[:, None]
        lateral = rho - lerp_rows(self.r, v)
        cap = p[..., 1].abs() - self.h[:, None]
        return lateral, cap, p

    def implicit(self, s: torch.Tensor) -> torch.Tensor:
        """F at ray parameters s (M x S)."""
        lateral, cap, _ = self.field(s)
        return torch.maximum(lateral, cap)


def cast_rays(
    radius: torch.Tensor,
    height: torch.Tensor,
    pose: torch.Tensor,
    size: int,
    camera: CameraConfig = CameraConfig(),
    sigma_px: float = 1.0,
) -> Hits:
    """Cast one ray per pixel at a batch of solids of revolution.

    Args:
        radius: B x L radius column, fractions of r_max (row 0 = top).
        height: B half-heights, fractions of r_max.
        pose: B x 4 (pitch deg, roll deg, tx, ty as fractions of r_max).
        size: image side in pixels.
        camera: the fixed camera.
        sigma_px: softness of the soft silhouette in pixels.

    Returns:
        Hits with H = W = size.
    """
    check_sor(radius, height, pose)
    if size < 1 or sigma_px <= 0:
        from radar_cli.errors import InputError

        raise InputError(f"size must be >= 1 and sigma_px > 0, got size={size}, sigma_px={sigma_px}")
    n_batch, dev, dt = radius.shape[0], radius.device, radius.dtype
    sigma = sigma_px * pixel_size(size, camera)
    rot = rotation_matrix(pose)  # B x 3 x 3
    origin = -(rot.transpose(1, 2) @ translation(pose, camera)[..., None])[..., 0]  # B x 3
    dirs = pixel_rays(size, camera, dev, dt).reshape(-1, 3)
    dirs = dirs / dirs.norm(dim=-1, keepdim=True)
    d_obj = dirs @ rot  # B x P x 3: R^T applied to each ray direction
    r_world, h_world = radius * camera.r_max, height * camera.r_max

    s_near, s_far = _span(origin.detach(), d_obj.detach(), r_world.detach().amax(1) + 4 * sigma,
                          h_world.detach() + 4 * sigma)
    active = s_far > s_near  # B x P
    b_idx, p_idx = active.nonzero(as_tuple=True)
    rays = _Rays(b_idx, origin[b_idx], d_obj[b_idx, p_idx], r_world[b_idx], h_world[b_idx])
    flat = b_idx * d_obj.shape[1] + p_idx

    found = _search(rays, s_near[b_idx, p_idx], s_far[b_idx, p_idx])
    g = rays.implicit(found.s_min[:, None])[:, 0]  # differentiable margin, world units
    scale = _margin_scale(g.detach(), flat, n_batch, size, sigma, pixel_size(size, camera))
    sil_m = torch.sigmoid(-g / (sigma * scale))

    hit_pts, normals, uv = _surface_at(rays, found, height[b_idx], radius[b_idx])
    cam_pts = (rot[b_idx] @ hit_pts[..., None])[..., 0] + translation(pose, camera)[b_idx]
    cam_nrm = (rot[b_idx] @ normals[..., None])[..., 0]

    total, P = n_batch * d_obj.shape[1], d_obj.shape[1]
    hit_m = found.hit
    def scatter(values: torch.Tensor, fill: float = 0.0) -> torch.Tensor:
        out = torch.full((total,) + values.shape[1:], fill, device=dev, dtype=values.dtype)
        return out.index_put((flat,), values)

    sil = scatter(sil_m).view(n_batch, size, size)
    mask = scatter(hit_m).view(n_batch, size, size)
    inner = scatter(found.inner & hit_m).view(n_batch, size, size)
    depth = scatter(torch.where(hit_m, cam_pts[:, 2], torch.zeros_like(cam_pts[:, 2]))).view(n_batch, size, size)
    points = scatter(cam_pts).view(n_batch, size, size, 3)
    normal = scatter(cam_nrm * hit_m[:, None].to(dt)).view(n_batch, size, size, 3)
    uv_img = scatter(uv).view(n_batch, size, size, 2)
    del P
    return Hits(sil, mask, inner, depth, points, normal, uv_img)


def _margin_scale(g: torch.Tensor, flat: torch.Tensor, n_batch: int, size: int, sigma: float,
                  pix: float) -> torch.Tensor:
    """Per-ray |image-space gradient| of the margin g (dimensionless, no grad), clamped to [0.2, 5].

    min_s F is not a distance in the image: a ray nicking the rim of a tilted base stays shallow for many pixels.
    Dividing g by how fast it changes from pixel to pixel turns it into an approximate signed distance in the
    image, so the soft silhouette is about sigma_px wide on every edge.
    """
    grid = torch.full((n_batch * size * size,), 8 * sigma, device=g.device, dtype=g.dtype)
    grid = grid.index_put((flat,), g).view(n_batch, 1, size, size)
    padded = torch.nn.functional.pad(grid, (1, 1, 1, 1), mode="replicate")
    gx = 0.5 * (padded[..., 1:-1, 2:] - padded[..., 1:-1, :-2])
    gy = 0.5 * (padded[..., 2:, 1:-1] - padded[..., :-2, 1:-1])
    mag = (torch.sqrt(gx * gx + gy * gy) / pix).clamp(0.2, 5.0)
    return mag.view(-1)[flat]


def _span(origin: torch.Tensor, d: torch.Tensor, rb: torch.Tensor, hb: torch.Tensor):
    """Ray parameters where each ray is inside the bounding cylinder (radius rb, |y| <= hb). B x P each."""
    o = origin[:, None, :]
    a = d[..., 0] ** 2 + d[..., 2] ** 2
    bq = 2 * (o[..., 0] * d[..., 0] + o[..., 2] * d[..., 2])
    c = o[..., 0] ** 2 + o[..., 2] ** 2 - rb[:, None] ** 2
    disc = bq * bq - 4 * a * c
    sq = torch.sqrt(disc.clamp_min(0))
    a_safe = a.clamp_min(1e-12)
    c0, c1 = (-bq - sq) / (2 * a_safe), (-bq + sq) / (2 * a_safe)
    c0 = torch.where(disc > 0, c0, torch.full_like(c0, math.inf))
    c1 = torch.where(disc > 0, c1, torch.full_like(c1, -math.inf))
    dy = torch.where(d[..., 1].abs() < 1e-12, torch.full_like(d[..., 1], 1e-12), d[..., 1])
    y0, y1 = (-hb[:, None] - o[..., 1]) / dy, (hb[:, None] - o[..., 1]) / dy
    lo = torch.maximum(torch.maximum(c0, torch.minimum(y0, y1)), torch.zeros_like(c0))
    hi = torch.minimum(c1, torch.maximum(y0, y1))
    return lo, hi


@dataclass(frozen=True)
class _Found:
    s_min: torch.Tensor  # M, parameter of the minimum of F (no grad)
    s_hit: torch.Tensor  # M, parameter of the shaded hit (no grad)
    hit: torch.Tensor  # M bool
    inner: torch.Tensor  # M bool, shaded hit is on the inside
    cap: torch.Tensor  # M bool, shaded hit is on the bottom disc


@torch.no_grad()
def _search(rays: _Rays, s_near: torch.Tensor, s_far: torch.Tensor) -> _Found:
    """Find, per ray, the minimiser of F and the visible surface point (no autograd)."""
    m = s_near.shape[0]
    t = torch.linspace(0.0, 1.0, N_COARSE, device=s_near.device, dtype=s_near.dtype)
    step = (s_far - s_near) / (N_COARSE - 1)
    s = s_near[:, None] + (s_far - s_near)[:, None] * t  # M x N
    f = rays.implicit(s)
    k = f.argmin(dim=1)
    s_min, width = s.gather(1, k[:, None])[:, 0], step
    for _ in range(2):  # refine the minimum on a finer grid around the best sample
        offs = torch.linspace(-1.0, 1.0, N_REFINE, device=s.device, dtype=s.dtype)
        cand = s_min[:, None] + width[:, None] * offs
        fc = rays.implicit(cand)
        s_min = cand.gather(1, fc.argmin(1, keepdim=True))[:, 0]
        width = width * (2.0 / (N_REFINE - 1))
    f_min = rays.implicit(s_min[:, None])[:, 0]

    neg = f < 0
    any_neg = neg.any(1)
    hit = any_neg | (f_min < 0)
    k1 = torch.where(any_neg, neg.float().argmax(1), (s_min - s_near).div(step.clamp_min(1e-12)).floor().long())
    k1 = k1.clamp(1, N_COARSE - 1)
    s_in = torch.where(any_neg, s.gather(1, k1[:, None])[:, 0], s_min)
    s_out = s.gather(1, (k1 - 1)[:, None])[:, 0]
    s_in, s_out = torch.where(hit, s_in, s_min), torch.where(hit, s_out, s_min)
    entry = _bisect(rays, s_out, s_in)
    lateral, cap, p = rays.field(entry[:, None])
    via_cap = cap[:, 0] > lateral[:, 0]
    mouth = hit & via_cap & (p[:, 0, 1] > 0)

    # inside the mouth: the visible point is where the ray leaves the solid again
    after_out = (s > s_in[:, None]) & ~neg
    k2 = after_out.float().argmax(1).clamp(1, N_COARSE - 1)
    prev_in = neg.gather(1, (k2 - 1)[:, None])[:, 0] & (s.gather(1, (k2 - 1)[:, None])[:, 0] > s_in)
    lo2 = torch.where(prev_in, s.gather(1, (k2 - 1)[:, None])[:, 0], s_in)
    exit_s = _bisect(rays, s.gather(1, k2[:, None])[:, 0], lo2)
    lat2, cap2, _ = rays.field(exit_s[:, None])
    s_hit = torch.where(mouth, exit_s, entry)
    on_cap = torch.where(mouth, cap2[:, 0] > lat2[:, 0], via_cap)
    del m
    return _Found(s_min, torch.where(hit, s_hit, s_min), hit, mouth, on_cap & hit)


def _bisect(rays: _Rays, s_outside: torch.Tensor, s_inside: torch.Tensor) -> torch.Tensor:
    """Root of F between a point outside (F > 0) and one inside (F < 0), as the inside end of the final bracket."""
    a, b = s_outside.clone(), s_inside.clone()
    for _ in range(N_BISECT):
        mid = 0.5 * (a + b)
        inside = rays.implicit(mid[:, None])[:, 0] < 0
        b = torch.where(inside, mid, b)
        a = torch.where(inside, a, mid)
    return 0.5 * (a + b)


def _surface_at(rays: _Rays, found: _Found, height: torch.Tensor, radius: torch.Tensor):
    """Differentiable hit points (canonical, M x 3), normals of the seen side (M x 3) and uv (M x 2)."""
    s0 = found.s_hit
    lateral, cap, _ = rays.field(s0[:, None])
    bottom = found.cap & found.hit
    g = torch.where(bottom, cap[:, 0], lateral[:, 0])
    with torch.no_grad():
        eps = 1e-4 * rays.h
        lp, cp, _ = rays.field((s0 + eps)[:, None])
        lm, cm, _ = rays.field((s0 - eps)[:, None])
        dg = torch.where(bottom, cp[:, 0] - cm[:, 0], lp[:, 0] - lm[:, 0]) / (2 * eps)
        dg = torch.where(dg.abs() < 1e-3, torch.full_like(dg, 1e-3) * torch.sign(dg + 1e-30), dg)
    s = s0 + torch.where(found.hit, -(g - g.detach()) / dg, torch.zeros_like(g))
    p = rays.o + s[:, None] * rays.d  # M x 3

    rho = torch.sqrt(p[:, 0] ** 2 + p[:, 2] ** 2 + 1e-20)
    v = (-p[:, 1] / rays.h).clamp(-1.0, 1.0)
    slope = lerp_rows(row_slopes(radius, height), v[:, None])[:, 0]
    side = torch.stack([p[:, 0] / rho, -slope, p[:, 2] / rho], dim=-1)
    side = side / side.norm(dim=-1, keepdim=True)
    side = torch.where(found.inner[:, None], -side, side)
    up = torch.zeros_like(side)
    up[:, 1] = torch.where(found.inner, 1.0, -1.0)
    normal = torch.where(bottom[:, None], up, side)
    u = torch.atan2(p[:, 0], -p[:, 2]) / math.pi
    return p, normal, torch.stack([u, v], dim=-1)
