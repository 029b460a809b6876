"""Image-space renders of one object: silhouettes, reconstruction, albedo and normals in the input view, the
material on a sphere, a turntable (GIF + PNG strip) and relit views."""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from PIL import Image

from radar_cli.config import CameraConfig
from radar_cli.derender.export.environments import match_exposure
from radar_cli.derender.export.maps import FAST_ENCODE_PIXELS, chw_image, write_picture
from radar_cli.derender.export.palette import quantize
from radar_cli.derender.run.state import ObjectState
from radar_cli.fileio import atomic_path, to_uint8
from radar_cli.render.lighting import compose, tone_map
from radar_cli.render.material import Material
from radar_cli.render.raycast import Hits, cast_rays
from radar_cli.render.scene import Shading, render_front, rotate_full_map, shade
from radar_cli.render.texture import render_texture
from radar_cli.results import (
    ALBEDO_RENDERED_FILE,
    DIFFUSE_RENDERED_FILE,
    MASK_FILE,
    MASK_FRONT_FILE,
    MATERIAL_SPHERE_FILE,
    NORMAL_RENDERED_FILE,
    RECON_FILE,
    RELIT_PREFIX,
    SPECULAR_RENDERED_FILE,
    TURNTABLE_GIF_FILE,
    TURNTABLE_STRIP_FILE,
)
from radar_cli.sor.solid import Solid
from radar_cli.sor.surface import FULL_SPAN

SPHERE_ROWS = 64
SPHERE_RADIUS = 0.8  # fraction of r_max
SPHERE_MIN_RADIUS = 0.02  # the poles are kept open a hair so the profile stays a valid SoR
TURNTABLE_FRAME_MS = 120


class ViewRenderer:
    """Draws one object from one camera pose, many times.

    The solid is symmetric about its axis, so spinning it (yaw) only moves the albedo over a fixed surface: the
    rays are cast once, and the lighting is shaded once per environment. Each image equals
    radar_cli.render.scene.render_view with the same arguments.

    Args:
        state: the object.
        size: image side in pixels.
        pitch_deg: replaces the predicted pitch if given.
        hits: the ray-casting result for this shape, pose and size, if already known.
    """

    def __init__(self, state: ObjectState, size: int, pitch_deg: float | None = None, hits: Hits | None = None):
        self.state = state
        pose = state.solid.pose.clone()
        if pitch_deg is not None:
            pose[:, 0] = pitch_deg
        self.solid = Solid(state.solid.radius, state.solid.height, pose)
        if hits is None:
            with torch.no_grad():
                hits = cast_rays(self.solid, size, state.camera,
                                 state.render.sil_sigma_px)
        self.hits = hits

    @torch.no_grad()
    def shading(self, env: torch.Tensor | None = None) -> Shading:
        """The 360 deg lighting factors under `env` (1 x He x We; default: the predicted one)."""
        s = self.state
        material = s.material if env is None else Material(s.material.albedo, env, s.material.alpha, s.material.rho)
        return shade(self.solid, material, s.render, s.camera, span=FULL_SPAN)

    @torch.no_grad()
    def draw(self, shading: Shading, yaw_deg: float = 0.0, background: float = 1.0) -> np.ndarray:
        """The shaded object spun by `yaw_deg`: size x size x 3 uint8 over a grey level `background` (unspun, the
        texture is the one `shading` holds)."""
        s = self.state
        if yaw_deg % 360.0 == 0.0:
            texture = shading.texture
        else:
            texture = compose(rotate_full_map(s.material.albedo, yaw_deg), shading.diffuse, shading.specular,
                              s.material.rho, s.render.gamma)
        image, _ = render_texture(self.hits, texture, front_only=False, inside_dim=s.render.inside_dim,
                                  background=background)
        return chw_image(image)


def render_object(state: ObjectState, size: int, yaw_deg: float = 0.0, pitch_deg: float | None = None,
                  env: torch.Tensor | None = None, background: float = 1.0) -> np.ndarray:
    """The whole shaded object from a new view (spun by yaw, optionally another pitch) and lighting.

    Returns:
        size x size x 3 uint8 over a grey level `background`.
    """
    view = ViewRenderer(state, size, pitch_deg)
    return view.draw(view.shading(env), yaw_deg, background)


@dataclass(frozen=True)
class InputDrawing:
    """The object drawn in the input view, what the quality checks compare with the photo (all S x S).

    Attributes:
        solid: bool, the solid's hard silhouette. mouth: bool, where its inside shows through the mouth.
        recon: uint8 x 3, the reconstruction over white. highlight: uint8, the drawn highlight alone
            (specular_rendered.png).
    """

    solid: np.ndarray
    mouth: np.ndarray
    recon: np.ndarray
    highlight: np.ndarray


@torch.no_grad()
def input_drawing(view: ViewRenderer, shading: Shading, recon: np.ndarray) -> InputDrawing:
    """The InputDrawing of a view drawn under `shading` as `recon`."""
    s, hits = view.state, view.hits
    highlight = _on_object(hits, tone_map(s.material.rho[:, None, None, None] * shading.specular, s.render.gamma))
    return InputDrawing(hits.mask[0].numpy(), hits.inner[0].numpy(), recon, highlight)


@torch.no_grad()
def write_input_view(folder: Path, state: ObjectState, size: int) -> tuple[ViewRenderer, Shading, InputDrawing]:
    """mask.png, mask_front.png, albedo_rendered.png, normal_rendered.png, recon.png, diffuse_rendered.png and
    specular_rendered.png at the input's size.

    Returns:
        (the input view's renderer: its rays serve other views of the same size and pose; its shading under the
        object's own lighting; what it draws)."""
    view = ViewRenderer(state, size)
    hits = view.hits
    coverage = torch.where(hits.mask, torch.ones_like(hits.sil), hits.sil)  # 1 x S x S
    write_picture(folder / MASK_FILE, to_uint8(coverage[0].numpy()))
    albedo = state.material.albedo
    _, front = render_front(hits, torch.ones_like(albedo[:, :1, :, : albedo.shape[-1] // 3]))
    write_picture(folder / MASK_FRONT_FILE, to_uint8(front[0, 0].numpy()))
    # drawn as radar synth draws its ground truth (black off the hard silhouette), so radar eval compares like
    # with like at the outline
    write_picture(folder / ALBEDO_RENDERED_FILE, _on_object(hits, tone_map(state.material.albedo, state.render.gamma)))
    normals = torch.where(hits.mask[..., None], (hits.normal + 1) / 2, torch.zeros_like(hits.normal))
    write_picture(folder / NORMAL_RENDERED_FILE, to_uint8(normals[0].numpy()))
    shading = view.shading()
    recon = view.draw(shading)
    write_picture(folder / RECON_FILE, recon)
    write_picture(folder / DIFFUSE_RENDERED_FILE, _on_object(hits, tone_map(shading.diffuse, state.render.gamma)))
    drawing = input_drawing(view, shading, recon)
    write_picture(folder / SPECULAR_RENDERED_FILE, drawing.highlight)
    return view, shading, drawing


def _on_object(hits: Hits, texture: torch.Tensor) -> np.ndarray:
    """A 360 deg map (1 x C x Ht x 3Wt in [0, 1]) drawn undimmed in the view, black off the hard silhouette:
    S x S (x C) uint8."""
    image, _ = render_texture(hits, texture, inside_dim=1.0, background=0.0)
    return chw_image(image * hits.mask[:, None])


def sphere_profile() -> tuple[torch.Tensor, torch.Tensor]:
    """A sphere as a SoR: radius column sqrt(1 - y^2) (1 x L) and half-height (1), fractions of r_max."""
    y = torch.linspace(1.0, -1.0, SPHERE_ROWS)
    radius = (SPHERE_RADIUS * torch.sqrt(1 - y**2)).clamp_min(SPHERE_MIN_RADIUS)[None]
    return radius, torch.tensor([SPHERE_RADIUS])


@functools.lru_cache(maxsize=4)
def _sphere_hits(size: int, camera: CameraConfig, sigma_px: float) -> Hits:
    """The sphere's ray casting is the same for every object: done once per size."""
    radius, height = sphere_profile()
    with torch.no_grad():
        return cast_rays(Solid(radius, height, torch.zeros(1, 4)), size, camera, sigma_px)


def material_sphere(state: ObjectState, size: int) -> np.ndarray:
    """The recovered material and lighting on a sphere with the object's mean albedo, seen straight on."""
    radius, height = sphere_profile()
    mean = state.material.albedo.mean(dim=(2, 3), keepdim=True)  # 1 x 3 x 1 x 1
    sphere = dataclasses.replace(state, solid=Solid(radius, height, torch.zeros(1, 4)),
                                 material=state.material.with_albedo(mean.expand(-1, -1, 16, 48).contiguous()))
    view = ViewRenderer(sphere, size, hits=_sphere_hits(size, state.camera, state.render.sil_sigma_px))
    return view.draw(view.shading())


def gif_frames(views: list[np.ndarray]) -> list[Image.Image]:
    """GIF frames of H x W x 3 uint8 views: large ones (FAST_ENCODE_PIXELS) share one palette, a median cut of a
    sample of all of them, each pixel drawn by its nearest entry (export.palette: cheaper and truer than Pillow's
    per-frame palettes and than its median cut of every pixel, docs/resolution.md); smaller ones are left to
    Pillow's per-frame palettes."""
    if views[0].shape[0] * views[0].shape[1] < FAST_ENCODE_PIXELS:
        return [Image.fromarray(v) for v in views]
    indices, palette = quantize(views)
    frames = []
    for index in indices:
        frame = Image.frombytes("P", (index.shape[1], index.shape[0]), np.ascontiguousarray(index).tobytes())
        frame.putpalette(palette.tobytes())
        frames.append(frame)
    return frames


def write_turntable(folder: Path, view: ViewRenderer, frames: int, shading: Shading | None = None,
                    first: np.ndarray | None = None) -> None:
    """turntable.gif (looping) and turntable.png (the frames side by side): `frames` equal yaw steps.

    Args:
        shading: the view's shading under the object's own lighting, if already known.
        first: the unspun frame, if already drawn."""
    shading = view.shading() if shading is None else shading
    views = [first if k == 0 and first is not None else view.draw(shading, yaw_deg=360.0 * k / frames)
             for k in range(frames)]
    write_picture(folder / TURNTABLE_STRIP_FILE, np.concatenate(views, axis=1))
    images = gif_frames(views)
    with atomic_path(folder / TURNTABLE_GIF_FILE) as tmp:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], duration=TURNTABLE_FRAME_MS,
                       loop=0)


def texture_for_size(state: ObjectState, size: int) -> ObjectState:
    """The object with its albedo averaged down to about one texel per pixel of a size x size view (the full
    map is 3x wider): small views then shade and sample a texture of their own scale."""
    rows = state.material.albedo.shape[2]
    if rows <= size:
        return state
    albedo = F.interpolate(state.material.albedo, size=(size, 3 * size), mode="area")  # 1 x 3 x S x 3S
    return dataclasses.replace(state, material=state.material.with_albedo(albedo))


def relit_file(name: str) -> str:
    """File name of the view relit under environment `name`."""
    return f"{RELIT_PREFIX}{name}.png"


def write_relit(folder: Path, view: ViewRenderer, envs: dict[str, np.ndarray]) -> None:
    """relit_<name>.png for every environment (He x We maps, camera frame), from the input's view, each at the
    exposure of the object's own lighting."""
    own = view.state.material.env[0].numpy()
    for name, env in envs.items():
        shading = view.shading(torch.from_numpy(match_exposure(np.asarray(env, np.float32), own))[None])
        write_picture(folder / relit_file(name), view.draw(shading))


def write_renders(folder: Path, state: ObjectState, input_size: int, view_size: int, frames: int,
                  envs: dict[str, np.ndarray]) -> InputDrawing:
    """Every render of one object; the turntable and relit views reuse the input view's rays at its size.

    Returns:
        What the input view draws, for the quality checks."""
    input_view, shading, drawing = write_input_view(folder, state, input_size)
    recon = drawing.recon
    write_picture(folder / MATERIAL_SPHERE_FILE, material_sphere(state, view_size))
    view_state = texture_for_size(state, view_size)
    known: tuple[Shading | None, np.ndarray | None]
    if view_size == input_size and view_state is state:  # the input view itself: its shading and recon serve
        view, known = input_view, (shading, recon)
    else:
        view = ViewRenderer(view_state, view_size, hits=input_view.hits if view_size == input_size else None)
        known = (None, None)
    if frames > 0:
        write_turntable(folder, view, frames, *known)
    write_relit(folder, view, envs)
    return drawing
