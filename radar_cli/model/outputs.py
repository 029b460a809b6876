"""The typed result of de-rendering a batch: what the model predicts and what every consumer reads."""

from __future__ import annotations

from dataclasses import dataclass

import torch


@dataclass(frozen=True)
class Decomposition:
    """The intrinsic components of B images, in physical units (already rescaled to the config's ranges).

    Attributes:
        radius: B x L radius column, fractions of r_max, row 0 at the top.
        height: B half-heights, fractions of r_max.
        pose: B x 4 (pitch deg, roll deg, tx, ty as fractions of r_max).
        albedo: B x 3 x Ht x Wt linear diffuse albedo of the frontal third, in [0, 1].
        env: B x He x We environment map (linear, >= 0, camera frame; see radar_cli.render.lighting).
        alpha: B shininess (1..196).
        rho: B specular albedo (0..2).
    """

    radius: torch.Tensor
    height: torch.Tensor
    pose: torch.Tensor
    albedo: torch.Tensor
    env: torch.Tensor
    alpha: torch.Tensor
    rho: torch.Tensor

    def detach(self) -> "Decomposition":
        """The same components, detached from the autograd graph."""
        return Decomposition(*(t.detach() for t in self.as_tuple()))

    def to(self, device: torch.device | str) -> "Decomposition":
        """The same components on another device."""
        return Decomposition(*(t.to(device) for t in self.as_tuple()))

    def as_tuple(self) -> tuple[torch.Tensor, ...]:
        return (self.radius, self.height, self.pose, self.albedo, self.env, self.alpha, self.rho)

    def select(self, index: int) -> "Decomposition":
        """Object `index` of the batch, as a batch of one."""
        return Decomposition(*(t[index : index + 1] for t in self.as_tuple()))
