"""Reading model weights: RADAR checkpoints and exported models, and the specular-albedo reader, from safetensors
files whose metadata names their format and holds the config they were trained with. Loading never unpickles
anything; a corrupt file or one that does not fit its configuration raises CheckpointError.
"""

from __future__ import annotations

import json
from pathlib import Path

import torch
from safetensors import SafetensorError, safe_open
from safetensors.torch import load_file
from torch import nn

from radar_cli.config import from_dict
from radar_cli.errors import CheckpointError, ConfigError
from radar_cli.model.config import ModelConfig, RunConfig, run_config_from_dict
from radar_cli.model.radar import RadarModel
from radar_cli.model.specular_reader import SpecularReader

FORMAT = "radar-checkpoint-1"
READER_FORMAT = "radar-specular-reader-1"  # a SpecularReader's weights, its ModelConfig and training record


def module_tensors(module: nn.Module, prefix: str) -> dict[str, torch.Tensor]:
    return {f"{prefix}.{k}": v.detach().cpu().contiguous() for k, v in module.state_dict().items()}


def load_module(module: nn.Module, tensors: dict[str, torch.Tensor], prefix: str, path: Path) -> None:
    sub = {k[len(prefix) + 1 :]: v for k, v in tensors.items() if k.startswith(prefix + ".")}
    try:
        module.load_state_dict(sub, strict=True)
    except RuntimeError as e:
        first = str(e).strip().splitlines()
        message = " ".join(first)[:300]
        raise CheckpointError(f"{path}: {prefix} weights do not fit the configuration ({message})") from None


def read_checkpoint(path: str | Path) -> tuple[dict[str, torch.Tensor], dict[str, str], RunConfig]:
    """Tensors, metadata and config of a checkpoint or exported weights file, validated.

    Raises:
        CheckpointError: missing, truncated or corrupt file, foreign format, or an invalid stored config.
    """
    tensors, meta = read_weights(path, FORMAT)
    try:
        config = run_config_from_dict(json.loads(meta["config"]))
    except (KeyError, ValueError, ConfigError) as e:
        raise CheckpointError(f"{path}: stored config is invalid ({e})") from None
    return tensors, meta, config


def read_weights(path: str | Path, expected_format: str,
                 kind: str = "radar checkpoint") -> tuple[dict[str, torch.Tensor], dict[str, str]]:
    """Tensors and metadata of a safetensors file whose metadata names `expected_format` (never unpickles);
    `kind` names such a file in errors.

    Raises:
        CheckpointError: missing, truncated or corrupt file, or another format.
    """
    path = Path(path)
    if not path.is_file():
        raise CheckpointError(f"{path}: no such checkpoint")
    try:
        with safe_open(str(path), framework="pt") as f:
            meta = f.metadata() or {}
        tensors = load_file(str(path))
    except (SafetensorError, OSError, ValueError, RuntimeError) as e:
        raise CheckpointError(f"{path}: corrupt or not a safetensors checkpoint ({e})") from None
    if meta.get("format") != expected_format:
        raise CheckpointError(f"{path}: not a {kind} (format {meta.get('format')!r}, expected {expected_format})")
    return tensors, meta


def load_model(path: str | Path, device: str | torch.device = "cpu") -> tuple[RadarModel, RunConfig]:
    """A RadarModel in eval mode from a checkpoint or exported weights file, with the config it was trained with.

    Raises:
        CheckpointError: corrupt file or weights that do not fit the stored config.
    """
    tensors, _, config = read_checkpoint(path)
    model = RadarModel(config.model)
    load_module(model, tensors, "model", Path(path))
    return model.to(device).eval(), config


def read_specular_reader(path: str | Path) -> tuple[SpecularReader, dict[str, torch.Tensor], dict[str, str]]:
    """A SpecularReader (train mode, CPU) from its file, with the file's tensors and metadata.

    Raises:
        CheckpointError: missing or corrupt file, another format, or weights that do not fit the stored config.
    """
    tensors, meta = read_weights(path, READER_FORMAT, "radar specular-albedo reader")
    try:
        config = from_dict(ModelConfig, json.loads(meta["config"]), "reader config")
        config.validate()
    except (KeyError, ValueError, ConfigError) as e:
        raise CheckpointError(f"{path}: stored config is invalid ({e})") from None
    reader = SpecularReader(config)
    load_module(reader, tensors, "reader", Path(path))
    return reader, tensors, meta


def load_specular_reader(path: str | Path, device: str | torch.device = "cpu") -> SpecularReader:
    """A SpecularReader in eval mode from its file (CheckpointError as read_specular_reader)."""
    reader, _, _ = read_specular_reader(path)
    return reader.to(device).eval()
