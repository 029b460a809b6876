"""The `radar derender` driver: inputs -> crops -> network in batches -> per-object exports -> report.

One bad input costs one line and one failures.csv row; the rest are processed. Finished object folders are
skipped (a killed run resumes) and never overwritten without `overwrite`. An object's files are the same bytes
whatever the batch size, worker count or share and wherever a killed run resumed: the network sees one photo at a
time (Predictor.predict) and each object is refined and exported on one torch thread (EXPORT_THREADS).

Workers are processes where the model runs on the CPU (`DerenderOptions.processes`, run.processes: each object
one task, taken by whichever process is free) and threads beside a GPU, which one process drives.
"""

from __future__ import annotations

import dataclasses
import functools
import pickle
import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, TypeVar

import numpy as np
import torch
from tqdm import tqdm

from radar_cli.allocator import keep_freed_memory
from radar_cli.derender.export.environments import builtin_environments, env_name, load_environment
from radar_cli.derender.export.object_folder import ExportConfig, export_object, is_complete
from radar_cli.derender.multiview.driver import derender_views, recorded_left_out
from radar_cli.derender.present.report import write_report
from radar_cli.derender.run.inputs import (
    DEFAULT_RESOLUTION,
    Backdrop,
    CropMode,
    Failure,
    InputItem,
    Prepared,
    Resolution,
    collect_inputs,
    output_side,
    prepare,
)
from radar_cli.derender.run.object_record import ObjectRecord, RecordFinder
from radar_cli.derender.run.predictor import Predictor
from radar_cli.derender.run.processes import spread
from radar_cli.derender.run.shard import Shard, read_share_failures, write_share_failures
from radar_cli.derender.run.upsample import full_resolution_state
from radar_cli.errors import InputError, NothingToDoError, RadarError
from radar_cli.fileio import remove_stale_temps
from radar_cli.model.outputs import Decomposition
from radar_cli.threads import on_torch_threads, torch_threads

R = TypeVar("R")
EXPORT_THREADS = 1  # exports work on small tensors: one torch thread runs them faster (docs/performance.md, Threads)
# errors of one object's export that must not stop the batch (decoding, writing, a degenerate prediction)
ITEM_ERRORS = (RadarError, OSError, ValueError, RuntimeError)
SHARED_TEMP_AGE_S = 60.0
"""A share of a collection removes only temporary files this old outside its own objects: the other shares
writing into the same folder finish each of theirs in well under a second."""


@dataclass(frozen=True)
class DerenderOptions:
    """How a batch is run (the CLI's options)."""

    out: Path
    crop: CropMode = "auto"
    backdrop: Backdrop = "white"
    masks: Path | None = None
    envs: tuple[Path, ...] = ()
    batch_size: int = 8
    workers: int = 2
    threads: int = 1
    """torch intra-op threads for the network (one: docs/performance.md, Threads)."""
    overwrite: bool = False
    export: ExportConfig = field(default_factory=ExportConfig)
    resolution: Resolution = DEFAULT_RESOLUTION
    """Side of the outputs (inputs.output_side): an integer, or `photo` for each crop's own size."""
    shard: Shard = Shard()
    """The share of the inputs this process de-renders (0/1: all of them)."""
    dimensions: Path | None = None
    """A table of catalogued sizes (radar_cli.sizes.read_size_table); harvested sizes are used without it."""
    processes: bool = False
    """Workers as processes, each object a task, where the model runs on the CPU (the CLI's choice; on two
    cores 24 photos took 27 s where two threads took 35 s, docs/performance.md); threads otherwise."""


@dataclass
class BatchSummary:
    """What a run did."""

    done: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failures: list[Failure] = field(default_factory=list)
    seconds: float = 0.0
    index: Path | None = None
    printed: bool = True
    """False on the torchrun ranks other than 0, whose summary line rank 0 prints with its own."""

    def line(self) -> str:
        rate = len(self.done) / self.seconds if self.seconds > 0 else 0.0
        return (f"{len(self.done)} de-rendered, {len(self.skipped)} skipped (already done), "
                f"{len(self.failures)} failed in {self.seconds:.1f} s ({rate:.2f} objects/s)")


def environments(paths: tuple[Path, ...], height: int, width: int) -> dict[str, np.ndarray]:
    """The built-in relighting environments plus the user's (named by file stem), at the model's size."""
    envs = builtin_environments(height, width)
    for path in paths:
        name = env_name(path)
        if name in envs:
            raise InputError(f"{path}: environment name {name!r} is already used; rename the file")
        envs[name] = load_environment(path, height, width)
    return envs


class _Pool:
    """Runs calls on up to `workers` threads (in the calling thread when workers <= 1, one call at a time, in
    order), every call on EXPORT_THREADS torch threads (threads.on_torch_threads)."""

    def __init__(self, workers: int):
        self.executor = ThreadPoolExecutor(max_workers=workers) if workers > 1 else None

    def submit(self, fn: Callable[..., R], *args) -> Future[R]:
        if self.executor is not None:
            return self.executor.submit(on_torch_threads, EXPORT_THREADS, fn, *args)
        done: Future[R] = Future()
        with torch_threads(EXPORT_THREADS):
            done.set_result(fn(*args))
        return done

    def close(self) -> None:
        if self.executor is not None:
            self.executor.shutdown(wait=True)


def collect(inputs: list[str | Path], options: DerenderOptions) -> tuple[list[InputItem], list[Failure]]:
    """The run's photos and the inputs that failed (see inputs.collect_inputs).

    Raises InputError when --out is one of the input folders (the report would land among the photos) and
    NothingToDoError when no input holds a photo; nothing is written in either case."""
    out = options.out.resolve()
    for raw in inputs:
        if Path(raw).is_dir() and Path(raw).resolve() == out:
            raise InputError(f"{options.out}: --out is the input folder {raw}; choose a results folder outside it")
    items, failures = collect_inputs(list(inputs), options.masks, exclude=options.out)
    if not items:
        raise NothingToDoError("; ".join(f.line() for f in failures) or "no inputs given")
    return items, failures


def _pending(batch: list[InputItem], out: Path, overwrite: bool, summary: BatchSummary,
             say: Callable[[str], None]) -> set[str]:
    """The names of a batch still to do; finished folders are skipped unless `overwrite`."""
    todo = set()
    for item in batch:
        if is_complete(out / item.name) and not overwrite:
            summary.skipped.append(item.name)
            say(f"{item.name}: skipped, {out / item.name} exists (use --overwrite to redo it)")
            if item.multiview:  # the photos it was fitted without stay failures
                for failure in recorded_left_out(out / item.name, item.name):
                    summary.failures.append(failure)
                    say(failure.line())
        else:
            todo.add(item.name)
            remove_stale_temps(out / item.name)  # this share's own object: whatever a killed run was writing
    return todo


def derender(inputs: list[str | Path], predictor: Predictor, options: DerenderOptions,
             say: Callable[[str], None] = tqdm.write, report: bool = True) -> BatchSummary:
    """De-render every input (of options.shard's share) into options.out/<name>/ and write index.html,
    summary.csv and failures.csv.

    Args:
        inputs: image files, folders, prepared dataset folders.
        predictor: the model.
        options: output folder and settings.
        say: where one-line messages (skips, failures) go.
        report: write the report (False: a torchrun rank, whose rank 0 writes it for all).

    Returns:
        BatchSummary; the caller decides the exit code (non-zero if any failure).
    """
    start = time.perf_counter()
    if options.batch_size < 1 or options.workers < 0 or options.threads < 1:
        raise InputError("--batch-size and --threads must be >= 1, --workers >= 0")
    output_side(options.resolution, 1)  # checks it before any work
    render = predictor.setup.render
    envs = environments(options.envs, render.env_height, render.env_width)
    records = RecordFinder(options.dimensions)  # a bad table stops the run before any work
    items, failures = collect(inputs, options)
    shard = options.shard
    if options.out.is_dir():  # what a killed run was writing: the report, the gallery, finished objects
        remove_stale_temps(options.out, recursive=True, min_age_s=SHARED_TEMP_AGE_S if shard.enabled else 0.0)
    summary = BatchSummary(failures=list(failures) if shard.index == 0 else [])  # input errors: share 0 records
    for f in summary.failures:
        say(f.line())
    options.out.mkdir(parents=True, exist_ok=True)
    batches = shard.blocks([i for i in items if not i.multiview], options.batch_size)
    several = [block[0] for block in shard.blocks([i for i in items if i.multiview], 1)]
    with records, torch_threads(options.threads), tqdm(total=sum(map(len, batches)) + len(several), desc="derender",
                                                     unit="obj", disable=None) as bar:
        if options.processes and options.workers > 1 and predictor.device.type == "cpu":
            _on_processes(batches, several, predictor, options, envs, summary, say, records, bar)
        else:
            _on_threads(batches, several, predictor, options, envs, summary, say, records, bar)
    if shard.enabled:
        write_share_failures(options.out, shard, summary.failures)
    if report:
        merged = read_share_failures(options.out, shard.count) if shard.enabled else summary.failures
        summary.index = write_report(options.out, merged)
    summary.seconds = time.perf_counter() - start
    return summary


def _on_threads(batches: list[list[InputItem]], several: list[InputItem], predictor: Predictor,
                options: DerenderOptions, envs: dict[str, np.ndarray], summary: BatchSummary,
                say: Callable[[str], None], records: RecordFinder, bar: tqdm) -> None:
    """The batches through one pool of options.workers threads, then the multi-view objects one by one."""
    runner = _Batches(predictor, options, envs, summary, say, records, bar)
    try:
        for batch in batches:
            runner.run(batch, _pending(batch, options.out, options.overwrite, summary, say))
        runner.finish()
    finally:
        runner.pool.close()
    for item in several:
        if _pending([item], options.out, options.overwrite, summary, say):
            _run_views(item, predictor, options, envs, summary, say, records)
        bar.update(1)


@dataclass(frozen=True)
class _Task:
    """One object for a worker process: a photo, or a multi-view object's folder (views)."""

    item: InputItem
    views: bool = False


@dataclass
class _Outcome:
    """What a worker process did with a _Task: the object done, or its failures, and the lines it said."""

    done: list[str]
    failures: list[Failure]
    said: list[str]


def _on_processes(batches: list[list[InputItem]], several: list[InputItem], predictor: Predictor,
                  options: DerenderOptions, envs: dict[str, np.ndarray], summary: BatchSummary,
                  say: Callable[[str], None], records: RecordFinder, bar: tqdm) -> None:
    """Every object still to do as a task for options.workers processes (this one and workers - 1 spawned ones,
    each given the model and options pickled); outcomes recorded in input order, said as they come."""
    tasks = []
    for batch in batches:
        todo = _pending(batch, options.out, options.overwrite, summary, say)
        tasks += [_Task(item) for item in batch if item.name in todo]
        bar.update(len(batch) - len(todo))
    for item in several:
        if _pending([item], options.out, options.overwrite, summary, say):
            tasks.append(_Task(item, views=True))
        else:
            bar.update(1)
    one = dataclasses.replace(options, workers=1)

    def arrived(outcome: _Outcome) -> None:
        for line in outcome.said:
            say(line)
        bar.update(1)

    def lost(task: _Task, reason: str) -> _Outcome:
        failure = Failure(str(task.item.image_path.parent if task.views else task.item.image_path),
                          f"not de-rendered: {reason}")
        return _Outcome([], [failure], [failure.line()])

    payload = pickle.dumps((predictor, one, envs))  # for our own worker processes only: never written to disk
    outcomes = spread(tasks, functools.partial(_run_task, predictor=predictor, options=one, envs=envs, records=records),
                      functools.partial(_process_worker, payload), options.workers - 1, arrived, lost)
    for outcome in outcomes:
        summary.done += outcome.done
        summary.failures += outcome.failures


def _process_worker(payload: bytes) -> Callable[[_Task], _Outcome]:
    """In a spawned worker process: the model, options and environments unpickled, the run's settings made (the
    allocator's, torch's threads), and the task runner over them."""
    keep_freed_memory()
    predictor, options, envs = pickle.loads(payload)  # made by the run's own process, passed by a pipe
    torch.set_num_threads(options.threads)
    records = RecordFinder(options.dimensions)  # open for the process's life: its catalogs' connections are its own
    return functools.partial(_run_task, predictor=predictor, options=options, envs=envs, records=records)


def _run_task(task: _Task, predictor: Predictor, options: DerenderOptions, envs: dict[str, np.ndarray],
              records: RecordFinder) -> _Outcome:
    """De-render one object in this process (options.workers 1)."""
    summary = BatchSummary()
    said: list[str] = []
    if task.views:
        _run_views(task.item, predictor, options, envs, summary, said.append, records)
    else:
        runner = _Batches(predictor, options, envs, summary, said.append, records, None)
        runner.run([task.item], {task.item.name})
        runner.finish()
    return _Outcome(summary.done, summary.failures, said)


class _Batches:
    """Crops, predicts and exports the batches through one pool of options.workers threads, with no barrier
    between batches: a batch's photos are read and located while the batch before it is still exported, and the
    network reads them (in the calling thread) meanwhile. Outcomes are recorded in input order, whatever finished
    first; each object's files are the same bytes as a one-worker run's (every export on one torch thread)."""

    def __init__(self, predictor: Predictor, options: DerenderOptions, envs: dict[str, np.ndarray],
                 summary: BatchSummary, say: Callable[[str], None], records: RecordFinder, bar: tqdm | None):
        self.predictor, self.options, self.envs, self.summary, self.say = predictor, options, envs, summary, say
        self.records, self.bar = records, bar
        self.pool = _Pool(options.workers)
        self.exporting: list[tuple[InputItem, Future[Failure | None]]] = []  # the batch before, in input order
        self.size_of_exporting = 0  # its inputs, skipped ones included (the progress bar's steps)

    def run(self, batch: list[InputItem], todo: set[str]) -> None:
        """Start a batch (its objects named in `todo`; the others were skipped); records the batch before it."""
        chunk = [item for item in batch if item.name in todo]
        size, options = self.predictor.setup.render.image_size, self.options
        reading = [self.pool.submit(_prepare_one, item, size, options) for item in chunk]
        prepared = [f.result() for f in reading]
        ok = [(item, prep) for item, prep in zip(chunk, prepared) if not isinstance(prep, Failure)]
        exports = []
        if ok:
            dec = self.predictor.predict([prep.image for _, prep in ok], [prep.silhouette for _, prep in ok])
            found = [self.records.find(item) for item, _ in ok]  # here: this thread holds the catalogs' connections
            exports = [(item, self.pool.submit(self._export_one, item, prep, dec.select(k), found[k]))
                       for k, (item, prep) in enumerate(ok)]
        self.finish()
        for prep in prepared:
            if isinstance(prep, Failure):
                self.summary.failures.append(prep)
                self.say(prep.line())
        self.exporting, self.size_of_exporting = exports, len(batch)

    def finish(self) -> None:
        """Wait for the batch being exported and record its outcomes."""
        for item, future in self.exporting:
            failure = future.result()
            if failure is None:
                self.summary.done.append(item.name)
            else:
                self.summary.failures.append(failure)
                self.say(failure.line())
        if self.bar is not None:
            self.bar.update(self.size_of_exporting)
        self.exporting, self.size_of_exporting = [], 0

    def _export_one(self, item: InputItem, prep: Prepared, dec: Decomposition,
                    found: ObjectRecord) -> Failure | None:
        """Refine and export one predicted object (batch of one `dec`); an error costs this object only."""
        predictor = self.predictor
        assert prep.photo_image is not None  # Prepared sets it
        try:
            refined, report = predictor.refine_object(dec, prep.image, prep.photo_image, prep.photo_silhouette)
            if report.status == "fallback":
                self.say(f"{item.image_path}: refinement fell back to the network's prediction: {report.reason}")
            with torch.inference_mode():  # no gradients from here on, and less bookkeeping per operation
                state = full_resolution_state(refined, prep, predictor.setup, predictor.albedo)
                export_object(self.options.out / item.name, item, prep, state, predictor.setup, predictor.version,
                              self.envs, self.options.export, predictor.albedo, predictor.pitch, report.record(),
                              found.size, description=found.description)
        except ITEM_ERRORS as e:
            return Failure(str(item.image_path), f"export failed ({type(e).__name__}: {e})")
        return None


def _prepare_one(item: InputItem, size: int, options: DerenderOptions) -> Prepared | Failure:
    """Read and crop one input (decoding and detection release the GIL)."""
    try:
        return prepare(item, size, options.crop, options.backdrop, options.resolution)
    except RadarError as e:
        return Failure(str(item.image_path), str(e).removeprefix(f"{item.image_path}: "))


def _run_views(item: InputItem, predictor: Predictor, options: DerenderOptions, envs: dict[str, np.ndarray],
               summary: BatchSummary, say: Callable[[str], None], records: RecordFinder) -> None:
    """One object photographed from several sides (derender.multiview.driver); its unreadable photos are recorded
    as failures, the object is done with the others."""
    try:
        with torch_threads(EXPORT_THREADS):
            left_out = derender_views(item, predictor, options.out, options.crop, options.backdrop,
                                      options.resolution, envs, options.export, say, records.find(item),
                                      options.workers)
    except ITEM_ERRORS as e:
        failure = Failure(str(item.image_path.parent), f"multi-view object failed ({type(e).__name__}: {e})")
        summary.failures.append(failure)
        say(failure.line())
        return
    summary.failures.extend(left_out)
    summary.done.append(item.name)
