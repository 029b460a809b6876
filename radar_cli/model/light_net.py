"""f_L: unwrapped texture + normals -> environment map, shininess and specular albedo (supplementary Table 6)."""

from __future__ import annotations

import torch
from torch import nn

from radar_cli.model.blocks import channels, conv_encoder, head, levels, norm_layer
from radar_cli.sor.profile import rescale


class LightNet(nn.Module):
    """GN encoder of the 6-channel (texture, normals) map; a 2-D upsampling-conv branch for the He x 3He
    environment map and two FC layers for shininess and specular albedo."""

    def __init__(self, tex_size: int, env_height: int, width: int, max_channels: int, latent: int,
                 shininess_range: tuple[float, float], spec_albedo_range: tuple[float, float],
                 env_range: tuple[float, float]):
        super().__init__()
        self.shininess_range, self.spec_albedo_range, self.env_range = shininess_range, spec_albedo_range, env_range
        self.encoder = light_encoder(tex_size, width, max_channels, latent)
        n_up = levels(env_height, 2)
        ch = channels(width, n_up, max_channels)
        layers: list[nn.Module] = [nn.ConvTranspose2d(latent, ch, (2, 6), 1, 0), nn.ReLU()]  # 2 x 6
        for i in range(n_up):
            out = channels(width, n_up - 1 - i, max_channels)
            layers += [nn.Upsample(scale_factor=2, mode="nearest"), nn.Conv2d(ch, out, 3, 1, 1),
                       norm_layer("group", out), nn.ReLU()]
            ch = out
        layers += [nn.Conv2d(ch, 1, 3, 1, 1), nn.Sigmoid()]
        self.env_decoder = nn.Sequential(*layers)
        self.material_head = head(latent, 2)

    def forward(self, texture: torch.Tensor, normals: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Args:
            texture: B x 3 x Ht x Wt unwrapped frontal texture (tone-mapped, [0, 1]).
            normals: B x 3 x Ht x Wt camera-space unit normals.

        Returns:
            env B x He x We, alpha B (shininess), rho B (specular albedo), rescaled to their ranges.
        """
        z = self.encoder(encoder_input(texture, normals))  # B x latent x 1 x 1
        env = rescale(self.env_decoder(z)[:, 0], *self.env_range)  # B x He x We
        s = self.material_head(z.flatten(1))
        return env, rescale(s[:, 0], *self.shininess_range), rescale(s[:, 1], *self.spec_albedo_range)


def light_encoder(tex_size: int, width: int, max_channels: int, latent: int) -> nn.Module:
    """f_L's GN encoder of the 6-channel (texture, normals) map (encoder_input) to a B x latent x 1 x 1 code."""
    return conv_encoder(6, tex_size, width, max_channels, latent, norm="group")


def encoder_input(texture: torch.Tensor, normals: torch.Tensor) -> torch.Tensor:
    """B x 6 x Ht x Wt: the texture ([0, 1]) moved to [-1, 1], then the camera-space normals."""
    return torch.cat([texture * 2 - 1, normals], dim=1)
