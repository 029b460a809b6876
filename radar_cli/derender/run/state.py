"""One de-rendered object as everything downstream needs it: shape, pose, 360 deg albedo, lighting, material
and the renderer settings, built from the network's Decomposition or read back from a results folder."""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from radar_cli.config import CameraConfig, RenderConfig, from_dict, to_dict
from radar_cli.errors import InputError
from radar_cli.fileio import read_image, to_uint8
from radar_cli.model.outputs import Decomposition
from radar_cli.render.lighting import tone_map
from radar_cli.render.material import Material
from radar_cli.render.texture import full_from_front
from radar_cli.results import ALBEDO_FILE, ENV_MAP_FILE, MATERIAL_FILE
from radar_cli.sor.solid import Solid

EXPORT_SHADING_GRID = 32  # at most this many rows and columns (per frontal third) in whole-object renders' shading


def roughness_from_shininess(alpha: float) -> float:
    """PBR roughness matching a Phong exponent: sqrt(2 / (alpha + 2)) (Blinn-Phong / Beckmann equivalence)."""
    return math.sqrt(2.0 / (alpha + 2.0))


def quantise(albedo: torch.Tensor, gamma: float) -> torch.Tensor:
    """Round-trip a linear albedo through its 8-bit tone-mapped PNG, so renders match what relight reads."""
    png = to_uint8(tone_map(albedo, gamma).permute(0, 2, 3, 1).numpy())  # B x Ht x W x 3
    return linearise(png, gamma).permute(0, 3, 1, 2)


def linearise(png: np.ndarray, gamma: float) -> torch.Tensor:
    """uint8 tone-mapped image (... x 3) -> linear float tensor."""
    return torch.from_numpy(png.astype(np.float32) / 255.0) ** gamma


@dataclass(frozen=True)
class ObjectState:
    """One object, batch of one.

    Attributes:
        solid: the shape and pose (radius 1 x L; height 1; pose 1 x 4 pitch deg, roll deg, tx, ty).
        material: albedo 1 x 3 x Ht x 3Wt the linear 360 deg map (back mirrored from the front), 8-bit exact;
            env 1 x He x We linear, camera frame; alpha 1 shininess; rho 1 specular albedo.
        render: the renderer settings of whole-object renders; camera: the fixed camera.
    """

    solid: Solid
    material: Material
    render: RenderConfig
    camera: CameraConfig

    @staticmethod
    def export_render(render: RenderConfig) -> RenderConfig:
        """The renderer settings of whole-object renders: the model's, the shading grid at most
        EXPORT_SHADING_GRID."""
        return dataclasses.replace(render, shading_height=min(render.shading_height, EXPORT_SHADING_GRID),
                                   shading_width=min(render.shading_width, EXPORT_SHADING_GRID))

    @classmethod
    def from_decomposition(cls, dec: Decomposition, render: RenderConfig, camera: CameraConfig,
                           albedo: torch.Tensor | None = None) -> "ObjectState":
        """The state of a batch-of-one Decomposition: its frontal albedo mirrored to 360 deg, or `albedo` (a 360
        deg map, 1 x 3 x Ht x 3Wt linear) instead."""
        if dec.radius.shape[0] != 1:
            raise ValueError(f"expected a batch of one, got {dec.radius.shape[0]}")
        export_render = cls.export_render(render)
        whole = full_from_front(dec.albedo.float()) if albedo is None else albedo.float()
        material = dec.material.map(torch.Tensor.float).with_albedo(quantise(whole.clamp(0, 1), render.gamma))
        return cls(dec.solid.map(torch.Tensor.float), material, export_render, camera)

    def record(self) -> dict:
        """The material.json record of the shape, pose, material and renderer settings."""
        pitch, roll, tx, ty = (float(v) for v in self.solid.pose[0])
        alpha = float(self.material.alpha[0])
        return {"pitch": pitch, "roll": roll, "tx": tx, "ty": ty, "height": float(self.solid.height[0]),
                "radius": [float(r) for r in self.solid.radius[0]], "alpha": alpha,
                "rho": float(self.material.rho[0]),
                "roughness": roughness_from_shininess(alpha), "render": to_dict(self.render),
                "camera": to_dict(self.camera)}


def read_record(folder: str | Path) -> dict:
    """The material.json record of an object folder; InputError if it is missing or not JSON."""
    path = Path(folder) / MATERIAL_FILE
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{folder}: not a de-rendered object folder (no {MATERIAL_FILE})") from None
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: not readable JSON ({e})") from None
    if not isinstance(record, dict):
        raise InputError(f"{path}: expected a JSON object")
    return record


def read_state(folder: str | Path) -> ObjectState:
    """Read an object folder written by `radar derender` (material.json, albedo.png, env_map.npy)."""
    folder = Path(folder)
    record = read_record(folder)
    where = folder / MATERIAL_FILE
    try:
        render = from_dict(RenderConfig, record["render"], f"{where}:render")
        camera = from_dict(CameraConfig, record["camera"], f"{where}:camera")
        pose = torch.tensor([[record["pitch"], record["roll"], record["tx"], record["ty"]]], dtype=torch.float32)
        radius = torch.tensor([record["radius"]], dtype=torch.float32)
        height = torch.tensor([record["height"]], dtype=torch.float32)
        alpha = torch.tensor([record["alpha"]], dtype=torch.float32)
        rho = torch.tensor([record["rho"]], dtype=torch.float32)
    except (ValueError, KeyError, TypeError) as e:
        raise InputError(f"{where}: malformed ({type(e).__name__}: {e})") from None
    albedo = linearise(read_image(folder / ALBEDO_FILE, "RGB"), render.gamma).permute(2, 0, 1)[None]
    try:
        env = np.load(folder / ENV_MAP_FILE, allow_pickle=False).astype(np.float32)
    except (OSError, ValueError) as e:
        raise InputError(f"{folder / ENV_MAP_FILE}: not a readable environment map ({e})") from None
    if env.ndim != 2:
        raise InputError(f"{folder / ENV_MAP_FILE}: expected He x We, got shape {env.shape}")
    return ObjectState(Solid(radius, height, pose), Material(albedo, torch.from_numpy(env)[None], alpha, rho), render,
                       camera)
