"""RadarModel: image -> Decomposition, chaining f_S, texture unwrapping, normals, f_L and f_A (paper Fig. 2).

The discriminator is not part of the model: it only exists during training (radar_cli.train).
"""

from __future__ import annotations

import torch
from torch import nn

from radar_cli.checks import check_shape
from radar_cli.model.albedo_net import AlbedoNet
from radar_cli.model.config import ModelConfig
from radar_cli.model.light_net import LightNet
from radar_cli.model.outputs import Decomposition
from radar_cli.model.shape_net import ShapeNet
from radar_cli.render.texture import unwrap
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import surface_grid


class RadarModel(nn.Module):
    """The de-rendering function Phi of the paper: its three networks and the fixed geometry between them."""

    def __init__(self, config: ModelConfig):
        super().__init__()
        config.validate()
        self.config = config
        r = config.render
        self.shape_net = ShapeNet(r.image_size, config.geometry, config.shape_width, config.max_channels,
                                  config.latent)
        self.light_net = LightNet(min(r.tex_height, r.tex_width), r.env_height, config.light_width,
                                  config.max_channels, config.latent, config.shininess_range,
                                  config.spec_albedo_range, config.env_range)
        self.albedo_net = AlbedoNet(config.albedo_depth, config.albedo_width, config.max_channels)

    def unwrap_inputs(self, solid: Solid, image: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """The inputs of f_A and f_L (frontal_inputs at this model's sizes and camera)."""
        return frontal_inputs(self.config, solid, image)

    def forward(self, image: torch.Tensor) -> Decomposition:
        """De-render a batch.

        Args:
            image: B x 3 x H x W tone-mapped RGB in [0, 1], H = W = config.render.image_size.

        Returns:
            Decomposition in physical units.
        """
        size = self.config.render.image_size
        check_shape(image, f"B 3 {size} {size}", "image")
        return self.read_appearance(image, Solid(*self.shape_net(image)))

    def read_appearance(self, image: torch.Tensor, solid: Solid) -> Decomposition:
        """f_L and f_A on the texture unwrapped from `image` with the given shape and pose (f_S's, or another
        pose under test, derender.refine.pitch_search).

        Args:
            image: B x 3 x H x W. solid: the B solids.
        """
        seen = solid.map(torch.Tensor.detach) if self.config.detach_shape_for_texture else solid
        texture, normals = self.unwrap_inputs(seen, image)
        env, alpha, rho = self.light_net(texture, normals)
        albedo = self.albedo_net(texture)
        return Decomposition(solid.radius, solid.height, solid.pose, albedo, env, alpha, rho)


def frontal_inputs(config: ModelConfig, solid: Solid, image: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The frontal texture unwrapped from `image` with the given shape and pose, and its normals, at the texture
    size and camera of `config`.

    Args:
        image: B x 3 x H x W. solid: the B solids.

    Returns:
        texture B x 3 x Ht x Wt (as the image, tone-mapped), normals B x 3 x Ht x Wt (camera space).
    """
    size = (config.render.tex_height, config.render.tex_width)
    texture = unwrap(solid, image, size, config.camera)
    grid = surface_grid(solid, size[0], size[1], config.camera)
    return texture, grid.normals.permute(0, 3, 1, 2)  # B x 3 x Ht x Wt
