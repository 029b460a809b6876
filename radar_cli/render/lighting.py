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
        alpha: B shininess (>= 1 keeps the lobe's gradient finite where it vanishes).

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
    diffuse, specular = _Phong.apply(normals.reshape(n_batch, -1, 3), view.reshape(n_batch, -1, 3), radiance,
                                     alpha, dirs)
    return diffuse.view(n_batch, h, w), specular.view(n_batch, h, w)


CHUNK_ELEMENTS = 1 << 18  # B x samples x lights per chunk: bounds the B x N x E intermediates (1 MiB in float32,
# cache-sized: measured 2x faster than 16 MiB chunks on the CPU)
KEEP_ELEMENTS = 1 << 25  # up to this B x N x E the forward's chunks are kept for backward (4 x 128 MiB in float32)
# instead of recomputed; larger problems (64 x 64 grids at batch 24) recompute to keep memory flat
GPU_CHUNK_ELEMENTS = 1 << 24  # on a GPU, cache-sized chunks mean thousands of tiny kernel launches per step (the
# paper preset's step launched ~12k for Phong alone and took 0.46 s on an H100; 0.08-0.10 s with these and
# the ray caster's index_select gathers): 64 MiB chunks, a handful per call
GPU_KEEP_ELEMENTS = 1 << 28  # and keep up to 4 x 1 GiB for backward rather than recompute
BIG = 1e30  # step(x) = clamp(x * BIG, 0, 1): a 0/1 mask in two cheap passes (a comparison + masked_fill is ~15x
# slower on the CPU); it differs from x > 0 only for 0 < x < 1e-30


def _step(x: torch.Tensor) -> torch.Tensor:
    """1 where x > 0 (x >= 1e-30), 0 where x <= 0, as x's dtype."""
    return (x * BIG).clamp_(0.0, 1.0)


def phong_transport(normals: torch.Tensor, view: torch.Tensor, dirs: torch.Tensor, solid: torch.Tensor,
                    alpha: float) -> tuple[torch.Tensor, torch.Tensor]:
    """Eq. 6-7 per light, as matrices: I_d = Kd @ E and I_s = Ks @ E for a map E flattened as `dirs`.

    Args:
        normals, view: n x 3 unit vectors (camera frame). dirs, solid: `env_directions` of the map.
        alpha: shininess.

    Returns:
        (Kd, Ks), each n x (He*We).
    """
    ln, rp = _cosines(normals[None], view[None], dirs)
    lobe = torch.exp((alpha * torch.log(rp[0].clamp_min(TINY))).clamp_min(LOG_FLOOR))
    return ln[0].clamp_min(0.0) * solid, (alpha + 1) / (2 * math.pi) * lobe * solid


def _phong_chunk(n: torch.Tensor, p: torch.Tensor, dirs: torch.Tensor, alpha: torch.Tensor):
    """Per-light terms for one chunk of samples (B x n x 3 each), all B x n x E: clamped L.N, R.P (0 where the
    light is below the surface or the lobe points away), log of it, and the lobe max(0, R.P)^alpha.
    R_i . P = L_i . R_v with R_v = 2 (N.P) N - P, the view direction mirrored about N."""
    ln, rp = _cosines(n, p, dirs)
    log_rp = torch.log(rp.clamp_min(TINY))
    # exp(alpha log x) is much faster than a broadcast pow; the floor keeps exp away from denormals (slow on CPU)
    lobe = torch.exp((log_rp * alpha[:, None, None]).clamp_min_(LOG_FLOOR))
    return ln.clamp_min_(0.0), rp, log_rp, lobe


def _cosines(n: torch.Tensor, p: torch.Tensor, dirs: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """For every sample and light, B x n x E each: L.N (unclamped) and max(0, R_v . L), 0 where the light is
    below the surface."""
    ln = n @ dirs.T
    mirror = 2 * (n * p).sum(-1, keepdim=True) * n - p  # B x n x 3
    return ln, (mirror @ dirs.T).clamp_min_(0.0).mul_(_step(ln))


def _phong_sums(n: torch.Tensor, p: torch.Tensor, dirs: torch.Tensor, alpha: torch.Tensor, rad: torch.Tensor):
    """Forward only, in place: (sum_L max(0, L.N) rad, sum_L lobe rad) for one chunk, each B x n."""
    ln, lobe = _cosines(n, p, dirs)
    lobe = lobe.clamp_min_(TINY).log_().mul_(alpha[:, None, None]).clamp_min_(LOG_FLOOR).exp_()
    return (ln.clamp_min_(0.0) @ rad)[..., 0], (lobe @ rad)[..., 0]


TINY = 1e-30  # floor inside log(R.P): the lobe of a dark light is exp(-69 alpha) ~ 0, never NaN
LOG_FLOOR = -60.0  # floor of alpha log(R.P): lobes below exp(-60) are taken as exp(-60) (~1e-26, invisible)
LOBE_FLOOR = 1e-26  # lobes at or below this (the floor) get no gradient


class _Phong(torch.autograd.Function):
    """Eq. 6-7 summed over all environment texels, in chunks of samples, with an analytic backward that
    recomputes each chunk: memory stays O(chunk) instead of several B x N x E tensors kept for autograd."""

    @staticmethod
    def forward(ctx, n, p, radiance, alpha, dirs):
        step = _chunk(n, dirs)
        rad = radiance[..., None]  # B x E x 1
        keep_limit = GPU_KEEP_ELEMENTS if n.is_cuda else KEEP_ELEMENTS
        keep = any(ctx.needs_input_grad) and n.shape[0] * n.shape[1] * dirs.shape[0] <= keep_limit
        diffuse, lobe_sum, ctx.chunks = [], [], []
        for i in range(0, n.shape[1], step):
            if not keep:
                d, s = _phong_sums(n[:, i : i + step], p[:, i : i + step], dirs, alpha, rad)
                diffuse.append(d)
                lobe_sum.append(s)
                continue
            chunk = _phong_chunk(n[:, i : i + step], p[:, i : i + step], dirs, alpha)
            ln, lobe = chunk[0], chunk[3]
            diffuse.append((ln @ rad)[..., 0])
            lobe_sum.append((lobe @ rad)[..., 0])
            ctx.chunks.append(chunk)
        norm = (alpha[:, None] + 1) / (2 * math.pi)
        lobes = torch.cat(lobe_sum, 1)  # B x N, kept: d I_s / d alpha needs it
        ctx.save_for_backward(n, p, radiance, alpha, dirs, lobes)
        return torch.cat(diffuse, 1), norm * lobes

    @staticmethod
    def backward(ctx, g_diffuse, g_specular):
        n, p, radiance, alpha, dirs, lobe_sum = ctx.saved_tensors
        step = _chunk(n, dirs)
        norm = (alpha + 1) / (2 * math.pi)  # B
        rad = radiance[..., None]  # B x E x 1
        g_n, g_p = torch.zeros_like(n), torch.zeros_like(p)
        g_rad = torch.zeros_like(radiance)
        g_alpha = (g_specular * lobe_sum).sum(1) / (2 * math.pi)  # from the normalisation (alpha + 1) / (2 pi)
        for i in range(0, n.shape[1], step):
            sl = slice(i, i + step)
            chunk = ctx.chunks[i // step] if ctx.chunks else _phong_chunk(n[:, sl], p[:, sl], dirs, alpha)
            ln, rp, log_rp, lobe = chunk
            gd = g_diffuse[:, sl, None]  # B x n x 1
            gs = g_specular[:, sl, None] * norm[:, None, None]
            g_rad += (ln.transpose(1, 2) @ gd + lobe.transpose(1, 2) @ gs)[..., 0]
            # ... and from the lobe: norm * sum lobe log(rp) rad
            g_alpha += (gs * ((lobe * log_rp) @ rad)).sum((1, 2))
            # d lobe / d rp = alpha rp^(alpha - 1) where the light counts; d diffuse / d ln = rad where lit
            g_rp = (lobe / rp.clamp_min(TINY)).mul_(_step(lobe - LOBE_FLOOR)).mul_(radiance[:, None, :])
            g_rp *= gs * alpha[:, None, None]
            g_ln = (gd * radiance[:, None, :]).mul_(_step(ln))
            g_mirror = g_rp @ dirs  # B x n x 3
            nk, pk = n[:, sl], p[:, sl]
            np_ = (nk * pk).sum(-1, keepdim=True)
            gm_n = (g_mirror * nk).sum(-1, keepdim=True)
            g_n[:, sl] = g_ln @ dirs + 2 * (np_ * g_mirror + gm_n * pk)
            g_p[:, sl] = 2 * gm_n * nk - g_mirror
        ctx.chunks = []  # release the kept intermediates
        return g_n, g_p, g_rad, g_alpha, None


def _chunk(n: torch.Tensor, dirs: torch.Tensor) -> int:
    """Samples per chunk so one B x chunk x E tensor holds about CHUNK_ELEMENTS (GPU_CHUNK_ELEMENTS) values."""
    return max(1, (GPU_CHUNK_ELEMENTS if n.is_cuda else CHUNK_ELEMENTS) // max(1, n.shape[0] * dirs.shape[0]))


def tone_map(x: torch.Tensor, gamma: float = GAMMA) -> torch.Tensor:
    """tau(x) = x^(1/gamma), with a floor so the gradient stays finite at 0."""
    return power(x.clamp_min(EPS), 1.0 / gamma)


def power(x: torch.Tensor, exponent: float) -> torch.Tensor:
    """x^exponent for x > 0 as exp(exponent log x): cheaper than torch.pow on the CPU (docs/performance.md), same
    gradient."""
    return torch.exp(torch.log(x) * exponent)


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


def decompose(
    texture: torch.Tensor, diffuse: torch.Tensor, specular: torch.Tensor, rho: torch.Tensor,
    gamma: float = GAMMA, max_specular_share: float = 1.0,
) -> torch.Tensor:
    """The albedo that `compose` turns into `texture` under the given shading: A = (tau^-1(T) - rho I_s) / I_d.

    The specular part taken away is capped at `max_specular_share` of the texel's linear radiance, so a
    highlight the shading overestimates leaves a dimmed albedo instead of a black hole; the result is clamped to
    [0, 1] (where the diffuse factor is ~0 the albedo is unknown and comes out 1 or 0).

    Args:
        texture: B x 3 x Ht x Wt tone-mapped texture in [0, 1].
        diffuse, specular: B x 1 x Ht x Wt (or B x Ht x Wt) linear shading factors; rho: B specular albedo.

    Returns:
        B x 3 x Ht x Wt linear albedo in [0, 1].
    """
    d = diffuse if diffuse.dim() == 4 else diffuse[:, None]
    s = specular if specular.dim() == 4 else specular[:, None]
    radiance = power(texture.clamp_min(EPS), gamma)
    highlight = torch.minimum(rho[:, None, None, None] * s, max_specular_share * radiance)
    return ((radiance - highlight) / d.clamp_min(EPS)).clamp(0.0, 1.0)


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
