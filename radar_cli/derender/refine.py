"""Test-time albedo refinement: divide the predicted shading out of the texture the network saw.

f_A's albedo is smooth and does not reproduce its own input: on the bundled model's test vases the frontal texture
rebuilt from the prediction misses the unwrapped input by 26% of its radiance on average. Inverting Eq. 5 with the
predicted shape, lighting and material (`radar_cli.render.lighting.decompose`) gives an albedo that keeps the
photograph's painted detail and reconstructs it (up to the highlight cap, the [0, 1] clamp and resampling), at the
price of any shading the lighting failed to explain (README, Accuracy: albedo si-MSE 4.01 -> 2.33 x 1e-2 on the 460 test vases).
"""

from __future__ import annotations

import dataclasses
from typing import Literal

import torch

from radar_cli.config import CameraConfig, RenderConfig
from radar_cli.model.outputs import Decomposition
from radar_cli.render.lighting import decompose
from radar_cli.render.scene import shade
from radar_cli.render.texture import unwrap

AlbedoSource = Literal["network", "divided"]
ALBEDO_SOURCES: tuple[AlbedoSource, ...] = ("network", "divided")
MAX_SPECULAR_SHARE = 0.8
"""Cap on the share of a texel's radiance taken as highlight; chosen on 460 training vases among 0.5-1.0
(si-MSE x 1e-2: 0.5 2.65, 0.7 2.42, 0.8 2.40, 0.9 2.45, 1.0 2.84; f_A alone 3.77)."""


def divide_shading(image: torch.Tensor, dec: Decomposition, render: RenderConfig, camera: CameraConfig,
                   silhouette: torch.Tensor | None = None,
                   max_specular_share: float = MAX_SPECULAR_SHARE) -> Decomposition:
    """The prediction with its albedo replaced by the input's unwrapped texture divided by the predicted shading.

    Args:
        image: B x 3 x S x S tone-mapped input in [0, 1], the batch `dec` was predicted from (same device).
        dec: the network's Decomposition; its shape, pose, lighting and material are kept.
        render, camera: the model's settings (texture size, shading grid, gamma).
        silhouette: B x 1 x S x S object coverage in [0, 1] if known (all ones for an image without one): texels
            that unwrap from off the object (where the predicted outline overhangs the true one) would divide the
            backdrop, so they keep the network's albedo instead, blended by the coverage.

    Returns:
        Decomposition whose albedo is B x 3 x Ht x Wt linear in [0, 1].
    """
    stacked = image if silhouette is None else torch.cat([image, silhouette], dim=1)  # B x (3 or 4) x S x S
    unwrapped = unwrap(dec.radius, dec.height, dec.pose, stacked, (render.tex_height, render.tex_width), camera)
    shading = shade(dec.radius, dec.height, dec.pose, dec.albedo, dec.env, dec.alpha, dec.rho, render, camera)
    albedo = decompose(unwrapped[:, :3], shading.diffuse, shading.specular, dec.rho, render.gamma,
                       max_specular_share)
    if silhouette is not None:
        on_object = unwrapped[:, 3:]  # B x 1 x Ht x Wt
        albedo = on_object * albedo + (1 - on_object) * dec.albedo
    return dataclasses.replace(dec, albedo=albedo)
