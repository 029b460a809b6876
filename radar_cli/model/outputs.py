"""The typed result of de-rendering a batch: what the model predicts and what every consumer reads."""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Callable

import torch

from radar_cli.render.material import Material
from radar_cli.sor.solid import Solid


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

    @property
    def solid(self) -> Solid:
        """The shape and pose, as the renderer takes them."""
        return Solid(self.radius, self.height, self.pose)

    @property
    def material(self) -> Material:
        """The frontal albedo, the light and the gloss, as the renderer takes them."""
        return Material(self.albedo, self.env, self.alpha, self.rho)

    def tensors(self) -> tuple[torch.Tensor, ...]:
        """Every component, in field order (for checks and comparisons over all of them)."""
        return tuple(getattr(self, f.name) for f in fields(self))

    def map(self, fn: Callable[[torch.Tensor], torch.Tensor]) -> "Decomposition":
        """The same components with `fn` applied to each."""
        return Decomposition(**{f.name: fn(getattr(self, f.name)) for f in fields(self)})

    def combine(self, other: "Decomposition",
                fn: Callable[[torch.Tensor, torch.Tensor], torch.Tensor]) -> "Decomposition":
        """Each component from `fn(self's, other's)`."""
        return Decomposition(**{f.name: fn(getattr(self, f.name), getattr(other, f.name)) for f in fields(self)})

    def detach(self) -> "Decomposition":
        """The same components, detached from the autograd graph."""
        return self.map(torch.Tensor.detach)

    def to(self, device: torch.device | str) -> "Decomposition":
        """The same components on another device."""
        return self.map(lambda t: t.to(device))

    @staticmethod
    def concat(parts: "list[Decomposition]") -> "Decomposition":
        """The batches `parts` one after the other (B = the sum of theirs)."""
        return Decomposition(**{f.name: torch.cat([getattr(p, f.name) for p in parts]) for f in fields(Decomposition)})

    def select(self, index: int) -> "Decomposition":
        """Object `index` of the batch, as a batch of one."""
        return self.map(lambda t: t[index : index + 1])
