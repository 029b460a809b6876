"""f_S: image -> radius column, half-height and pose (paper Sec. 3.1, supplementary Table 5)."""

from __future__ import annotations

import torch
from torch import nn

from radar_cli.config import GeometryConfig
from radar_cli.model.blocks import conv_encoder, head, levels
from radar_cli.sor.profile import rescale


class ShapeNet(nn.Module):
    """Encoder to a latent vector; a 1-D upsampling-conv branch for the radius column (its convolutions make
    the curve smooth) and two FC layers for height and pose; sigmoids rescaled to the geometry's ranges."""

    def __init__(self, image_size: int, geometry: GeometryConfig, width: int, max_channels: int, latent: int):
        super().__init__()
        self.geometry = geometry
        self.encoder = conv_encoder(3, image_size, width, max_channels, latent, norm="none")
        n_up = levels(geometry.n_rows, 1)
        layers: list[nn.Module] = []
        for i in range(n_up):
            last = i == n_up - 1
            layers += [nn.Upsample(scale_factor=2, mode="nearest"),
                       nn.Conv1d(latent, 1 if last else latent, 3, 1, 1)]
            layers.append(nn.Sigmoid() if last else nn.ReLU())
        self.radius_decoder = nn.Sequential(*layers)
        self.pose_head = head(latent, 5)

    def forward(self, image: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Args: image B x 3 x H x W in [0, 1].

        Returns:
            radius B x L (fractions of r_max), height B, pose B x 4 (pitch deg, roll deg, tx, ty).
        """
        g = self.geometry
        z = self.encoder(image * 2 - 1).flatten(1)  # B x latent
        radius = rescale(self.radius_decoder(z[..., None])[:, 0], *g.radius_range)  # B x L
        s = self.pose_head(z)  # B x 5 in [0, 1]
        height = rescale(s[:, 0], *g.height_range)
        pose = torch.stack([rescale(s[:, 1], *g.pitch_range), rescale(s[:, 2], *g.roll_range),
                            rescale(s[:, 3], *g.trans_range), rescale(s[:, 4], *g.trans_range)], dim=1)
        return radius, height, pose
