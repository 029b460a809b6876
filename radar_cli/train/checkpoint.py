"""Checkpoints: one safetensors file per save holding the model, D and both optimizers' tensors, with the run
config, the step and the optimizers' settings as JSON metadata, so inference needs only the checkpoint.

    RUN_DIR/checkpoints/step_0001000.safetensors   written atomically; the last K are kept
    RUN_DIR/model.safetensors                      the model alone, exported when the run completes

Exported weights (`export_weights`) are the same format with only the model's tensors; radar_cli.model.weights
reads both.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

import torch
from safetensors.torch import save_file
from torch import nn

from radar_cli.errors import CheckpointError
from radar_cli.fileio import atomic_path
from radar_cli.model.config import RunConfig, to_dict
from radar_cli.model.radar import RadarModel
from radar_cli.model.specular_reader import SpecularReader
from radar_cli.model.weights import FORMAT, READER_FORMAT, load_module, module_tensors, read_checkpoint

CHECKPOINT_DIR = "checkpoints"
_NAME_RE = re.compile(r"^step_(\d{7,})\.safetensors$")
MODEL_FILE = "model.safetensors"  # RUN_DIR/model.safetensors: weights + config only, written when a run completes


@dataclass
class TrainState:
    """Everything a run needs to continue exactly: the step to run next and the modules it updates."""

    step: int
    model: RadarModel
    disc: nn.Module
    opt_model: torch.optim.Optimizer
    opt_disc: torch.optim.Optimizer


def optimizer_tensors(opt: torch.optim.Optimizer, prefix: str) -> tuple[dict[str, torch.Tensor], str]:
    """Flatten an optimizer state_dict into named tensors plus JSON for its param groups."""
    sd = opt.state_dict()
    tensors = {}
    for pid, state in sd["state"].items():
        for name, value in state.items():
            t = value if isinstance(value, torch.Tensor) else torch.tensor(value)
            tensors[f"{prefix}.{pid}.{name}"] = t.detach().cpu().contiguous()
    return tensors, json.dumps(sd["param_groups"])


def restore_optimizer(opt: torch.optim.Optimizer, tensors: dict[str, torch.Tensor], groups: str,
                       prefix: str) -> None:
    state: dict[int, dict[str, torch.Tensor]] = {}
    for key, value in tensors.items():
        if key.startswith(prefix + "."):
            _, pid, name = key.split(".", 2)
            state.setdefault(int(pid), {})[name] = value
    opt.load_state_dict({"state": state, "param_groups": json.loads(groups)})


def save_checkpoint(run_dir: str | Path, config: RunConfig, state: TrainState, keep: int) -> Path:
    """Write RUN_DIR/checkpoints/step_<step>.safetensors atomically and delete all but the newest `keep`."""
    tensors = module_tensors(state.model, "model") | module_tensors(state.disc, "disc")
    opt_m, groups_m = optimizer_tensors(state.opt_model, "opt_model")
    opt_d, groups_d = optimizer_tensors(state.opt_disc, "opt_disc")
    meta = {"format": FORMAT, "config": json.dumps(to_dict(config)), "step": str(state.step),
            "opt_model_groups": groups_m, "opt_disc_groups": groups_d}
    path = Path(run_dir) / CHECKPOINT_DIR / f"step_{state.step:07d}.safetensors"
    with atomic_path(path) as tmp:
        save_file(tensors | opt_m | opt_d, str(tmp), metadata=meta)
    for old in list_checkpoints(run_dir)[:-keep]:
        old.unlink(missing_ok=True)
    return path


def list_checkpoints(run_dir: str | Path) -> list[Path]:
    """Checkpoints of a run, oldest first."""
    folder = Path(run_dir) / CHECKPOINT_DIR
    if not folder.is_dir():
        return []
    found = [p for p in folder.iterdir() if _NAME_RE.match(p.name)]
    return sorted(found, key=lambda p: int(_NAME_RE.match(p.name).group(1)))  # type: ignore[union-attr]


def restore(path: str | Path, config: RunConfig, state: TrainState) -> int:
    """Load a checkpoint into `state` for `--resume`; returns the step to run next.

    Raises:
        CheckpointError: if the checkpoint is corrupt, or its model/loss config differs from `config`.
    """
    tensors, meta, stored = read_checkpoint(path)
    for part in ("model", "loss"):
        if to_dict(getattr(stored, part)) != to_dict(getattr(config, part)):
            raise CheckpointError(f"{path}: its [{part}] config differs from the one given; resume with the same "
                                  "config or start a new run folder")
    load_module(state.model, tensors, "model", Path(path))
    load_module(state.disc, tensors, "disc", Path(path))
    try:
        restore_optimizer(state.opt_model, tensors, meta["opt_model_groups"], "opt_model")
        restore_optimizer(state.opt_disc, tensors, meta["opt_disc_groups"], "opt_disc")
        state.step = int(meta["step"])
    except (KeyError, ValueError) as e:
        raise CheckpointError(f"{path}: optimizer state is missing or does not fit ({e})") from None
    return state.step


def initialise(path: str | Path, state: TrainState) -> bool:
    """Start a new run from the weights of another run's checkpoint or exported model (`radar train --init`):
    the networks (and the discriminator, when the file has one) are loaded; optimizers and the step start afresh.
    The loss and render settings may differ (e.g. a sharper silhouette for fine-tuning); the architecture may not.
    Returns whether the discriminator was loaded (an exported model.safetensors has none).

    Raises:
        CheckpointError: corrupt file, or weights that do not fit the model being trained.
    """
    tensors, _, _ = read_checkpoint(path)
    load_module(state.model, tensors, "model", Path(path))
    if not any(k.startswith("disc.") for k in tensors):
        return False
    load_module(state.disc, tensors, "disc", Path(path))
    return True


def export_weights(checkpoint: str | Path, out: str | Path) -> Path:
    """Write only the model's weights and its config (safetensors metadata) from a checkpoint, atomically."""
    tensors, meta, config = read_checkpoint(checkpoint)
    model = {k: v for k, v in tensors.items() if k.startswith("model.")}
    with atomic_path(out) as tmp:
        save_file(model, str(tmp), metadata={"format": FORMAT, "config": json.dumps(to_dict(config)),
                                             "step": meta.get("step", "0")})
    return Path(out)


def save_specular_reader(reader: SpecularReader, path: str | Path, extra: dict[str, torch.Tensor] | None = None,
                         meta: dict[str, str] | None = None) -> Path:
    """Write a SpecularReader's weights (and `extra` tensors, e.g. its optimizer's) with its config, atomically."""
    tensors = {**module_tensors(reader, "reader"), **(extra or {})}
    with atomic_path(path) as tmp:
        save_file(tensors, str(tmp), metadata={"format": READER_FORMAT, "config": json.dumps(to_dict(reader.config)),
                                               **(meta or {})})
    return Path(path)


