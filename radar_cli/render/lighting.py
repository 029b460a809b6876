"""Environment-map Phong shading with the normalised specular term, and tone-mapping (paper Eq. 5-8).

The environment map E (B x He x We, grey, equirectangular, camera frame) is a set of directional lights: texel
(i, j) has elevation el_i = pi/2 - (i + 0.5) pi / He and azimuth az_j = -pi + (j + 0.5) 2 pi / We, direction
L = (cos el sin az, sin el, -cos el cos az) (azimuth 0 = light from behind the camera), and radiance E_ij times
its solid angle w_i = cos(el_i) (pi / He) (2 pi / We). So a uniform map E = 1 gives a diffuse factor of pi on
any surface facing the camera.
"""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F

from radar_cli.checks import check_range, check_shape

GAMMA = 2.2
EPS = 1e-6


def env_directions(height: int, width: int, device=None, dtype=torch.float32) -> tuple[torch.Tensor, torch.Tensor]:
    """Light directions (He*We x 3) and solid angles (He*We) of the environment-map texels."""
    el = math.pi / 2 - (torch.arange(height, device=device, dtype=dtype) + 0.5) * (math.pi / height)
    az = -math.pi + (torch.arange(width, device=device, dtype=dtype) + 0.5) * (2 * math.pi / width)
    el_g, az_g = torch.meshgrid(el, az, indexing="ij")
    dirs = torch.stack([torch.cos(el_g) * torch.sin(az_g), torch.sin(el_g), -torch.cos(el_g) * torch.cos(az_g)], -1)
    solid = torch.cos(el_g) * (math.pi / height) * (2 * math.pi / width)
    return dirs.reshape(-1, 3), solid.reshape(-1)


def shading_factors(
    normals: torch.Tensor, view: torch.Tensor, env: torch.Tensor, alpha: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """Diffuse and normalised-specular lighting factors (Eq. 6-7) at surface samples.

    Args:
        normals: B x H x W x 3 unit normals (camera frame).
        view: B x H x W x 3 unit directions towards the camera (P in the paper).
        env: B x He x We environment map, >= 0.
        alpha: B shininess.

    Returns:
        (I_d, I_s), each B x H x W.
    """
    dims = check_shape(normals, "B H W 3", "normals")
    check_shape(view, "B H W 3", "view", dims)
    check_shape(env, "B He We", "env", dims)
    check_shape(alpha, "B", "alpha", dims)
    n_batch, h, w, _ = normals.shape
    dirs, solid = env_directions(env.shape[1], env.shape[2], env.device, env.dtype)
    radiance = env.reshape(n_batch, -1) * solid  # B x E
    n = normals.reshape(n_batch, -1, 3)
    p = view.reshape(n_batch, -1, 3)
    ln = n @ dirs.T  # B x N x E
    lp = p @ dirs.T
    np_ = (n * p).sum(-1, keepdim=True)  # B x N x 1
    diffuse = ln.clamp_min(0) @ radiance[..., None]  # B x N x 1
    rp = (2 * ln * np_ - lp).clamp_min(0) * (ln > 0)  # reflected light . view, lights above the surface only
    lobe = torch.exp(alpha[:, None, None] * torch.log(rp + EPS))  # rp ** alpha, finite gradient at 0
    specular = (alpha[:, None, None] + 1) / (2 * math.pi) * (lobe @ radiance[..., None])
    return diffuse.view(n_batch, h, w), specular.view(n_batch, h, w)


def tone_map(x: torch.Tensor, gamma: float = GAMMA) -> torch.Tensor:
    """tau(x) = x^(1/gamma), with a floor so the gradient stays finite at 0."""
    return x.clamp_min(EPS) ** (1.0 / gamma)


def compose(
    albedo: torch.Tensor, diffuse: torch.Tensor, specular: torch.Tensor, rho: torch.Tensor, gamma: float = GAMMA
) -> torch.Tensor:
    """T = tau(A * I_d + rho * I_s) (Eq. 5).

    Args:
        albedo: B x 3 x Ht x Wt linear albedo. diffuse, specular: B x Ht x Wt (or broadcastable B x 1 x Ht x Wt).
        rho: B specular albedo.

    Returns:
        B x 3 x Ht x Wt tone-mapped texture.
    """
    d = diffuse if diffuse.dim() == 4 else diffuse[:, None]
    s = specular if specular.dim() == 4 else specular[:, None]
    return tone_map(albedo * d + rho[:, None, None, None] * s, gamma)


def upsample(x: torch.Tensor, size: tuple[int, int]) -> torch.Tensor:
    """Bilinear upsampling of B x H x W (or B x C x H x W) maps from the shading grid to texture size."""
    squeeze = x.dim() == 3
    y = F.interpolate(x[:, None] if squeeze else x, size=size, mode="bilinear", align_corners=False)
    return y[:, 0] if squeeze else y


def check_material(alpha: torch.Tensor, rho: torch.Tensor, env: torch.Tensor) -> None:
    """Validate shininess (>= 0), specular albedo (>= 0) and environment map (>= 0, finite)."""
    check_range(alpha, 0.0, 1e4, "alpha")
    check_range(rho, 0.0, 1e3, "rho")
    check_range(env, 0.0, 1e6, "env")
