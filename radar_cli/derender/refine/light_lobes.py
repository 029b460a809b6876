"""A few spherical-Gaussian lobes fitted to the unwrapped texture's shading (the lighting fit's light model,
derender.refine.fit_light; docs/refinement.md).

A lobe is the supplementary's light, L(eta) = sqrt(lambda) F exp(-lambda (1 - eta . xi)) (the model radar synth
draws its lighting from, synth.lighting), with its direction xi at elevation el and azimuth az in the convention
of render.lighting.env_directions. Lobes are baked into the He x We map as the solid-angle-weighted mean over
SUPERSAMPLE x SUPERSAMPLE points per texel, in closed form together with their Jacobian, so a Levenberg-Marquardt
fit can move their directions, sharpness and intensities against the photograph: the texture is linear in the
map (texel radiance = albedo x (Kd @ map) + rho x (Ks @ map)).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

import torch

from radar_cli.render.lighting import env_directions

SUPERSAMPLE = 2  # points per texel side when baking (the synthetic maps use 4; 2 moves the map by < 1%)
LM_START_DAMPING = 1e-3
LM_MAX_DAMPING = 1e8


@dataclass(frozen=True)
class LobeProblem:
    """The lighting fit's texels, for a lobe fit.

    Attributes:
        transport: (He*We) x 2n float32: Kd and Ks (render.lighting.phong_transport) of the n used texels side by
            side, transposed (float32 and this layout keep the fit's products faster than float64 would).
        linear: 3 x n linear texture of the used texels.
        rho: specular albedo, held.
        size: (He, We) of the map.
    """

    transport: torch.Tensor
    linear: torch.Tensor
    rho: float
    size: tuple[int, int]


@functools.lru_cache(maxsize=4)
def _bake_points(height: int, width: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Per map texel its SUPERSAMPLE^2 directions (E x s x 3) and their solid-angle weights summing to 1 (E x s),
    float64."""
    s = SUPERSAMPLE
    dirs, solid = env_directions(height * s, width * s, dtype=torch.float64)
    order = torch.arange(dirs.shape[0]).reshape(height, s, width, s).permute(0, 2, 1, 3).reshape(-1, s * s)
    weight = solid[order]
    return dirs[order], weight / weight.sum(1, keepdim=True)


def direction(elevation: torch.Tensor, azimuth: torch.Tensor) -> torch.Tensor:
    """Unit directions (k x 3) at elevations and azimuths (k each, radians; env_directions' convention)."""
    return torch.stack([torch.cos(elevation) * torch.sin(azimuth), torch.sin(elevation),
                        -torch.cos(elevation) * torch.cos(azimuth)], -1)


def bake_lobes(theta: torch.Tensor, size: tuple[int, int],
               jacobian: bool = True) -> tuple[torch.Tensor, torch.Tensor | None]:
    """The map of k lobes and its Jacobian.

    Args:
        theta: 4k float64: elevations (k), azimuths (k), log sharpness (k), log intensities (k).
        size: (He, We) of the map.
        jacobian: also return d map / d theta.

    Returns:
        (map He*We, Jacobian He*We x 4k or None).
    """
    k = theta.numel() // 4
    points, weight = _bake_points(*size)
    el, az, sharp, power = theta[:k], theta[k:2 * k], theta[2 * k:3 * k].exp(), theta[3 * k:].exp()
    cos = torch.einsum("esc,kc->esk", points, direction(el, az))  # E x s x k
    g = sharp.sqrt() * torch.exp(-sharp * (1 - cos)) * weight[..., None]  # E x s x k, weighted
    lobe = g.sum(1)  # E x k
    env = lobe @ power
    if not jacobian:
        return env, None
    d_el = torch.stack([-torch.sin(el) * torch.sin(az), torch.cos(el), torch.sin(el) * torch.cos(az)], -1)
    d_az = torch.stack([torch.cos(el) * torch.cos(az), torch.zeros_like(el), torch.cos(el) * torch.sin(az)], -1)
    pull = torch.einsum("esk,esc->ekc", g, points) * sharp[:, None]  # E x k x 3: d lobe / d xi
    d_sharp = (g * (0.5 - sharp * (1 - cos))).sum(1)  # d lobe / d log sharpness
    jac = torch.cat([(pull * d_el).sum(-1), (pull * d_az).sum(-1), d_sharp, lobe], 1) * power.repeat(4)
    return env, jac


def peak_directions(env: torch.Tensor, k: int, min_elevation: float) -> tuple[torch.Tensor, torch.Tensor]:
    """Elevations and azimuths (k each) of a map's k brightest local maxima at or above min_elevation (radians);
    missing ones are spread in azimuth at 30 deg elevation.

    Args:
        env: He x We map, float64.
    """
    height, width = env.shape
    padded = torch.cat([env[:, -1:], env, env[:, :1]], 1)  # azimuth wraps round
    padded = torch.cat([torch.full_like(padded[:1], -math.inf), padded, torch.full_like(padded[:1], -math.inf)])
    around = torch.stack([padded[1 + i:1 + i + height, 1 + j:1 + j + width] for i in (-1, 0, 1) for j in (-1, 0, 1)])
    dirs, _ = env_directions(height, width, dtype=torch.float64)
    elevation, azimuth = torch.asin(dirs[:, 1].clamp(-1, 1)), torch.atan2(dirs[:, 0], -dirs[:, 2])
    peak = ((env >= around.amax(0)) & (env > 0)).reshape(-1) & (elevation >= min_elevation)
    found = torch.nonzero(peak)[:, 0]
    found = found[env.reshape(-1)[found].argsort(descending=True, stable=True)][:k]
    missing = k - found.numel()
    el = torch.cat([elevation[found], torch.full((missing,), math.radians(30), dtype=torch.float64)])
    az = torch.cat([azimuth[found], torch.linspace(-0.6, 0.6, missing, dtype=torch.float64)])
    return el, az


def fit_lobes(problem: LobeProblem, start: torch.Tensor, k: int, paints: Callable[[torch.Tensor], torch.Tensor],
              rounds: int, steps: int, tolerance: float, sharpness: tuple[float, float], start_sharpness: float,
              min_elevation: float) -> torch.Tensor:
    """Fit k lobes to the texture, alternating with the paints.

    Starts at the k brightest peaks of `start` with sharpness `start_sharpness` and one shared intensity (least
    squares), then `rounds` times: the paints' albedos from the current map, and Levenberg-Marquardt on the lobes
    (at most `steps` accepted steps, stopping when one lowers the squared residual by less than `tolerance` of
    it). Elevations stay in [min_elevation, pi/2] and sharpness in `sharpness`.

    Args:
        problem: the texels. start: He x We float64 map the lobes start from.
        paints: a map (He*We) -> the used texels' paint albedos, 3 x n linear.

    Returns:
        The fitted map, He*We float64.
    """
    n = problem.linear.shape[1]
    target = problem.linear.reshape(-1)
    lo, hi = math.log(sharpness[0]), math.log(sharpness[1])
    el, az = peak_directions(start, k, min_elevation)
    theta = torch.cat([el, az, torch.full((2 * k,), math.log(start_sharpness), dtype=torch.float64)])
    theta[3 * k:] = 0.0

    def drawn(theta: torch.Tensor, jacobian: bool, albedo: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor | None]:
        """The texels' linear radiance (3n) and its Jacobian (3n x 4k or None)."""
        env, jac = bake_lobes(theta, problem.size, jacobian)
        columns = env[None] if jac is None else torch.cat([env[None], jac.T])  # (1 + 4k) x E
        shading = (columns.to(problem.transport.dtype) @ problem.transport).double()  # (1 + 4k) x 2n
        diffuse, specular = shading[:, :n], problem.rho * shading[:, n:]
        rows = torch.cat([albedo[c] * diffuse + specular for c in range(3)], 1)  # (1 + 4k) x 3n
        return rows[0], (rows[1:].T if jacobian else None)

    albedo = paints(start.reshape(-1))
    model, _ = drawn(theta, False, albedo)
    theta[3 * k:] = math.log(max(float(model @ target) / max(float(model @ model), 1e-30), 1e-12))
    for _ in range(rounds):
        albedo = paints(bake_lobes(theta, problem.size, False)[0])
        theta = _levenberg_marquardt(functools.partial(drawn, albedo=albedo), target, theta, steps, tolerance,
                                     (k, min_elevation, lo, hi))
    return bake_lobes(theta, problem.size, False)[0]


def _levenberg_marquardt(model: Callable[[torch.Tensor, bool], tuple[torch.Tensor, torch.Tensor | None]],
                         target: torch.Tensor, theta: torch.Tensor, steps: int, tolerance: float,
                         bounds: tuple[int, float, float, float]) -> torch.Tensor:
    """Minimise |model(theta) - target|^2 from theta, the elevations and log sharpness kept in bounds
    (k, min elevation, min and max log sharpness)."""
    k, min_elevation, lo, hi = bounds
    value, jac = model(theta, True)
    assert jac is not None  # asked for
    residual = value - target
    cost = float(residual @ residual)
    damping = LM_START_DAMPING
    for _ in range(steps):
        normal, gradient = jac.T @ jac, jac.T @ residual
        scale = normal.diagonal() + 1e-12 * float(normal.diagonal().max())
        improved = False
        while damping < LM_MAX_DAMPING:
            trial = theta + torch.linalg.solve(normal + torch.diag(damping * scale), -gradient)
            trial[:k] = trial[:k].clamp(min_elevation, math.pi / 2)
            trial[2 * k:3 * k] = trial[2 * k:3 * k].clamp(lo, hi)
            value, _ = model(trial, False)
            trial_residual = value - target
            trial_cost = float(trial_residual @ trial_residual)
            if trial_cost < cost:
                gain = (cost - trial_cost) / cost
                theta, residual, cost = trial, trial_residual, trial_cost
                damping = max(damping / 3, 1e-9)
                improved = True
                break
            damping *= 4
        if improved and gain >= tolerance:
            _, jac = model(theta, True)
            assert jac is not None
        if not improved or gain < tolerance:
            break
    return theta
