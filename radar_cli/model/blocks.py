"""Layer builders shared by the networks: the strided-conv encoder to a latent vector and channel schedules."""

from __future__ import annotations

import math
from typing import Literal

from torch import nn

Norm = Literal["none", "group", "instance"]


def channels(width: int, level: int, max_channels: int) -> int:
    """Channels at encoder level `level` (0-based): width * 2^level, capped."""
    return min(width * 2**level, max_channels)


def levels(size: int, stop: int) -> int:
    """Number of stride-2 halvings from `size` down to `stop` (both powers of two)."""
    return int(round(math.log2(size / stop)))


def norm_layer(kind: Norm, ch: int) -> nn.Module:
    """GroupNorm with 4 channels per group (the paper's GN(n) uses n = ch / 4), InstanceNorm, or nothing."""
    if kind == "group":
        return nn.GroupNorm(max(1, ch // 4), ch)
    if kind == "instance":
        return nn.InstanceNorm2d(ch)
    return nn.Identity()


def conv_encoder(in_ch: int, size: int, width: int, max_channels: int, latent: int, norm: Norm) -> nn.Sequential:
    """Image B x in_ch x size x size -> B x latent x 1 x 1 (supplementary Tables 5-6 encoders).

    Stride-2 4x4 convolutions halve the image down to 4 x 4, then a 4x4 valid convolution gives the latent
    vector. With norm = "none" the activation is ReLU (f_S), otherwise LeakyReLU(0.2) with the norm on every
    layer but the last strided one (f_L).
    """
    n = levels(size, 4)
    layers: list[nn.Module] = []
    ch = in_ch
    for i in range(n):
        out = channels(width, i, max_channels)
        layers.append(nn.Conv2d(ch, out, 4, 2, 1))
        if norm != "none":
            layers.append(norm_layer(norm, out) if i < n - 1 else nn.Identity())
            layers.append(nn.LeakyReLU(0.2))
        else:
            layers.append(nn.ReLU())
        ch = out
    layers += [nn.Conv2d(ch, latent, 4, 1, 0), nn.ReLU()]
    return nn.Sequential(*layers)


def head(latent: int, n_out: int) -> nn.Sequential:
    """Two FC layers (Linear + ReLU + Linear) then a sigmoid: scalars in [0, 1] to be rescaled."""
    return nn.Sequential(nn.Linear(latent, latent), nn.ReLU(), nn.Linear(latent, n_out), nn.Sigmoid())
