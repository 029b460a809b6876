"""D: the patch discriminator of the self-supervised albedo discriminator (SAD, supplementary Table 8)."""

from __future__ import annotations

import torch
from torch import nn

from radar_cli.model.blocks import channels, levels, norm_layer


class PatchDiscriminator(nn.Module):
    """Stride-2 convs from a p x p patch down to 4 x 4, then a 4x4 valid conv to one LSGAN score per patch."""

    def __init__(self, patch: int, width: int, max_channels: int):
        super().__init__()
        n = levels(patch, 4)
        layers: list[nn.Module] = []
        ch = 3
        for i in range(n):
            out = channels(width, i, max_channels)
            layers += [nn.Conv2d(ch, out, 4, 2, 1), norm_layer("instance" if i < n - 1 else "none", out),
                       nn.LeakyReLU(0.2)]
            ch = out
        layers.append(nn.Conv2d(ch, 1, 4, 1, 0))
        self.net = nn.Sequential(*layers)

    def forward(self, patches: torch.Tensor) -> torch.Tensor:
        """Args: patches N x 3 x p x p tone-mapped albedo in [0, 1]. Returns: N scores (unbounded)."""
        return self.net(patches * 2 - 1).flatten()
