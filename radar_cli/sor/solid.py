"""A batch of solids of revolution as the renderer takes them: the profile, the half-height and the pose."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import torch

from radar_cli.sor.profile import check_sor


@dataclass(frozen=True)
class Solid:
    """B solids of revolution, in fractions of r_max.

    Attributes:
        radius: B x L radius column, row 0 at the top.
        height: B half-heights.
        pose: B x 4 (pitch deg, roll deg, tx, ty as fractions of r_max).
    """

    radius: torch.Tensor
    height: torch.Tensor
    pose: torch.Tensor

    def check(self) -> dict[str, int]:
        """The sizes {"B", "L"}; ValueError naming the field whose shape or values are wrong."""
        return check_sor(self.radius, self.height, self.pose)

    @property
    def batch(self) -> int:
        return self.radius.shape[0]

    def rows(self, start: int, stop: int) -> "Solid":
        """Solids start..stop-1 of the batch."""
        return Solid(self.radius[start:stop], self.height[start:stop], self.pose[start:stop])

    def map(self, fn: Callable[[torch.Tensor], torch.Tensor]) -> "Solid":
        """The same solids with `fn` applied to each tensor (detach, to a device, select rows...)."""
        return Solid(fn(self.radius), fn(self.height), fn(self.pose))
