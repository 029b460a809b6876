"""Inference state for de-rendering: the model, its configuration and device, and batched prediction under
torch.no_grad. The only place that knows how a checkpoint becomes a model."""

from __future__ import annotations

import dataclasses
import hashlib
from pathlib import Path
from typing import Callable, Literal, Sequence

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.driver import REFINE_MODES, RefineMode, RefineReport, refine_object
from radar_cli.derender.refine.fit_light import LightFitConfig
from radar_cli.derender.refine.pitch_search import search_pitch
from radar_cli.errors import CheckpointError, InputError
from radar_cli.model.config import ModelConfig
from radar_cli.model.outputs import Decomposition
from radar_cli.model.radar import RadarModel
from radar_cli.model.specular_reader import SpecularReader
from radar_cli.model.weights import load_model, load_specular_reader
from radar_cli.render.scene import divide_shading, shade

ASSETS = Path(__file__).resolve().parents[2] / "assets"
READER_ASSET = "readers/specular_albedo.safetensors"  # the bundled reader (pipelines/readers/specular_albedo.toml)
BUNDLED, NO_READER = "bundled", "none"  # --specular-reader's named values
AlbedoSource = Literal["network", "divided"]
ALBEDO_SOURCES: tuple[AlbedoSource, ...] = ("network", "divided")
PitchSource = Literal["network", "search"]
PITCH_SOURCES: tuple[PitchSource, ...] = ("network", "search")


def bundled_checkpoint() -> Path:
    """The default model shipped inside the package (the one .safetensors file in radar_cli/assets)."""
    found = sorted(ASSETS.glob("*.safetensors")) if ASSETS.is_dir() else []
    if not found:
        raise CheckpointError(f"{ASSETS}: no bundled model (*.safetensors) found; pass --checkpoint PATH")
    return found[0]


def reader_path(reader: str | Path) -> Path:
    """The file --specular-reader names: the bundled reader for `bundled`, else the path given."""
    return ASSETS / READER_ASSET if str(reader) == BUNDLED else Path(reader)


def load_reader(reader: str | Path, camera: CameraConfig, device: torch.device) -> SpecularReader | None:
    """The specular-albedo reader `reader` names (a file, `bundled`, or `none`: None), in eval mode on `device`;
    CheckpointError if it is unreadable or was trained for another camera than the model's."""
    if str(reader) == NO_READER:
        return None
    path = reader_path(reader)
    loaded = load_specular_reader(path, device)
    if loaded.config.camera != camera:
        raise CheckpointError(f"{path}: the reader was trained with another camera than the model's")
    return loaded


def resolve_device(name: str) -> torch.device:
    """`auto` picks CUDA when available; `cpu`, `cuda`, `cuda:N` are taken as given (checked)."""
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    try:
        device = torch.device(name)
    except RuntimeError:
        raise InputError(f"unknown device {name!r} (use auto, cpu or cuda)") from None
    if device.type == "cuda" and not torch.cuda.is_available():
        raise InputError(f"device {name!r} requested but CUDA is not available")
    return device


class Predictor:
    """Batches images through a de-rendering model on one device.

    Args:
        model: any callable image B x 3 x S x S in [0, 1] -> Decomposition (a RadarModel in practice).
        setup: the model's render, camera and geometry configuration.
        version: a label recorded in every material.json (checkpoint name and hash).
        device: where the model runs.
        albedo: `divided`: the input's texture divided by the predicted shading (render.scene.divide_shading;
            about 0.6x the albedo error of f_A's on synthetic vases, docs/accuracy.md); `network`: f_A's
            albedo, as the paper.
        pitch: `network`: f_S's pitch; `search`: derender.refine.pitch_search where the silhouette is known (needs a
            RadarModel), f_S's elsewhere.
        refine: `full`: each object's shape and pose fitted at the output resolution, f_L and f_A re-read
            there, and the environment map fitted to the crop's shading (derender.refine.driver; needs a RadarModel);
            `shape`: the same without the lighting fit; `none`: the network's prediction as it is.
        reader: reads the specular albedo at the refined shape (model.specular_reader; None: f_L's re-reading).
    """

    def __init__(self, model: Callable[[torch.Tensor], Decomposition], setup: ModelConfig, version: str,
                 device: torch.device | str = "cpu", albedo: AlbedoSource = "divided",
                 pitch: PitchSource = "network", refine: RefineMode = "none", reader: SpecularReader | None = None):
        if albedo not in ALBEDO_SOURCES:
            raise InputError(f"unknown albedo source {albedo!r} (use {' or '.join(ALBEDO_SOURCES)})")
        if pitch not in PITCH_SOURCES:
            raise InputError(f"unknown pitch source {pitch!r} (use {' or '.join(PITCH_SOURCES)})")
        if refine not in REFINE_MODES:
            raise InputError(f"unknown refinement {refine!r} (use {' or '.join(REFINE_MODES)})")
        if (pitch == "search" or refine != "none") and not isinstance(model, RadarModel):
            raise InputError("the pitch search and the refinement need a RadarModel (a checkpoint), not another "
                             "callable")
        self.model = model
        self.setup = setup
        self.version = version
        self.device = torch.device(device)
        self.albedo = albedo
        self.pitch = pitch
        self.refine = refine
        self.reader = reader

    @classmethod
    def from_checkpoint(cls, path: str | Path | None = None, device: str = "auto",
                        albedo: AlbedoSource = "divided", pitch: PitchSource = "network",
                        refine: RefineMode = "none", reader: str | Path = BUNDLED) -> "Predictor":
        """Load a checkpoint (default: the bundled model) and, when refining, a specular-albedo reader (`reader`:
        a file, `bundled`, or `none` for f_L's reading); CheckpointError if either is missing or does not fit."""
        path = Path(path) if path is not None else bundled_checkpoint()
        if not path.is_file():
            raise CheckpointError(f"{path}: no such checkpoint")
        dev = resolve_device(device)
        model, _ = load_model(path, dev)
        model.eval()
        cfg = model.config
        specular = None if refine == "none" else load_reader(reader, cfg.camera, dev)
        version = f"{path.name}#{_short_hash(path)}"
        if specular is not None:
            read_from = reader_path(reader)
            version += f" + {read_from.name}#{_short_hash(read_from)}"
        return cls(model, cfg, version, dev, albedo, pitch, refine, specular)

    @torch.no_grad()
    def predict(self, images: Sequence[np.ndarray],
                silhouettes: Sequence[np.ndarray | None] | None = None) -> Decomposition:
        """De-render a batch of crops, each on its own.

        The network runs on one image at a time: a convolution's sums are taken in another order for another
        batch size, so a batched prediction would depend on the photos beside it (its batch size, worker count,
        shard, or where a killed run resumed); one at a time, a photo always gives the same numbers.

        Args:
            images: S x S x 3 uint8 RGB crops, S = setup.render.image_size.
            silhouettes: per crop, its S x S bool object mask or None; the divided albedo keeps the network's
                where the predicted surface unwraps from off the object, and the pitch search runs where it is
                known.

        Returns:
            Decomposition of the batch, on the CPU, detached.
        """
        size = self.setup.render.image_size
        for im in images:
            if im.shape != (size, size, 3) or im.dtype != np.uint8:
                raise InputError(f"expected {size} x {size} x 3 uint8 crops, got {im.shape} {im.dtype}")
        masks: list[np.ndarray | None] = [None] * len(images) if silhouettes is None else list(silhouettes)
        if len(masks) != len(images):
            raise InputError(f"expected {len(images)} silhouettes, got {len(masks)}")
        coverage = None if silhouettes is None else _coverage(masks, size)  # checks them all before any work
        return Decomposition.concat([self._predict_one(im, mask, None if coverage is None else coverage[k : k + 1])
                                     for k, (im, mask) in enumerate(zip(images, masks))])

    def _predict_one(self, image: np.ndarray, silhouette: np.ndarray | None,
                     coverage: torch.Tensor | None) -> Decomposition:
        """One S x S x 3 uint8 crop (its 1 x 1 x S x S coverage, or None) de-rendered: a batch of one, on the
        CPU."""
        batch = torch.from_numpy(np.array(image)).permute(2, 0, 1)[None].to(self.device, torch.float32) / 255.0
        dec = self.model(batch)
        if self.pitch == "search" and silhouette is not None:
            assert isinstance(self.model, RadarModel)  # __init__ refuses the search without one
            dec = search_pitch(self.model, batch, [silhouette], dec)
        if self.albedo == "divided":
            render, camera = self.setup.render, self.setup.camera
            shading = shade(dec.solid, dec.material, render, camera)
            albedo = divide_shading(batch, dec.solid, dec.albedo, dec.rho, shading, render,
                                    camera, None if coverage is None else coverage.to(self.device))
            dec = dataclasses.replace(dec, albedo=albedo)
        return dec.detach().to("cpu")

    def refine_object(self, dec: Decomposition, image: np.ndarray, crop: np.ndarray,
                      silhouette: np.ndarray | None) -> tuple[Decomposition, RefineReport]:
        """One object's prediction refined at the output resolution (derender.refine.driver), or kept.

        Args:
            dec: its Decomposition (batch of one, CPU). image: the S x S x 3 uint8 network input.
            crop: N x N x 3 uint8 at the output side; silhouette: N x N bool, or None.

        Returns:
            (the Decomposition to export, what the refinement did).
        """
        if self.refine == "none":
            return dec, RefineReport("off", "--refine none", crop.shape[0])
        if crop.shape[0] <= self.setup.render.image_size:
            return dec, RefineReport("off", "the output is at the network's size", crop.shape[0])
        batch = torch.from_numpy(image).permute(2, 0, 1)[None].to(self.device, torch.float32) / 255.0
        light = LightFitConfig() if self.refine == "full" else None
        # the fits run on the CPU (float64 outlines, small steps); only the networks' re-reading runs on the device
        refined, report = refine_object(self.model, batch, dec, crop, silhouette, self.setup.camera, light=light,
                                        reader=self.reader)
        return (dec if refined is None else refined.to("cpu")), report


def _coverage(silhouettes: Sequence[np.ndarray | None], size: int) -> torch.Tensor:
    """B x 1 x S x S float object coverage: each S x S mask, or all ones where none is known."""
    masks = [np.ones((size, size), bool) if m is None else m for m in silhouettes]
    for m in masks:
        if m.shape != (size, size):
            raise InputError(f"expected {size} x {size} silhouettes, got {m.shape}")
    return torch.from_numpy(np.stack(masks).astype(np.float32))[:, None]


def _short_hash(path: Path) -> str:
    """First 12 hex digits of the file's SHA-256."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()[:12]
