"""The object at the output resolution: a batch-of-one Decomposition (the network's, or a refined one) and its
output-side crop -> the ObjectState every export is drawn from, its profile smooth and its albedo at that side."""

from __future__ import annotations

import dataclasses

import numpy as np
import torch
import torch.nn.functional as F

from radar_cli.derender.run.inputs import Prepared
from radar_cli.derender.run.predictor import AlbedoSource
from radar_cli.derender.run.state import ObjectState
from radar_cli.model.config import ModelConfig
from radar_cli.model.outputs import Decomposition
from radar_cli.render.material import Material
from radar_cli.render.scene import divide_shading, shade
from radar_cli.sor.resample import smooth_rows
from radar_cli.sor.solid import Solid

PROFILE_ROWS = 128
"""Rows of the exported profile away from the network's side (the meshes' rings; the renderer interpolates
linearly between rows, so 32 rows would show as kinks at 512 px)."""


def resize_front(albedo: torch.Tensor, side: int) -> torch.Tensor:
    """A frontal albedo (1 x 3 x Ht x Wt) at side x side: bilinear up, area down, in [0, 1]."""
    if albedo.shape[-2:] == (side, side):
        return albedo
    grow = side >= max(albedo.shape[-2:])
    out = F.interpolate(albedo, size=(side, side), mode="bilinear" if grow else "area",
                        **({"align_corners": False} if grow else {}))
    return out.clamp(0, 1)


def photo_tensors(prepared: Prepared) -> tuple[torch.Tensor, torch.Tensor | None]:
    """The output-side crop as (1 x 3 x N x N tone-mapped float in [0, 1], 1 x 1 x N x N coverage or None)."""
    image = torch.from_numpy(np.ascontiguousarray(prepared.photo_image)).permute(2, 0, 1)[None].float() / 255.0
    sil = prepared.photo_silhouette
    coverage = None if sil is None else torch.from_numpy(sil.astype(np.float32))[None, None]
    return image, coverage


@torch.no_grad()
def full_resolution_state(dec: Decomposition, prepared: Prepared, setup: ModelConfig,
                          albedo_source: AlbedoSource) -> ObjectState:
    """The state exported at the output side N = prepared.side.

    At the network's side (N = S) the Decomposition is exported as it is (its rows, its albedo: the network-only
    outputs). At any other side:
    - the profile is resampled to max(PROFILE_ROWS, L) rows (monotone cubic through the given rows; a profile
      that has that many already is kept);
    - the frontal albedo is N x N: `divided` unwraps the N x N crop and divides it by the shading of the
      Decomposition's shape, pose, lighting and material (render.scene.divide_shading, the shading grid as the
      model's, upsampled), with the Decomposition's albedo resized to N where the surface unwraps from off the
      silhouette; `network` resizes the Decomposition's albedo.

    Args:
        dec: batch of one, CPU (radius 1 x L, albedo 1 x 3 x Ht x Wt frontal, ...).
        prepared: the object's crops (photo_image N x N x 3, photo_silhouette N x N or None).
        setup: the model's settings.
        albedo_source: `divided` or `network`.

    Returns:
        ObjectState with albedo 1 x 3 x N x 3N (N x N frontal third) and radius 1 x max(128, L) when N != S.
    """
    side = prepared.side
    if side == setup.render.image_size:
        return ObjectState.from_decomposition(dec, setup.render, setup.camera)
    radius = smooth_rows(dec.radius.float(), max(PROFILE_ROWS, dec.radius.shape[1]))
    front = resize_front(dec.albedo.float().clamp(0, 1), side)  # 1 x 3 x N x N
    if albedo_source == "divided":
        render = dataclasses.replace(setup.render, tex_height=side, tex_width=side)
        height, pose, env = dec.height.float(), dec.pose.float(), dec.env.float()
        alpha, rho = dec.alpha.float(), dec.rho.float()
        shading = shade(Solid(radius, height, pose), Material(front, env, alpha, rho), render, setup.camera)
        image, coverage = photo_tensors(prepared)
        front = divide_shading(image, Solid(radius, height, pose), front, rho, shading, render, setup.camera, coverage)
    return ObjectState.from_decomposition(dataclasses.replace(dec, radius=radius, albedo=front), setup.render,
                                          setup.camera)
