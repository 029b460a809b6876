"""The specular-albedo reader: f_L's encoder and a one-output material head, fine-tuned on `radar synth`'s ground
truth (radar's addition; `radar train-reader`, docs/refinement.md).

f_L, taught by the paper's self-supervised losses, reads the specular albedo no better than a constant guess;
the same encoder taught with the true specular albedo of synthetic vases reads it (the paper's supervised baseline
shows the same). The refinement uses the reader on the frontal texture unwrapped at the fitted shape, in place of
f_L's reading.
"""

from __future__ import annotations

import torch
from torch import nn

from radar_cli.model.blocks import head
from radar_cli.model.config import ModelConfig
from radar_cli.model.light_net import LightNet, encoder_input, light_encoder
from radar_cli.model.radar import frontal_inputs
from radar_cli.sor.solid import Solid

RANGE = (0.0, 1.0)  # a normalised Phong lobe with a specular albedo above 1 would send out more light than arrives


class SpecularReader(nn.Module):
    """Image and shape -> specular albedo.

    Args:
        config: the configuration of the model whose f_L it starts from: texture size, camera, f_L's widths.
    """

    def __init__(self, config: ModelConfig):
        super().__init__()
        self.config = config
        r = config.render
        self.encoder = light_encoder(min(r.tex_height, r.tex_width), config.light_width, config.max_channels,
                                     config.latent)
        self.head = head(config.latent, 1)

    @classmethod
    def from_light_net(cls, config: ModelConfig, light_net: LightNet) -> "SpecularReader":
        """A reader starting from f_L's encoder and its material head's specular-albedo output."""
        reader = cls(config)
        reader.encoder.load_state_dict(light_net.encoder.state_dict())
        source = light_net.material_head
        reader.head[0].load_state_dict(source[0].state_dict())
        out, source_out = reader.head[2], source[2]
        assert isinstance(out, nn.Linear) and isinstance(source_out, nn.Linear)
        with torch.no_grad():
            out.weight.copy_(source_out.weight[1:2])
            out.bias.copy_(source_out.bias[1:2])
        return reader

    def forward(self, image: torch.Tensor, solid: Solid) -> torch.Tensor:
        """Args:
            image: B x 3 x H x W in [0, 1]. solid: the B solids.

        Returns:
            B specular albedo in RANGE.
        """
        texture, normals = frontal_inputs(self.config, solid, image)
        z = self.encoder(encoder_input(texture, normals))  # B x latent x 1 x 1
        return RANGE[0] + (RANGE[1] - RANGE[0]) * self.head(z.flatten(1))[:, 0]
