"""The specular albedo lowered until the fitted highlights stay within what the photograph shows.

A highlight is light added to the paint, so where the photo is dark no highlight can be bright. The lobe fits
(derender.refine.fit_light) place a few compact lights where the diffuse shading says the light comes from; on a
black glaze photographed under broad or polarised studio lights (soft reflections, or none) the shininess and
specular albedo the networks read then draw those lights as white spots the photo does not have, and dividing the
photo by that shading leaves dark blotches in the albedo that every relit view repeats. The photo shows no such
highlight, so the specular albedo is lowered by the least of a ladder of factors that brings the spots under it.
(Spreading the lights instead, the map blurred by 1.5-4 map texels, turned the spots into grey glows:
docs/refinement.md.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.export.likeness import LUMA
from radar_cli.derender.refine.texels import read_front
from radar_cli.render.lighting import GAMMA, env_directions, phong_transport
from radar_cli.sor.solid import Solid


@dataclass(frozen=True)
class GlareConfig:
    """When and how far the specular albedo is lowered.

    Attributes:
        texels: side of the frontal texel grid the check reads the photo on (finer than the lighting fit's: a
            white spot covers a few percent of the object).
        glaring: a texel whose drawn highlight outshines the photo by this much (luminance, display 0..1) shows a
            white spot there. Below the 0.3 that the status reads in the input view
            (`derender.export.likeness.GLARING`): this check reads the fitted profile's exact normals, the export
            draws the resampled profile with its shading interpolated, and a highlight on a curved neck a
            little brighter (at 0.3 one red-figure jug kept a spot on its neck).
        trigger: the specular albedo is lowered where more than this share of the object (texels weighted by how
            squarely they face the camera) glares ...
        target: ... by the largest factor of the ladder 1, step, step^2, ... that brings the share to this or less
            (at most `steps` steps).
        min_facing, coverage: texels facing the camera less than this (cosine), or less covered by the located
            silhouette, are not read (the limbs: the outline's errors and grazing reflections).
    """

    texels: int = 64
    glaring: float = 0.2
    trigger: float = 0.002
    target: float = 0.0005
    step: float = 0.85
    steps: int = 28
    min_facing: float = 0.2
    coverage: float = 0.9


@dataclass(frozen=True)
class _Surface:
    """The read texels: Ks n x (He*We); the photo's linear and display texture, 3 x n; the weights n."""

    ks: torch.Tensor
    linear: torch.Tensor
    shown: torch.Tensor
    weight: torch.Tensor

    def glare(self, env: torch.Tensor, rho: float, glaring: float) -> float:
        """Weighted share of the texels whose highlight under `env` (He x We) outshines the photo by `glaring`.
        Drawn, a texel is the photo or the highlight, whichever is brighter per channel (the divided albedo is
        the photo less the highlight, at least 0)."""
        luma = torch.from_numpy(LUMA).to(self.linear.dtype)
        highlight = rho * (self.ks @ env.reshape(-1).to(self.ks.dtype))  # n
        drawn = torch.maximum(self.linear, highlight[None]) ** (1 / GAMMA)
        over = (luma @ drawn - luma @ self.shown) > glaring
        return float((self.weight * over).sum() / self.weight.sum())


def _surface(crop: np.ndarray, silhouette: np.ndarray, geo: Solid, env_shape: tuple[int, int], alpha: float,
             camera: CameraConfig, config: GlareConfig) -> _Surface | None:
    """The crop unwrapped at the shape onto the check's texels; None where too few are read."""
    dtype = torch.float32
    front = read_front(crop, silhouette, geo, config.texels, camera, config.coverage, config.min_facing, dtype)
    if front is None:
        return None
    _, ks = phong_transport(front.normals, front.view, *env_directions(*env_shape, dtype=dtype), alpha)
    return _Surface(ks, front.shown ** GAMMA, front.shown, front.facing)


def dim(crop: np.ndarray, silhouette: np.ndarray, geo: Solid, env: torch.Tensor, alpha: float, rho: float,
        camera: CameraConfig, config: GlareConfig = GlareConfig()) -> float:
    """The factor (<= 1) on the specular albedo that keeps the fitted highlights under the photo (module
    docstring): 1 where they glare on `config.trigger` of the object or less.

    Args:
        crop: N x N x 3 uint8; silhouette: N x N bool. geo: the fitted solid (batch of one).
        env: He x We fitted map (linear). alpha, rho: the shininess and specular albedo it is drawn with.
    """
    surface = _surface(crop, silhouette, geo.map(lambda t: t.float().cpu()), (env.shape[0], env.shape[1]),
                       alpha, camera, config)
    if surface is None or surface.glare(env, rho, config.glaring) <= config.trigger:
        return 1.0
    factor = 1.0
    for _ in range(config.steps):
        factor *= config.step
        if surface.glare(env, rho * factor, config.glaring) <= config.target:
            break
    return factor
