"""Training data: the dataset layout of radar_cli.dataset, held in memory as tensors, and a deterministic sampler.

Images and masks are resized to the model's image size when they differ; the distance transform of each mask
(for L_sil) is computed once at load. The batch drawn at step s depends only on (seed, s), so a resumed run
sees exactly the batches an uninterrupted one would, and the ranks of a distributed run split each global batch.
"""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import cv2
import numpy as np
import torch
from torch.utils.data import Sampler

from radar_cli.dataset import SampleRef, list_samples, read_sample
from radar_cli.errors import InputError
from radar_cli.fileio import number, read_json
from radar_cli.model.losses import distance_transform
from radar_cli.model.outputs import Decomposition
from radar_cli.results import MATERIAL_FILE
from radar_cli.synth.layout import ALBEDO_FILE, ENV_MAP_FILE, PARAMS_FILE
from radar_cli.train.step import Batch


@dataclass(frozen=True)
class Sample:
    """One preprocessed sample: image 3 x S x S uint8, mask S x S bool, dt S x S float32."""

    image: np.ndarray
    mask: np.ndarray
    dt: np.ndarray


def _resize(image: np.ndarray, mask: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    if image.shape[0] == size and image.shape[1] == size:
        return image, mask
    if image.shape[0] != image.shape[1]:
        raise InputError(f"training images must be square, got {image.shape[1]}x{image.shape[0]}")
    image = cv2.resize(image, (size, size), interpolation=cv2.INTER_AREA)
    mask = cv2.resize(mask.astype(np.uint8), (size, size), interpolation=cv2.INTER_NEAREST) > 0
    return image, mask


def load_sample(ref: SampleRef, size: int) -> Sample:
    """Read, resize and preprocess one sample (InputError names the file on any problem)."""
    image, mask = _resize(*read_sample(ref), size)
    return Sample(np.ascontiguousarray(image.transpose(2, 0, 1)), mask, distance_transform(mask))


def read_params(ref: SampleRef) -> dict | None:
    """The synthetic ground truth of a sample (params.json), or None when there is none."""
    path = ref.folder / PARAMS_FILE
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: not readable JSON ({e})") from None


class VaseDataset:
    """All samples of one split in memory; `batch(indices)` gathers a batch straight from the stacked tensors.

    Batches stay in their compact types (uint8 images, bool masks) until `to_batch` has moved them to the device,
    so the float conversion runs there; the gathers replace collating item by item through a DataLoader."""

    def __init__(self, root: str | Path, split: str, size: int, limit: int | None = None, workers: int = 4):
        refs = list_samples(root, split)
        if limit is not None:
            refs = refs[:limit]
        if not refs:
            raise InputError(f"{Path(root) / split}: no samples (expected <id>/image.png + mask.png)")
        self.refs = refs
        with ThreadPoolExecutor(max(1, workers)) as pool:
            samples = list(pool.map(lambda r: load_sample(r, size), refs))
        self.images = torch.from_numpy(np.stack([s.image for s in samples]))  # N x 3 x S x S uint8
        self.masks = torch.from_numpy(np.stack([s.mask for s in samples]))  # N x S x S bool
        self.dts = torch.from_numpy(np.stack([s.dt for s in samples]))  # N x S x S float32
        self.targets: list[dict | None] = [None] * len(refs)
        self.pitch_labels: torch.Tensor | None = None  # N degrees, once load_pitch_labels has run

    def load_targets(self) -> None:
        """Read params.json of every sample (for the supervised baseline); InputError if one is missing."""
        self.targets = [read_params(r) for r in self.refs]
        missing = [r.folder for r, t in zip(self.refs, self.targets) if t is None]
        if missing:
            raise InputError(f"{missing[0]}: no {PARAMS_FILE} (the supervised baseline needs synthetic ground truth)")

    def load_pitch_labels(self, results_dir: str | Path) -> None:
        """Read each sample's pitch from `results_dir/<sample id>/material.json`, as `radar derender --pitch
        search` writes it for a dataset split (loss.pitch_label_weight); InputError names the first sample
        without a usable one."""
        labels = []
        for ref in self.refs:
            path = Path(results_dir) / ref.sample_id / MATERIAL_FILE
            if not path.is_file():
                raise InputError(f"{path}: missing (de-render the training split with `radar derender "
                                 f"{ref.root / ref.split} --pitch search` into {results_dir})")
            labels.append(number(read_json(path), "pitch", path))
        self.pitch_labels = torch.tensor(labels)

    def __len__(self) -> int:
        return len(self.refs)

    def batch(self, indices: list[int]) -> dict:
        """{"index": B, "image": B x 3 x S x S uint8, "mask": B x S x S bool, "dt": B x S x S float32}, and
        "pitch_label": B degrees when the labels are loaded."""
        idx = torch.as_tensor(indices, dtype=torch.long)
        items = {"index": idx, "image": self.images.index_select(0, idx), "mask": self.masks.index_select(0, idx),
                 "dt": self.dts.index_select(0, idx)}
        if self.pitch_labels is not None:
            items["pitch_label"] = self.pitch_labels.index_select(0, idx)
        return items


class StepBatchSampler(Sampler[list[int]]):
    """Yields the indices of this rank's share of the global batch for steps start, start+1, ... end-1.

    The global batch of step s is positions [s*B, (s+1)*B) of an endless sequence of per-epoch permutations,
    each drawn from a generator seeded by (seed, epoch); rank r of W takes every W-th index of it.
    """

    def __init__(self, n: int, batch_size: int, seed: int, start: int, end: int, rank: int = 0, world: int = 1):
        self.n, self.batch_size, self.seed = n, batch_size, seed
        self.start, self.end, self.rank, self.world = start, end, rank, world
        self._perms: dict[int, torch.Tensor] = {}

    def _perm(self, epoch: int) -> torch.Tensor:
        if epoch not in self._perms:
            self._perms = {epoch: torch.randperm(self.n, generator=torch.Generator().manual_seed(
                self.seed * 1_000_003 + epoch))}
        return self._perms[epoch]

    def global_batch(self, step: int) -> list[int]:
        """The dataset indices of the whole batch at `step` (all ranks)."""
        pos = range(step * self.batch_size, (step + 1) * self.batch_size)
        return [int(self._perm(p // self.n)[p % self.n]) for p in pos]

    def __iter__(self) -> Iterator[list[int]]:
        for step in range(self.start, self.end):
            yield self.global_batch(step)[self.rank :: self.world]

    def __len__(self) -> int:
        return max(0, self.end - self.start)


def make_loader(dataset: VaseDataset, sampler: StepBatchSampler) -> Iterator[dict]:
    """This rank's batches for the sampler's steps, gathered from the in-memory dataset."""
    return (dataset.batch(indices) for indices in sampler)


def to_batch(items: dict, device: torch.device, target: Decomposition | None = None) -> Batch:
    """A `VaseDataset.batch` dict (B x 3 x S x S uint8 images, B x S x S bool masks) as a float Batch on `device`."""
    image = items["image"].to(device).float() / 255.0
    label = items.get("pitch_label")
    return Batch(image, items["mask"].to(device).float(), items["dt"].to(device), target,
                 None if label is None else label.to(device))


def _target_maps(ref: SampleRef, tex: tuple[int, int], env: tuple[int, int], gamma: float):
    from radar_cli.fileio import read_image

    full = read_image(ref.folder / ALBEDO_FILE, "RGB").astype(np.float32) / 255.0  # Ht x 3Wt, tone-mapped
    w = full.shape[1] // 3
    albedo = full[:, w : 2 * w]  # the frontal third
    albedo = cv2.resize(albedo, (tex[1], tex[0]), interpolation=cv2.INTER_AREA) ** gamma  # linear
    try:
        env_map = np.load(ref.folder / ENV_MAP_FILE, allow_pickle=False).astype(np.float32)
    except (OSError, ValueError) as e:
        raise InputError(f"{ref.folder / ENV_MAP_FILE}: not a readable .npy array ({e})") from None
    env_map = cv2.resize(env_map, (env[1], env[0]), interpolation=cv2.INTER_AREA)
    return torch.from_numpy(albedo.transpose(2, 0, 1).copy()), torch.from_numpy(env_map)


def target_batch(dataset: VaseDataset, indices: torch.Tensor, config, device: torch.device) -> Decomposition:
    """Ground truth of the samples `indices` as a Decomposition at the model's sizes (supervised baseline).

    Reads params.json (radius, height, pose, alpha, rho), the frontal third of albedo.png and env_map.npy
    (radar_cli.synth.layout).
    """
    r = config.model.render
    rows = []
    for i in indices.tolist():
        p, ref = dataset.targets[i], dataset.refs[i]
        if p is None:
            raise InputError(f"{ref.folder}: no {PARAMS_FILE}")
        try:
            radius = torch.tensor(p["radius"], dtype=torch.float32)
            scalars = torch.tensor([p["height"], p["alpha"], p["rho"]], dtype=torch.float32)
            pose = torch.tensor(p["pose"], dtype=torch.float32)
        except (KeyError, TypeError, ValueError) as e:
            raise InputError(f"{ref.folder / PARAMS_FILE}: missing or bad ground-truth field ({e})") from None
        if radius.numel() != config.model.geometry.n_rows:
            radius = torch.nn.functional.interpolate(radius[None, None], size=config.model.geometry.n_rows,
                                                     mode="linear", align_corners=True)[0, 0]
        albedo, env = _target_maps(ref, (r.tex_height, r.tex_width), (r.env_height, r.env_width), r.gamma)
        rows.append((radius, scalars, pose, albedo, env))
    radius, scalars, pose, albedo, env = (torch.stack(c).to(device) for c in zip(*rows))
    return Decomposition(radius, scalars[:, 0], pose, albedo, env, scalars[:, 1], scalars[:, 2])
