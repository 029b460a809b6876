"""The environment map refined against the photograph's shading at the fitted shape (radar's addition, step 2 of
`radar derender --refine full`; docs/refinement.md).

The photograph's frontal texture is unwrapped at the fitted shape onto a texel grid. Everything the shading
cannot tell from the albedo is pinned by one assumption: a vessel is painted in a few colours. The texture
divided by the starting lighting is clustered into those paints (k-means in display colour); a texel far from
its paint's centre (a thin line, an anti-aliased edge) is left out. The image is linear in the environment map,
and each paint's linear albedo follows from the lighting in closed form (least squares over its texels), with
shininess and specular albedo held at the network's.

The light is a few soft lights: spherical-Gaussian lobes (derender.refine.light_lobes). A regularised least-squares
solve for a coarse free map, alternating with the paints, finds where the light comes from; lobes started at
its brightest peaks are fitted by Levenberg-Marquardt, again alternating with the paints, once for each of a few
lobe counts. The photograph pins the light only loosely, and the fits disagree where it does not: the map is
the mean of their maps. It keeps the starting map's mean, since the albedo's brightness and the light's cannot
be told apart.

Only the environment map is fitted here; shininess and specular albedo are held at what the caller read
(derender.refine.driver: f_L's shininess, the specular-albedo reader's specular albedo). With the map unknown, a sharper
light and a lower shininess, or a brighter light in the highlight's direction and a lower specular albedo, draw
the same photograph (docs/refinement.md measures it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import cv2
import numpy as np
import torch
import torch.nn.functional as F

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.glare import GlareConfig, dim
from radar_cli.derender.refine.light_lobes import LobeProblem, fit_lobes
from radar_cli.derender.refine.texels import MIN_READ, read_front
from radar_cli.render.lighting import GAMMA, decompose, env_directions, phong_transport, tone_map
from radar_cli.sor.solid import Solid
from radar_cli.threads import torch_threads


@dataclass(frozen=True)
class LightFitConfig:
    """How the environment map is fitted (chosen on `radar synth --size 512` seeds 5 and 7; docs/refinement.md).

    Attributes:
        texels: side of the frontal texel grid the photograph is unwrapped onto.
        coarse: (rows, columns) of the free map that places the lobes, upsampled bilinearly to the model's map.
        paints: k-means clusters of the divided albedo.
        min_share: a paint covering less than this share of the usable texels is left out.
        max_distance: texels further than this from their paint's centre (display colour, 0..1) are left out.
        min_facing: texels whose normal faces the camera less than this (cosine) are left out.
        coverage: texels less covered than this by the located silhouette are left out.
        rounds: alternations of paints and the free map.
        smooth: weight of the free map's smoothness (squared differences of neighbouring coarse texels).
        ridge: weight of the free map's pull towards the starting map (relative to `smooth`).
        lobe_counts: the lobe fits whose maps are averaged, by their number of lobes (none: the free map).
        lobe_rounds: alternations of paints and lobes in each lobe fit.
        lobe_steps: Levenberg-Marquardt steps per alternation, at most.
        lobe_tolerance: a step that lowers the squared residual by less than this share of it ends the
            alternation's steps.
        sharpness: (min, max) lobe sharpness lambda (at half its peak a lobe is 34 deg from its centre at 4, 9
            deg at 60).
        start_sharpness: every lobe's starting sharpness.
        min_elevation: lobes stay at or above this elevation (deg): the lights are above the horizon.
        glare: how far the specular albedo is lowered where the fitted highlights outshine the photo
            (derender.refine.glare; None: not lowered).
    """

    texels: int = 32
    coarse: tuple[int, int] = (8, 24)
    paints: int = 6
    min_share: float = 0.03
    max_distance: float = 0.08
    min_facing: float = 0.2
    coverage: float = 0.9
    rounds: int = 6
    smooth: float = 0.3
    ridge: float = 1.0
    lobe_counts: tuple[int, ...] = (2, 3, 4)
    lobe_rounds: int = 6
    lobe_steps: int = 30
    lobe_tolerance: float = 1e-3
    sharpness: tuple[float, float] = (4.0, 60.0)
    start_sharpness: float = 15.0
    min_elevation: float = 0.0
    glare: GlareConfig | None = GlareConfig()


@dataclass(frozen=True)
class LightFit:
    """A fitted environment map and how well it draws the photograph.

    Attributes:
        env: 1 x He x We environment map (the starting map's size and mean).
        rmse: (fitted, start) root-mean-square error of the paints' model against the texture on the used
            texels, display levels 0..1.
        texels: texels used.
        specular_scale: the factor (<= 1) on the specular albedo that keeps the highlights as bright as the
            fits drew them, the map being brought to the starting map's mean (1 where the fits drew them
            brighter: the specular albedo is never raised here), times the factor that keeps them under the
            photo (`glare_scale`).
        glare_scale: the part of `specular_scale` that keeps the highlights under the photo (derender.refine.glare;
            1: they were).
    """

    env: torch.Tensor
    rmse: tuple[float, float]
    texels: int
    specular_scale: float = 1.0
    glare_scale: float = 1.0


def upsampler(coarse: tuple[int, int], size: tuple[int, int]) -> torch.Tensor:
    """The bilinear upsampling from a coarse map to a full one as a matrix: (He*We) x (hc*wc), float64."""
    n = coarse[0] * coarse[1]
    basis = np.eye(n, dtype=np.float32).reshape(n, coarse[0], coarse[1])
    cols = [cv2.resize(b, (size[1], size[0]), interpolation=cv2.INTER_LINEAR).reshape(-1) for b in basis]
    return torch.from_numpy(np.stack(cols, axis=1).astype(np.float64))


def smoothness(coarse: tuple[int, int]) -> torch.Tensor:
    """D^T D of the coarse map's neighbour differences (across rows, and across columns with the azimuth
    wrapping round): (hc*wc) x (hc*wc), float64."""
    rows, cols = coarse
    index = torch.arange(rows * cols).reshape(rows, cols)
    pairs = [(index, index.roll(-1, dims=1)), (index[:-1], index[1:])]
    a = torch.cat([p[0].reshape(-1) for p in pairs])
    b = torch.cat([p[1].reshape(-1) for p in pairs])
    diff = torch.zeros(a.numel(), rows * cols, dtype=torch.float64)
    diff[torch.arange(a.numel()), a] = 1.0
    diff[torch.arange(a.numel()), b] = -1.0
    return diff.T @ diff


def paint_labels(albedo: np.ndarray, config: LightFitConfig) -> np.ndarray:
    """Cluster display-space albedo colours (n x 3, 0..1) into paints: n labels, -1 where left out."""
    pixels = np.ascontiguousarray(albedo, dtype=np.float32)
    k = min(config.paints, len(pixels))
    cv2.setRNGSeed(0)
    criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 1e-3)
    # OpenCV's stubs want an array for bestLabels; None (let it allocate) is what its documentation allows
    _, labels, centres = cv2.kmeans(pixels, k, None, criteria, 3, cv2.KMEANS_PP_CENTERS)  # type: ignore[call-overload]
    labels = labels[:, 0]
    distance = np.linalg.norm(pixels - centres[labels], axis=1)
    share = np.bincount(labels, minlength=k) / len(labels)
    keep = (share[labels] >= config.min_share) & (distance < config.max_distance)
    return np.where(keep, labels, -1)


@dataclass(frozen=True)
class _Texels:
    """The used texels: Kd, Ks n x (He*We); linear and shown (display) texture 3 x n; paint n indices 0..P-1."""

    kd: torch.Tensor
    ks: torch.Tensor
    linear: torch.Tensor
    shown: torch.Tensor
    paint: torch.Tensor
    n_paints: int
    rho: float

    def paints(self, env: torch.Tensor) -> torch.Tensor:
        """3 x n: each texel's paint albedo under a map (He*We; least squares over the paint's texels), linear."""
        d, s = self.kd @ env, self.ks @ env
        num = torch.zeros(3, self.n_paints, dtype=d.dtype).index_add_(1, self.paint, d * (self.linear - self.rho * s))
        den = torch.zeros(self.n_paints, dtype=d.dtype).index_add_(0, self.paint, d * d)
        return (num / den.clamp_min(1e-12)).clamp_min(1e-3)[:, self.paint]

    def rmse(self, env: torch.Tensor) -> float:
        """The paints' model under a map (He*We) against the texture, display levels."""
        drawn = tone_map(self.paints(env) * (self.kd @ env) + self.rho * (self.ks @ env))
        return float(((drawn - self.shown) ** 2).mean().sqrt())


def _texels(crop: np.ndarray, silhouette: np.ndarray, geo: Solid, start: torch.Tensor,
            alpha: float, rho: float, camera: CameraConfig, config: LightFitConfig) -> _Texels | None:
    """Unwrap the crop at the shape, keep the usable texels and cluster them into paints under `start`
    (He x We float64); None when under 5% of the grid is usable."""
    g = config.texels
    dtype = torch.float64
    front = read_front(crop, silhouette, geo, g, camera, config.coverage, config.min_facing, dtype)
    if front is None:
        return None
    shown = front.shown  # 3 x n display
    directions = env_directions(start.shape[0], start.shape[1], dtype=dtype)
    kd, ks = phong_transport(front.normals, front.view, *directions, alpha)
    diffuse, specular = kd @ start.reshape(-1), ks @ start.reshape(-1)  # n each
    divided = decompose(shown[None, :, None], diffuse[None, None], specular[None, None],
                        torch.tensor([rho], dtype=dtype), GAMMA)[0, :, 0]  # 3 x n linear
    labels = torch.from_numpy(paint_labels((divided ** (1 / GAMMA)).T.numpy(), config))
    keep = labels >= 0
    if int(keep.sum()) < MIN_READ * g * g:
        return None
    _, paint = torch.unique(labels[keep], return_inverse=True)  # n paint indices 0..P-1
    shown = shown[:, keep]
    return _Texels(kd[keep], ks[keep], shown ** GAMMA, shown, paint, int(paint.max()) + 1, rho)


def _free_map(texels: _Texels, start: torch.Tensor, config: LightFitConfig) -> torch.Tensor:
    """The coarse free map (regularised least squares, alternating with the paints), upsampled: He x We."""
    up = upsampler(config.coarse, (start.shape[0], start.shape[1]))  # E x c
    kd, ks = texels.kd @ up, texels.ks @ up  # n x c
    coarse_start = F.adaptive_avg_pool2d(start[None, None], config.coarse).reshape(-1)
    mean = float(coarse_start.mean())
    smooth = smoothness(config.coarse)
    eye = torch.eye(smooth.shape[0], dtype=torch.float64)
    e = coarse_start.clone()
    for _ in range(config.rounds):
        albedo = texels.paints(up @ e)
        system = torch.cat([albedo[c][:, None] * kd + texels.rho * ks for c in range(3)])  # 3n x c
        weight = config.smooth * float((system * system).sum()) / (10 * system.shape[1])
        lhs = system.T @ system + weight * (smooth + config.ridge * eye)
        rhs = system.T @ texels.linear.reshape(-1) + weight * config.ridge * coarse_start
        e = torch.linalg.solve(lhs, rhs).clamp_min(0.0)
        e = e * (mean / max(float(e.mean()), 1e-12))
    return (up @ e).reshape(start.shape)


def fit_environment(crop: np.ndarray, silhouette: np.ndarray, radius: torch.Tensor, height: torch.Tensor,
                    pose: torch.Tensor, env: torch.Tensor, alpha: float, rho: float, camera: CameraConfig,
                    config: LightFitConfig = LightFitConfig()) -> LightFit | None:
    """Fit the environment map to the photograph's shading at a fitted shape.

    Args:
        crop: N x N x 3 uint8 crop; silhouette: N x N bool located silhouette.
        radius: 1 x L; height: 1; pose: 1 x 4 (the fitted shape and pose).
        env: 1 x He x We starting map. alpha, rho: shininess and specular albedo, held.
        camera: the fixed camera.

    Returns:
        The fit, or None when too few texels are usable (under 5% of the grid).
    """
    # one thread: the products are small, and the same input gives the same bits whatever the caller's threads
    with torch_threads(1):
        return _fit(crop, silhouette, radius, height, pose, env, alpha, rho, camera, config)


def _fit(crop: np.ndarray, silhouette: np.ndarray, radius: torch.Tensor, height: torch.Tensor, pose: torch.Tensor,
         env: torch.Tensor, alpha: float, rho: float, camera: CameraConfig, config: LightFitConfig) -> LightFit | None:
    """fit_environment's work, on the calling thread's torch threads."""
    geo = Solid(radius, height, pose).map(lambda t: t.double().cpu())
    start = env[0].double().cpu()
    texels = _texels(crop, silhouette, geo, start, alpha, rho, camera, config)
    if texels is None:
        return None
    free = _free_map(texels, start, config)
    transport = torch.cat([texels.kd, texels.ks]).T.float().contiguous()  # E x 2n
    problem = LobeProblem(transport, texels.linear, rho, (start.shape[0], start.shape[1]))
    maps, means = [], []
    for k in config.lobe_counts:
        lobes = fit_lobes(problem, free, k, texels.paints, config.lobe_rounds, config.lobe_steps,
                          config.lobe_tolerance, config.sharpness, config.start_sharpness,
                          math.radians(config.min_elevation))
        means.append(max(float(lobes.mean()), 1e-12))
        maps.append(lobes / means[-1])
    fitted = torch.stack(maps).mean(0).clamp_min(0.0) if maps else free.reshape(-1)
    # the paints take up the diffuse light's scale, the highlights do not: the map's scale that the fits found
    # is what the photo's highlights support (a photo without them: a dim map), and the specular albedo keeps it
    scale = min(1.0, float(np.median(means)) / max(float(start.mean()), 1e-12)) if means else 1.0
    fitted = (fitted * (float(start.mean()) / max(float(fitted.mean()), 1e-12))).reshape(start.shape)
    glare = 1.0 if config.glare is None else dim(crop, silhouette, geo, fitted, alpha, rho * scale, camera,
                                                   config.glare)
    rmse = (replace(texels, rho=rho * scale * glare).rmse(fitted.reshape(-1)), texels.rmse(start.reshape(-1)))
    return LightFit(fitted[None].to(env.dtype).to(env.device), rmse, int(texels.paint.numel()), scale * glare,
                    glare)
