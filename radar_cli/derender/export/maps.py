"""Unwrapped maps of one object: 360 deg albedo, shaded texture, normals, diffuse and specular shading, and the
environment map as float .npy, an HDR file and a preview PNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from radar_cli.derender.run.state import ObjectState
from radar_cli.fileio import atomic_path, encode_png_fast, to_uint8, write_bytes, write_image, write_npy
from radar_cli.render.lighting import tone_map
from radar_cli.render.scene import shade
from radar_cli.render.texture import front_third
from radar_cli.results import (
    DIFFUSE_FILE,
    ENV_HDR_FILE,
    ENV_MAP_FILE,
    ENV_PREVIEW_FILE,
    NORMAL_FILE,
    SPECULAR_FILE,
    TEXTURE_FILE,
)

ENV_PREVIEW_SCALE = 8  # the He x We map is tiny; the preview is enlarged (nearest) so texels stay visible
FAST_ENCODE_PIXELS = 512 * 512
"""Images of at least this many pixels are encoded for speed (fileio.encode_png_fast: zlib level 1, files a few %
larger, pixels identical; docs/resolution.md); smaller ones, every file of a network-size export included, keep
Pillow's encoding."""


def write_picture(path: Path, image: np.ndarray) -> None:
    """Write an H x W (x 3) uint8 export image atomically, the large ones through the fast PNG encoder."""
    if image.shape[0] * image.shape[1] >= FAST_ENCODE_PIXELS and path.suffix.lower() == ".png":
        write_bytes(path, encode_png_fast(image))
    else:
        write_image(path, image)


def chw_image(x: torch.Tensor) -> np.ndarray:
    """1 x C x H x W (or C x H x W) float in [0, 1] -> H x W x C uint8 (H x W if C = 1)."""
    x = x[0] if x.dim() == 4 else x
    image = to_uint8(x.permute(1, 2, 0).numpy())
    return image[..., 0] if image.shape[-1] == 1 else image


def env_preview(env: np.ndarray, gamma: float) -> np.ndarray:
    """He x We linear map -> enlarged tone-mapped grey preview (uint8), normalised by its maximum."""
    peak = max(float(env.max()), 1e-8)
    grey = to_uint8((np.clip(env / peak, 0, 1)) ** (1.0 / gamma))
    return np.repeat(np.repeat(grey, ENV_PREVIEW_SCALE, 0), ENV_PREVIEW_SCALE, 1)


def write_env(folder: Path, env: np.ndarray, gamma: float) -> None:
    """env_map.npy (float32 He x We), env_map.hdr (Radiance RGBE, grey in 3 channels) and env_map.png."""
    import cv2

    write_npy(folder / ENV_MAP_FILE, env.astype(np.float32))
    with atomic_path(folder / ENV_HDR_FILE) as tmp:
        if not cv2.imwrite(str(tmp), np.repeat(env[..., None], 3, axis=2).astype(np.float32)):
            raise OSError(f"{folder / ENV_HDR_FILE}: OpenCV could not write the HDR file")
    write_picture(folder / ENV_PREVIEW_FILE, env_preview(env, gamma))


def write_maps(folder: Path, state: ObjectState, tex_render) -> None:
    """Write the unwrapped maps of one object, but for the albedo: ALBEDO_FILE is the meshes' texture, written
    with them (export.mesh.write_meshes).

    Args:
        folder: the object's results folder.
        state: the object.
        tex_render: RenderConfig of the network (its shading grid is used for the frontal maps).
    """
    gamma = state.render.gamma
    front = front_third(state.material.albedo)  # 1 x 3 x Ht x Wt
    s = shade(state.solid, state.material.with_albedo(front), tex_render,
              state.camera)
    write_picture(folder / TEXTURE_FILE, chw_image(s.texture))
    write_picture(folder / NORMAL_FILE, chw_image((s.normals + 1) / 2))
    write_picture(folder / DIFFUSE_FILE, chw_image(tone_map(s.diffuse, gamma)))
    specular = state.material.rho[:, None, None, None] * s.specular
    write_picture(folder / SPECULAR_FILE, chw_image(tone_map(specular, gamma)))
    write_env(folder, state.material.env[0].numpy(), gamma)
