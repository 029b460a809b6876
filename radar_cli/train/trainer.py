"""The training loop of `radar train`, as plain functions: build the state, run steps, log, checkpoint, resume.

Determinism: the model is initialised from `train.seed`; the batch of step s depends only on (seed, s) (see
StepBatchSampler) and the global RNG is reseeded from (seed, s, rank) before every step (it draws the SAD
patches), so a resumed run reproduces an uninterrupted one.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path

import torch
from tqdm import tqdm

from radar_cli import distributed as D
from radar_cli.errors import InputError, RadarError
from radar_cli.fileio import remove_stale_temps
from radar_cli.model.config import RunConfig, TrainConfig
from radar_cli.model.discriminator import PatchDiscriminator
from radar_cli.model.losses import sad_discriminator_loss
from radar_cli.model.radar import RadarModel
from radar_cli.train.checkpoint import (
    MODEL_FILE,
    TrainState,
    export_weights,
    initialise,
    list_checkpoints,
    restore,
    save_checkpoint,
)
from radar_cli.train.data import StepBatchSampler, VaseDataset, make_loader, target_batch, to_batch
from radar_cli.train.logging import RunLogger
from radar_cli.train.step import Batch, generator_losses


class DivergedError(RadarError):
    """A loss or gradient became NaN or Inf; the run stopped before applying the bad update."""


@dataclass(frozen=True)
class TrainSummary:
    """What a finished run reports.

    Attributes:
        run_dir: the run folder. start, end: first step run and the step count reached.
        losses: the last step's loss terms. history: every step's terms (this process's batch share).
        checkpoint: the last checkpoint written. seconds: wall time of the loop. sec_per_step: its mean.
        out_of_time: the run stopped at its wall-time budget (max_minutes) before reaching its iterations.
        state: the trained modules and optimizers.
    """

    run_dir: Path
    start: int
    end: int
    losses: dict[str, float]
    history: list[dict[str, float]]
    checkpoint: Path | None
    seconds: float
    sec_per_step: float
    out_of_time: bool
    state: TrainState = dataclasses.field(repr=False)


def build_state(config: RunConfig, device: torch.device) -> TrainState:
    """Model, discriminator and their Adam optimizers, initialised from the seed."""
    torch.manual_seed(config.train.seed)
    model = RadarModel(config.model).to(device)
    m = config.model
    disc = PatchDiscriminator(config.loss.sad_patch, m.disc_width, m.max_channels).to(device)
    t = config.train
    betas = (t.beta1, t.beta2)
    return TrainState(0, model, disc, torch.optim.Adam(model.parameters(), t.lr, betas),
                      torch.optim.Adam(disc.parameters(), t.lr, betas))


def learning_rate(t: TrainConfig, step: int) -> float:
    """The learning rate of step `step` (0-based): t.lr, decayed linearly to 0 over the last t.lr_decay_steps."""
    left = t.iterations - step
    if t.lr_decay_steps == 0 or left >= t.lr_decay_steps:
        return t.lr
    return t.lr * max(0, left) / t.lr_decay_steps


def uses_sad(config: RunConfig) -> bool:
    return not config.loss.no_sad and not config.loss.supervised


def _diverged(step: int, what: str, run_dir: Path) -> DivergedError:
    ckpts = list_checkpoints(run_dir)
    last = f"last good checkpoint: {ckpts[-1]}" if ckpts else "no checkpoint was written yet"
    return DivergedError(f"step {step}: {what}; stopped before the update ({last})")


def _finite_or_stop(value: torch.Tensor, what: str, step: int, info: D.DistInfo, run_dir: Path) -> None:
    if not D.all_finite(value, info):
        raise _diverged(step, f"{what} is NaN or Inf", run_dir)


def train_step(state: TrainState, model: torch.nn.Module, disc: torch.nn.Module, batch: Batch, config: RunConfig,
               info: D.DistInfo, run_dir: Path):
    """One optimisation step of the model and, with L_SAD, of D. `model`/`disc` may be DDP wrappers of
    state.model/state.disc. Returns (loss terms as floats, prediction, rendered) of this rank's batch."""
    step = state.step
    lr = learning_rate(config.train, step)  # a function of the step alone, so a resumed run follows the same curve
    for group in state.opt_model.param_groups + state.opt_disc.param_groups:
        group["lr"] = lr
    try:
        pred = model(batch.image)
    except InputError as e:  # the geometry checks inside forward reject NaN shapes before we see them
        raise _diverged(step, f"invalid network output ({e})", run_dir) from None
    _finite_or_stop(torch.stack([t.sum() for t in pred.tensors()]), "a network output", step, info, run_dir)
    bare_disc = D.unwrap(disc)
    terms, rendered = generator_losses(pred, batch, config, bare_disc if uses_sad(config) else None,
                                       state.model)
    _finite_or_stop(terms["total"], "the loss", step, info, run_dir)
    state.opt_model.zero_grad(set_to_none=True)
    terms["total"].backward()
    norm = torch.nn.utils.clip_grad_norm_(state.model.parameters(), float("inf"))
    _finite_or_stop(norm, "the gradient", step, info, run_dir)
    state.opt_model.step()
    if rendered.sad_real is not None and rendered.sad_fake is not None:
        d_loss = sad_discriminator_loss(disc, rendered.sad_real, rendered.sad_fake)
        _finite_or_stop(d_loss, "the discriminator loss", step, info, run_dir)
        state.opt_disc.zero_grad(set_to_none=True)
        d_loss.backward()
        state.opt_disc.step()
        terms["disc"] = d_loss
    state.step = step + 1
    return {k: float(v.detach()) for k, v in terms.items()}, pred.detach(), rendered


def _resume(run_dir: Path, config: RunConfig, state: TrainState) -> int:
    ckpts = list_checkpoints(run_dir)
    if not ckpts:
        raise RadarError(f"{run_dir}: --resume given but there is no checkpoint in {run_dir / 'checkpoints'}")
    return restore(ckpts[-1], config, state)


def apply_overrides(config: RunConfig, iterations: int | None, overfit: int | None,
                    threads: int | None = None) -> RunConfig:
    """The config with --iterations and --threads replaced and, for --overfit N, the batch size limited to N."""
    train = config.train
    if iterations is not None:
        train = dataclasses.replace(train, iterations=iterations)
    if threads is not None:
        train = dataclasses.replace(train, threads=threads)
    if overfit is not None:
        train = dataclasses.replace(train, batch_size=min(train.batch_size, overfit))
    return dataclasses.replace(config, train=train).validate()


def train(config: RunConfig, data_dir: str | Path, run_dir: str | Path, resume: bool = False,
          device: str | None = None, overfit: int | None = None, iterations: int | None = None,
          progress: bool = True, init: str | Path | None = None, threads: int | None = None,
          max_minutes: float | None = None, pitch_labels: str | Path | None = None) -> TrainSummary:
    """Train RADAR on DATA/train and write checkpoints, metrics and images to run_dir.

    Args:
        config: the run's configuration (pipelines/**/*.toml).
        data_dir: dataset root holding train/<id>/image.png + mask.png.
        run_dir: output folder (created).
        resume: continue from the newest checkpoint in run_dir.
        device: "auto", "cpu" or "cuda" (overrides config.train.device).
        overfit: train on the first N samples only (a wiring test).
        iterations: total steps (overrides config.train.iterations).
        progress: show the progress bar.
        init: start from this checkpoint's weights (fine-tuning); ignored when resuming a run that has
            checkpoints of its own.
        threads: CPU threads (overrides config.train.threads).
        max_minutes: wall-time budget of the loop: once a step ends past it, a checkpoint is written and the
            run stops (continue it with resume=True), e.g. inside a batch job's time limit.
        pitch_labels: a `radar derender --pitch search` results folder of the training split, one
            <sample id>/material.json each (needed when loss.pitch_label_weight > 0).

    Returns:
        TrainSummary.

    Raises:
        DivergedError: NaN/Inf in an output, loss or gradient (the step number and last checkpoint are named).
        CheckpointError, InputError, ConfigError: unusable checkpoint, data or config.
    """
    config = apply_overrides(config, iterations, overfit, threads)
    info = D.setup(device or config.train.device)
    if config.train.threads > 0:
        torch.set_num_threads(config.train.threads)
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    if info.is_main:  # rank 0 writes the run folder: whatever a killed run was writing there
        remove_stale_temps(run_dir, recursive=True)
    try:
        return _run(config, Path(data_dir), run_dir, resume, overfit, info, progress, init, max_minutes,
                    pitch_labels)
    finally:
        D.teardown(info)


def _run(config: RunConfig, data_dir: Path, run_dir: Path, resume: bool, overfit: int | None,
         info: D.DistInfo, progress: bool, init: str | Path | None, max_minutes: float | None,
         pitch_labels: str | Path | None) -> TrainSummary:
    t = config.train
    dataset = VaseDataset(data_dir, "train", config.model.render.image_size, limit=overfit)
    if config.loss.supervised:
        dataset.load_targets()
    if config.loss.pitch_label_weight > 0:
        if pitch_labels is None:
            raise InputError("loss.pitch_label_weight > 0 needs --pitch-labels (a `radar derender --pitch search` "
                             "results folder of the training split)")
        dataset.load_pitch_labels(pitch_labels)
    state = build_state(config, info.device)
    resuming = resume and (init is None or bool(list_checkpoints(run_dir)))
    start = _resume(run_dir, config, state) if resuming else 0
    if init is not None and not resuming and not initialise(init, state) and uses_sad(config) and info.is_main:
        tqdm.write(f"{init}: no discriminator in it (a model file): L_SAD's D starts afresh; --init a checkpoint "
                   "to keep the one it was trained with")
    model, disc = D.wrap(state.model, info), D.wrap(state.disc, info)
    sampler = StepBatchSampler(len(dataset), t.batch_size, t.seed, start, t.iterations, info.rank, info.world)
    logger = RunLogger(run_dir, start, t.iterations, enabled=info.is_main, bar=progress)
    history: list[dict[str, float]] = []
    ckpt, t0, terms, out_of_time = None, time.perf_counter(), {}, False
    deadline = None if max_minutes is None else t0 + 60.0 * max_minutes
    try:
        for step, items in enumerate(make_loader(dataset, sampler), start=start):
            torch.manual_seed(t.seed * 1_000_003 + step * info.world + info.rank)
            target = target_batch(dataset, items["index"], config, info.device) if config.loss.supervised else None
            batch = to_batch(items, info.device, target)
            tic = time.perf_counter()
            terms, pred, rendered = train_step(state, model, disc, batch, config, info, run_dir)
            history.append(terms)
            done = state.step
            logged = done % t.log_every == 0 or done == t.iterations
            values = dict(D.mean_across(terms, info)) if logged else None
            if values is not None:
                values["sec_per_step"] = time.perf_counter() - tic
                values["lr"] = learning_rate(t, step)
            logger.step(step, values)
            if done % t.image_every == 0 or done == t.iterations:
                logger.grid(done, batch, pred, rendered, config.model.render.gamma)
            if deadline is not None and done < t.iterations:
                out_of_time = D.any_rank(time.perf_counter() >= deadline, info)
            if done % t.checkpoint_every == 0 or done == t.iterations or out_of_time:
                if info.is_main:
                    ckpt = save_checkpoint(run_dir, config, state, t.keep_checkpoints)
                D.barrier(info)
            if out_of_time:
                break
    finally:
        logger.close()
    if info.is_main and ckpt is not None and state.step == t.iterations:
        export_weights(ckpt, run_dir / MODEL_FILE)  # what `radar derender --checkpoint` takes
    seconds = time.perf_counter() - t0
    n = max(1, len(history))
    return TrainSummary(run_dir, start, state.step, terms, history, ckpt, seconds, seconds / n, out_of_time, state)
