"""The object at the output resolution: a batch-of-one Decomposition (the network's, or a refined one) and its
output-side crop -> the ObjectState every export is drawn from, its profile smooth and its albedo at that side."""

from __future__ import annotations

import dataclasses
import math

import cv2
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
from radar_cli.render.texture import front_third, full_from_front, sample_surface
from radar_cli.sor.resample import smooth_rows
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import FRONT_SPAN, surface_grid

SEEN_DEG = 75.0
"""The divided albedo takes the photo's own texels up to this angle either side of the view (the frontal third
is +- 60 deg); beyond, the map is mirrored about that angle (render.texture.full_from_front)."""
SEEN_FACING = (0.15, 0.3)
"""Beyond the frontal third a texel is the photo's where the surface faces the camera more squarely than the
second cosine, the frontal third's mirror image where less than the first (a ramp between): grazing texels stretch
the limb's few pixels, its reflections and the outline's errors over many."""
SEEN_EDGE = 0.01
"""... and where the photo's silhouette, shrunk by this share of the side, covers it at least four times this far
from an appendage cut off it: near the outline the solid drawn and the photographed one part, and the unwrap reads
the backdrop or a handle's root."""
SEEN_GLARE = (0.04, 0.12)
"""... and is not a reflection: a texel brighter than the frontal third's mirror image by white light (every
channel by at least 60 % of the largest channel's excess) of the first linear amount keeps less of the photo, none
by the second. A glaze reflects the studio most at the limbs; painted colour differs from its neighbour in hue."""

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
      silhouette, and keeps the photo's texels up to SEEN_DEG where they can be trusted (_divided_albedo);
      `network` resizes the Decomposition's albedo.

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
    dec = dataclasses.replace(dec, radius=radius, albedo=front)
    if albedo_source == "network":
        return ObjectState.from_decomposition(dec, setup.render, setup.camera)
    image, coverage = photo_tensors(prepared)
    albedo = _divided_albedo(image, coverage, prepared.appendages, dec, front, setup)
    return ObjectState.from_decomposition(dec, setup.render, setup.camera, albedo)


def _divided_albedo(image: torch.Tensor, coverage: torch.Tensor | None, appendages: np.ndarray | None,
                    dec: Decomposition, front: torch.Tensor, setup: ModelConfig) -> torch.Tensor:
    """The 360 deg divided albedo, 1 x 3 x N x 3N: the photo divided by the shading within SEEN_DEG of the view
    (the frontal third, N x N, and k columns more on each side: render.texture.full_from_front's wide map), where
    beyond the frontal third each texel is the photo's if it is seen squarely enough, well inside the silhouette
    and no glare (SEEN_FACING, SEEN_EDGE, SEEN_GLARE), else the frontal third's mirror image; round the rest
    (_around).

    Args:
        image: 1 x 3 x N x N tone-mapped crop; coverage: 1 x 1 x N x N silhouette or None; appendages: N x N
            bool, what the locator cut off the silhouette, or None.
        dec: the object (its profile at the export's rows); front: 1 x 3 x N x N its albedo at N, the fallback
            off the silhouette.
    """
    side = image.shape[-1]
    third = math.degrees(FRONT_SPAN)  # the frontal third's half-width, deg
    extra = round((SEEN_DEG - third) / (2 * third) * side)  # k
    span = FRONT_SPAN * (side + 2 * extra) / side
    render = dataclasses.replace(setup.render, tex_height=side, tex_width=side + 2 * extra)
    fallback = front_third(full_from_front(front), extra)
    material = Material(fallback, dec.env.float(), dec.alpha.float(), dec.rho.float())
    solid = Solid(dec.radius.float(), dec.height.float(), dec.pose.float())
    shading = shade(solid, material, render, setup.camera, span)
    grid = surface_grid(solid, side, side + 2 * extra, setup.camera, span)
    wide = divide_shading(image, solid, fallback, material.rho, shading, render, setup.camera, coverage, span=span,
                          grid=grid)
    if extra == 0:
        return full_from_front(wide)
    sides = full_from_front(wide[..., extra : extra + side])  # the frontal third mirrored round, 1 x 3 x N x 3N
    mirrored = front_third(sides, extra)
    facing = (grid.normals * grid.view).sum(-1)[:, None]  # 1 x 1 x N x N + 2k
    lo, hi = SEEN_FACING
    trust = ((facing - lo) / (hi - lo)).clamp(0.0, 1.0)
    if coverage is not None:
        margin = max(1, round(SEEN_EDGE * side))
        kernel = np.ones((3, 3), np.uint8)
        inner = cv2.erode((coverage[0, 0].numpy() > 0.5).astype(np.uint8), kernel, iterations=margin).astype(bool)
        if appendages is not None and appendages.any():
            inner &= ~cv2.dilate(appendages.astype(np.uint8), kernel, iterations=4 * margin).astype(bool)
        trust = trust * sample_surface(torch.from_numpy(inner.astype(np.float32))[None, None], grid, setup.camera)
    excess = wide - mirrored  # 1 x 3 x N x N + 2k
    white, top = excess.min(1, keepdim=True).values, excess.max(1, keepdim=True).values
    lo, hi = SEEN_GLARE
    glare = ((white - lo) / (hi - lo)).clamp(0.0, 1.0) * (white >= 0.6 * top)
    trust = trust * (1 - glare)
    trust[..., extra : extra + side] = 1.0  # the frontal third is the photo's, as it always was
    return _around(trust * wide + (1 - trust) * mirrored, sides)


def _around(wide: torch.Tensor, sides: torch.Tensor) -> torch.Tensor:
    """The 360 deg map (1 x 3 x Ht x 3 third) of a wide frontal map: the wide map in the middle; beyond it, its
    mirror image about its edge fading over as many columns as it adds to the frontal third into `sides` (the
    frontal third mirrored round, render.texture.full_from_front), which the sides and back show as they always
    have: the limb's texels (grazing, often a glaze's reflections) are not spread over them."""
    third = sides.shape[-1] // 3
    extra = (wide.shape[-1] - third) // 2
    mirror = full_from_front(wide, third)
    cols = torch.arange(3 * third, dtype=wide.dtype)
    beyond = torch.maximum((third - extra) - cols, cols - (2 * third + extra - 1)).clamp_min(0.0)  # columns past
    fade = (1 - beyond / extra).clamp(0.0, 1.0)
    return fade * mirror + (1 - fade) * sides
