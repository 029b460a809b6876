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
from radar_cli.errors import InputError
from radar_cli.render.intersect import Found, search
from radar_cli.sor.camera import pixel_rays, pixel_size
from radar_cli.sor.pose import rotation_matrix, translation
from radar_cli.sor.profile import check_sor, row_coordinate, row_slopes
from radar_cli.sor.solid import Solid

CULL_SIGMAS = 6.0  # rays farther than this many sigmas from the bounding cylinder are not cast (sil = 0)
HIT_SIGMAS = 0.01  # the margin when only hits are wanted (soft_outside=False): against rounding at the rim
DEEP_SIGMAS = 10.0  # hits this many sigmas inside skip the exact margin (sil > 0.99995 either way)


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
    rows: torch.Tensor  # B x L radius column, world units (differentiable)
    h: torch.Tensor  # M half-height, world units (differentiable)

    def radius(self, v: torch.Tensor, values: torch.Tensor | None = None) -> torch.Tensor:
        """Per-row values (B x L, default the radii) interpolated at axial coordinates v (M x S), clamped."""
        values = self.rows if values is None else values
        n_rows = values.shape[1]
        t = row_coordinate(v, n_rows)
        i0 = t.detach().floor().clamp(0, n_rows - 2).long()
        w = t - i0.to(t.dtype)
        flat = values.reshape(-1)
        base = (self.b[:, None] * n_rows + i0).reshape(-1)
        # index_select, not flat[base]: its backward is an index_add, where advanced indexing's sorts the M x S
        # indices first
        a, b = (flat.index_select(0, k).view_as(i0) for k in (base, base + 1))
        return a + (b - a) * w

    def field(self, s: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Lateral term rho - r(y), cap term |y| - h, and points p, at ray parameters s (M x S)."""
        p = self.o[:, None, :] + s[..., None] * self.d[:, None, :]  # M x S x 3
        rho = torch.sqrt(p[..., 0] ** 2 + p[..., 2] ** 2 + 1e-20)
        lateral = rho - self.radius(-p[..., 1] / self.h[:, None])
        cap = p[..., 1].abs() - self.h[:, None]
        return lateral, cap, p

    def implicit(self, s: torch.Tensor) -> torch.Tensor:
        """F at ray parameters s (M x S)."""
        lateral, cap, _ = self.field(s)
        return torch.maximum(lateral, cap)


def object_rays(pose: torch.Tensor, size: int, camera: CameraConfig = CameraConfig()):
    """The camera's pixel rays in each object's canonical frame.

    Returns:
        (rot B x 3 x 3 object-to-camera rotation, origin B x 3 camera centre in the object frame,
         dirs P x 3 unit pixel directions in the camera frame, d_obj B x P x 3 the same in the object frame),
        P = size * size; differentiable in pose.
    """
    rot = rotation_matrix(pose)  # B x 3 x 3
    origin = -(rot.transpose(1, 2) @ translation(pose, camera)[..., None])[..., 0]  # B x 3
    dirs = pixel_rays(size, camera, pose.device, pose.dtype).reshape(-1, 3)
    dirs = dirs / dirs.norm(dim=-1, keepdim=True)
    return rot, origin, dirs, dirs @ rot  # R^T applied to each ray direction


def cast_rays(
    solid: Solid,
    size: int,
    camera: CameraConfig = CameraConfig(),
    sigma_px: float = 1.0,
    soft_outside: bool = True,
) -> Hits:
    """Cast one ray per pixel at a batch of solids of revolution.

    Args:
        solid: B solids (radius B x L, row 0 = top; height B; pose B x 4 pitch deg, roll deg, tx, ty; lengths in
            fractions of r_max).
        size: image side in pixels.
        camera: the fixed camera.
        sigma_px: softness of the soft silhouette in pixels.
        soft_outside: the soft silhouette off the object too (where training needs it); False sets it to 0 there
            and skips the search for those rays' closest approach, for renders drawn over a hard mask (synthesis).
            Hits are unchanged either way.

    Returns:
        Hits with H = W = size.
    """
    radius, height = solid.radius, solid.height
    n_batch, dev, dt = radius.shape[0], radius.device, radius.dtype
    sigma = _check(solid, size, camera, sigma_px)
    rot, dirs, d_obj, rays, flat, p_idx, (s_near, s_far) = _active_rays(solid, size, camera, sigma, soft_outside)
    r_world = radius * camera.r_max
    found = search(rays.o.detach(), rays.d.detach(), r_world.detach(), rays.b, rays.h.detach(), s_near, s_far,
                   deep=DEEP_SIGMAS * sigma, misses=soft_outside)
    g = _margin(rays, found.s_min)  # differentiable margin, world units
    # g is close to the distance from the ray to the solid, ~ pixels * pixel size at the object; the taper
    # takes the soft silhouette to exactly 0 at the culling margin, so it stays continuous in every input
    sil_m = torch.sigmoid(-g / sigma) * (CULL_SIGMAS - g / sigma).clamp(0.0, 1.0)
    if not soft_outside:
        sil_m = sil_m * found.hit.to(dt)

    s_hit, normals, uv = _surface_at(rays, found, row_slopes(radius, height))
    # the camera sits at the origin: a point at parameter s along pixel p's ray is s * dirs[p] in camera space
    cam_pts = s_hit[:, None] * dirs.index_select(0, p_idx)

    total = n_batch * d_obj.shape[1]
    hit_m = found.hit
    def scatter(values: torch.Tensor, fill: float = 0.0) -> torch.Tensor:
        out = torch.full((total,) + values.shape[1:], fill, device=dev, dtype=values.dtype)
        return out.index_put((flat,), values)  # (index_copy is slower on the CPU)

    sil = scatter(sil_m).view(n_batch, size, size)
    mask = scatter(hit_m).view(n_batch, size, size)
    inner = scatter(found.inner & hit_m).view(n_batch, size, size)
    depth = scatter(torch.where(hit_m, cam_pts[:, 2], torch.zeros_like(cam_pts[:, 2]))).view(n_batch, size, size)
    points = scatter(cam_pts).view(n_batch, size, size, 3)
    normal = scatter(normals * hit_m[:, None].to(dt)).view(n_batch, -1, 3) @ rot.transpose(1, 2)  # to camera
    normal = normal.view(n_batch, size, size, 3)
    uv_img = scatter(uv).view(n_batch, size, size, 2)
    return Hits(sil, mask, inner, depth, points, normal, uv_img)


def hit_mask(solid: Solid, size: int, camera: CameraConfig = CameraConfig()) -> torch.Tensor:
    """The hard silhouette alone, no grad: cast_rays(solid, size, camera, 1.0, soft_outside=False).mask, the same
    rays searched only as far as their first hits (about half the cost). B x size x size bool."""
    sigma = _check(solid, size, camera, 1.0)
    with torch.no_grad():
        _, _, d_obj, rays, flat, _, (s_near, s_far) = _active_rays(solid, size, camera, sigma, False)
        found = search(rays.o, rays.d, solid.radius * camera.r_max, rays.b, rays.h, s_near, s_far, hits_only=True)
        total = solid.radius.shape[0] * d_obj.shape[1]
        mask = torch.zeros(total, dtype=torch.bool, device=solid.radius.device).index_put((flat,), found.hit)
    return mask.view(-1, size, size)


def _check(solid: Solid, size: int, camera: CameraConfig, sigma_px: float) -> float:
    """Checks the solid and the image size; returns sigma_px in world units at the object's distance."""
    check_sor(solid.radius, solid.height, solid.pose)
    if not (isinstance(size, int) and size >= 1) or not (math.isfinite(sigma_px) and sigma_px > 0):
        raise InputError(f"size must be >= 1 and sigma_px > 0, got size={size}, sigma_px={sigma_px}")
    return sigma_px * pixel_size(size, camera)


def _active_rays(solid: Solid, size: int, camera: CameraConfig, sigma: float, soft_outside: bool
                 ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, _Rays, torch.Tensor, torch.Tensor,
                            tuple[torch.Tensor, torch.Tensor]]:
    """The rays that cross the bounding cylinder (inflated by the soft halo, or by a hair for hits alone).

    Returns:
        (rotation B x 3 x 3, unit camera-frame directions P x 3, object-frame directions B x P x 3, the active
        rays _Rays (M), their flat index into B x P, their pixel index (M), their span (s_near, s_far) (M each)).
    """
    radius, height, pose = solid.radius, solid.height, solid.pose
    rot, origin, dirs, d_obj = object_rays(pose, size, camera)
    r_world, h_world = radius * camera.r_max, height * camera.r_max
    cull = (CULL_SIGMAS if soft_outside else HIT_SIGMAS) * sigma  # bounding-cylinder margin: the soft halo or none
    s_near, s_far = _span(origin.detach(), d_obj.detach(), r_world.detach().amax(1) + cull, h_world.detach() + cull)
    active = s_far > s_near  # B x P
    b_idx, p_idx = active.nonzero(as_tuple=True)
    flat = b_idx * d_obj.shape[1] + p_idx
    rays = _Rays(b_idx, origin.index_select(0, b_idx), d_obj.reshape(-1, 3).index_select(0, flat), r_world,
                 h_world.index_select(0, b_idx))
    return rot, dirs, d_obj, rays, flat, p_idx, (s_near[b_idx, p_idx], s_far[b_idx, p_idx])


def _margin(rays: _Rays, s_min: torch.Tensor) -> torch.Tensor:
    """g = min_s F along each ray (M), differentiable by the envelope theorem.

    At a smooth minimum dg/dtheta = dF/dtheta at the (no-grad) minimiser. The minimum often sits on a kink of F
    instead (the rim, where the lateral and cap terms cross, or a profile row): there F = max(f_left, f_right)
    locally and dg/dtheta = lam dF_left/dtheta + (1 - lam) dF_right/dtheta with lam = b / (b - a) for the one-sided
    slopes a <= 0 <= b (the minimax theorem). Both pieces are sampled a hair either side of the minimiser.
    """
    delta = 1e-4 * rays.h.detach()
    s = torch.stack([s_min - delta, s_min, s_min + delta], dim=1)  # M x 3
    f = rays.implicit(s)
    with torch.no_grad():
        left = ((f[:, 1] - f[:, 0]) / delta).clamp_max(0.0)
        right = ((f[:, 2] - f[:, 1]) / delta).clamp_min(0.0)
        lam = torch.where(right - left > 1e-6, right / (right - left + 1e-30), torch.full_like(left, 0.5))
    return f[:, 1].detach() + lam * (f[:, 0] - f[:, 0].detach()) + (1 - lam) * (f[:, 2] - f[:, 2].detach())


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


def _surface_at(rays: _Rays, found: Found, slopes: torch.Tensor):
    """Differentiable hit parameters along the rays (M), canonical normals of the seen side (M x 3), uv (M x 2)."""
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
    slope = rays.radius(v[:, None], slopes)[:, 0]
    side = torch.stack([p[:, 0] / rho, -slope, p[:, 2] / rho], dim=-1)
    side = side / side.norm(dim=-1, keepdim=True)
    side = torch.where(found.inner[:, None], -side, side)
    up = torch.zeros_like(side)
    up[:, 1] = torch.where(found.inner, 1.0, -1.0)
    normal = torch.where(bottom[:, None], up, side)
    u = torch.atan2(p[:, 0], -p[:, 2]) / math.pi
    return s, normal, torch.stack([u, v], dim=-1)
