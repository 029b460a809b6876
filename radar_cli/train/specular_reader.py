"""`radar train-reader`: the specular-albedo reader (model.specular_reader) taught with the true specular albedo of
`radar synth` vases, starting from a trained model's f_L (docs/refinement.md).

    OUT/specular_reader.safetensors   the reader (weights, its ModelConfig, the epochs' scores), written at the end
    OUT/last.safetensors              after every epoch: the reader and its optimizer; a killed run resumes here
    OUT/loss.png                      the epochs' L1 errors: training, held-out, and the held-out best constant's

Each sample is unwrapped at its true shape and pose (params.json); the held-out split (`test`, when the dataset
has one) is scored after every epoch against the best constant guess (its median).
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import torch
from tqdm import tqdm

from radar_cli.config import to_dict
from radar_cli.errors import CheckpointError, ConfigError, InputError
from radar_cli.fileio import remove_stale_temps, write_image
from radar_cli.model.specular_reader import SpecularReader
from radar_cli.model.weights import load_model, read_specular_reader
from radar_cli.sor.solid import Solid
from radar_cli.threads import torch_threads
from radar_cli.train.checkpoint import optimizer_tensors, restore_optimizer, save_specular_reader
from radar_cli.train.data import VaseDataset
from radar_cli.train.logging import loss_curve

READER_FILE = "specular_reader.safetensors"
LAST_FILE = "last.safetensors"
CURVE_FILE = "loss.png"


@dataclass(frozen=True)
class ReaderConfig:
    """How the reader is trained (pipelines/readers/specular_albedo.toml).

    Attributes:
        epochs: passes over the training split.
        batch_size: samples per step.
        lr: Adam's learning rate.
        seed: shuffling seed (the same seed and data give the same reader).
        limit: train on the first N samples only (0: all).
        threads: CPU threads.
    """

    epochs: int = 2
    batch_size: int = 64
    lr: float = 3e-4
    seed: int = 0
    limit: int = 0
    threads: int = 2

    def validate(self) -> "ReaderConfig":
        """ConfigError for a value no run can use."""
        for name in ("epochs", "batch_size", "threads"):
            if getattr(self, name) < 1:
                raise ConfigError(f"reader config: {name} must be >= 1, got {getattr(self, name)}")
        if not self.lr > 0 or self.limit < 0 or self.seed < 0:
            raise ConfigError(f"reader config: lr must be > 0 and limit, seed >= 0 (got {self.lr}, {self.limit}, "
                              f"{self.seed})")
        return self


@dataclass(frozen=True)
class ReaderSummary:
    """What `train_reader` did: the reader file, every epoch's scores, the epoch it resumed after, wall time."""

    reader: Path
    history: list[dict]
    resumed: int
    seconds: float


@dataclass(frozen=True)
class _Split:
    """A split's images and ground truth: image N x 3 x S x S uint8, radius N x L, height N, pose N x 4, rho N."""

    image: torch.Tensor
    radius: torch.Tensor
    height: torch.Tensor
    pose: torch.Tensor
    rho: torch.Tensor

    @classmethod
    def load(cls, data_dir: str | Path, split: str, size: int, limit: int | None) -> "_Split":
        data = VaseDataset(data_dir, split, size, limit)
        data.load_targets()
        columns: dict[str, list] = {key: [] for key in ("radius", "height", "pose", "rho")}
        for ref, target in zip(data.refs, data.targets):
            for key, values in columns.items():
                if not isinstance(target, dict) or key not in target:
                    raise InputError(f"{ref.folder}: params.json lacks {key} (not a radar synth sample)")
                values.append(target[key])
        try:
            tensors = {key: torch.tensor(values, dtype=torch.float32) for key, values in columns.items()}
        except (ValueError, TypeError) as e:
            raise InputError(f"{Path(data_dir) / split}: ground truth of different shapes ({e})") from None
        return cls(data.images, **tensors)

    def __len__(self) -> int:
        return self.rho.shape[0]

    def read(self, reader: SpecularReader, index: torch.Tensor) -> torch.Tensor:
        """The reader's specular albedo of the samples `index` (B)."""
        image = self.image.index_select(0, index).float() / 255.0
        return reader(image, Solid(self.radius[index], self.height[index], self.pose[index]))

    def score(self, reader: SpecularReader, batch_size: int) -> tuple[float, float]:
        """(mean |error| of the reader, of the best constant guess) over the split."""
        reader.eval()
        with torch.no_grad():
            read = torch.cat([self.read(reader, torch.arange(i, min(i + batch_size, len(self))))
                              for i in range(0, len(self), batch_size)])
        return float((read - self.rho).abs().mean()), float((self.rho - self.rho.median()).abs().mean())


def train_reader(config: ReaderConfig, data_dir: str | Path, out_dir: str | Path, base: str | Path,
                 progress: bool | None = None, say: Callable[[str], None] = lambda line: None) -> ReaderSummary:
    """Train the reader from the f_L of the model in `base` (a checkpoint or exported model) on
    data_dir/train/<id>/{image.png, params.json}; resumes from out_dir/last.safetensors when it is there. A bar
    shows the steps on a terminal (`progress`); `say` gets one line per finished epoch.

    Raises:
        InputError: no samples, or samples without ground truth. CheckpointError: `base` or the run's last file
            is unreadable, or the last file was trained from another model.
    """
    config.validate()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(out, recursive=True)  # what a killed run was writing
    start_time = time.perf_counter()
    torch.manual_seed(config.seed)
    with torch_threads(config.threads):
        model, _ = load_model(base)
        size = model.config.render.image_size
        train = _Split.load(data_dir, "train", size, config.limit or None)
        held_out = _Split.load(data_dir, "test", size, None) if (Path(data_dir) / "test").is_dir() else None
        reader = SpecularReader.from_light_net(model.config, model.light_net)
        opt = torch.optim.Adam(reader.parameters(), lr=config.lr)
        history, resumed = _resume(out / LAST_FILE, reader, opt)
        steps = len(train) // config.batch_size
        if steps == 0:
            raise InputError(f"{Path(data_dir) / 'train'}: {len(train)} samples, fewer than one batch of "
                             f"{config.batch_size}")
        show = sys.stderr.isatty() if progress is None else progress
        for epoch in range(resumed, config.epochs):
            reader.train()
            order = torch.randperm(len(train), generator=torch.Generator().manual_seed(config.seed + epoch))
            total = 0.0
            for i in tqdm(range(steps), desc=f"reader epoch {epoch + 1}/{config.epochs}", disable=not show):
                index = order[i * config.batch_size:(i + 1) * config.batch_size]
                loss = (train.read(reader, index) - train.rho[index]).abs().mean()
                opt.zero_grad()
                loss.backward()
                opt.step()
                total += float(loss.detach())
            record = {"step": epoch + 1, "train_l1": total / steps}
            if held_out is not None:
                record["held_out_l1"], record["held_out_constant_l1"] = held_out.score(reader, config.batch_size)
            history.append(record)
            say(epoch_line(record))
            tensors, groups = optimizer_tensors(opt, "opt")
            save_specular_reader(reader, out / LAST_FILE, tensors,
                                 {"epoch": str(epoch + 1), "opt_groups": groups, "history": json.dumps(history),
                                  "train": json.dumps(to_dict(config))})
        path = save_specular_reader(reader, out / READER_FILE, meta={"history": json.dumps(history),
                                                                     "train": json.dumps(to_dict(config))})
        write_image(out / CURVE_FILE, loss_curve(history))
    return ReaderSummary(path, history, resumed, time.perf_counter() - start_time)


def epoch_line(record: dict) -> str:
    """One epoch's scores as a line of text."""
    held = (f", held out {record['held_out_l1']:.4f} (best constant {record['held_out_constant_l1']:.4f})"
            if "held_out_l1" in record else "")
    return f"epoch {record['step']}: train L1 {record['train_l1']:.4f}{held}"


def _resume(last: Path, reader: SpecularReader, opt: torch.optim.Optimizer) -> tuple[list[dict], int]:
    """Load the run's last epoch into `reader` and `opt` when there is one: (the epochs' records, epochs done)."""
    if not last.is_file():
        return [], 0
    saved, tensors, meta = read_specular_reader(last)
    if to_dict(saved.config) != to_dict(reader.config):
        raise CheckpointError(f"{last}: trained from a model of another configuration; use a new --out folder")
    reader.load_state_dict(saved.state_dict())
    try:
        restore_optimizer(opt, tensors, meta["opt_groups"], "opt")
        return json.loads(meta["history"]), int(meta["epoch"])
    except (KeyError, ValueError) as e:
        raise CheckpointError(f"{last}: not a resumable reader run ({e})") from None
