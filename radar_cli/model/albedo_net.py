"""f_A: unwrapped texture -> diffuse albedo, a U-Net with nearest upsampling + conv (supplementary Table 7)."""

from __future__ import annotations

import torch
from torch import nn

from radar_cli.model.blocks import channels, norm_layer


class AlbedoNet(nn.Module):
    """`depth` stride-2 conv levels down, `depth` upsample + conv levels up with skip connections, Tanh."""

    def __init__(self, depth: int, width: int, max_channels: int):
        super().__init__()
        enc_ch = [channels(width, i, max_channels) for i in range(depth)]
        self.down = nn.ModuleList()
        ch = 3
        for out in enc_ch:
            self.down.append(nn.Sequential(nn.Conv2d(ch, out, 4, 2, 1), norm_layer("instance", out),
                                           nn.LeakyReLU(0.2)))
            ch = out
        self.up = nn.ModuleList()
        for i in range(depth - 1, 0, -1):  # up to the resolution of encoder level i - 1, then concat its skip
            out = enc_ch[i - 1]
            self.up.append(nn.Sequential(nn.Upsample(scale_factor=2, mode="nearest"), nn.Conv2d(ch, out, 3, 1, 1),
                                         norm_layer("instance", out)))
            ch = out * 2
        self.last = nn.Sequential(nn.Upsample(scale_factor=2, mode="nearest"), nn.Conv2d(ch, 3, 3, 1, 1), nn.Tanh())

    def forward(self, texture: torch.Tensor) -> torch.Tensor:
        """Args: texture B x 3 x Ht x Wt in [0, 1]. Returns: albedo B x 3 x Ht x Wt in [0, 1] (linear)."""
        x = texture * 2 - 1
        skips = []
        for layer in self.down:
            x = layer(x)
            skips.append(x)
        for layer, skip in zip(self.up, reversed(skips[:-1])):
            x = torch.relu(torch.cat([layer(x), skip], dim=1))
        return (self.last(x) + 1) * 0.5
