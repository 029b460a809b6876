"""What the renderer shades a solid with: its diffuse albedo map, the environment light and the glossy material."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import torch


@dataclass(frozen=True)
class Material:
    """The appearance of B solids (Eq. 5-7).

    Attributes:
        albedo: B x 3 x Ht x Wt linear diffuse albedo in [0, 1]: the frontal third, or the whole 360 deg map
            (column 0 at the back, -180 deg), as the function taking it says.
        env: B x He x We environment map (linear, >= 0, camera frame; see radar_cli.render.lighting).
        alpha: B shininess (1..196).
        rho: B specular albedo.
    """

    albedo: torch.Tensor
    env: torch.Tensor
    alpha: torch.Tensor
    rho: torch.Tensor

    def map(self, fn: Callable[[torch.Tensor], torch.Tensor]) -> "Material":
        """The same material with `fn` applied to each tensor."""
        return Material(fn(self.albedo), fn(self.env), fn(self.alpha), fn(self.rho))

    def with_albedo(self, albedo: torch.Tensor) -> "Material":
        """The same light and gloss over another albedo map (e.g. the 360 deg map of a frontal third)."""
        return Material(albedo, self.env, self.alpha, self.rho)
