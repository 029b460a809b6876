"""Running `radar derender` as one share of a collection: alone (`--shard K/N`, or the whole collection) or as
a rank under torchrun, where the ranks meet at the end and rank 0 writes the one report for all."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Callable

from radar_cli import distributed
from radar_cli.derender.present.report import write_report
from radar_cli.derender.run.batch import BatchSummary, DerenderOptions, collect, derender
from radar_cli.derender.run.predictor import Predictor
from radar_cli.derender.run.shard import Shard, read_share_failures
from radar_cli.errors import InputError


def derender_sharded(inputs: list[str | Path], load: Callable[[str], Predictor], options: DerenderOptions,
                     device: str, say: Callable[[str], None]) -> BatchSummary:
    """Run `radar derender` as one share of a collection.

    Under torchrun (WORLD_SIZE > 1) the rank is the share; ranks wait for each other at the end and rank 0 writes
    summary.csv, failures.csv and the gallery for all. Otherwise options.shard says the share (1/1: the whole
    collection) and the share writes the report from every complete folder and every share's failures found.

    Args:
        inputs: image files and folders, the same on every share.
        load: device name -> Predictor (each rank loads the model on its own device).
        options: the run's options; options.shard must be 0/1 under torchrun.
        device: --device (under torchrun with CUDA each rank takes its LOCAL_RANK's GPU).
        say: where one-line messages go.

    Returns:
        This share's BatchSummary (its `index` set on the share that wrote the report).
    """
    collect(inputs, options)  # a refused --out or inputs without a photo end the run before the model loads
    info = distributed.setup(device)
    try:
        if info.enabled and options.shard.enabled:
            raise InputError("--shard cannot be combined with torchrun (each rank takes its share already)")
        shard = Shard(info.rank, info.world) if info.enabled else options.shard
        options = dataclasses.replace(options, shard=shard)
        summary = derender(inputs, load(str(info.device)), options, say, report=not info.enabled)
        distributed.barrier(info)  # every share's folders and failure list are written
        if info.enabled:
            summary = _whole_run(summary, info)
        if info.enabled and info.is_main:
            summary.index = write_report(options.out, read_share_failures(options.out, shard.count))
        distributed.barrier(info)  # no rank exits (and has torchrun stop the others) before the report is done
        return summary
    finally:
        distributed.teardown(info)


def _whole_run(summary: BatchSummary, info: distributed.DistInfo) -> BatchSummary:
    """Under torchrun: on rank 0 the summary of every rank together (the one the command prints), on the other
    ranks theirs with `printed` off."""
    import torch.distributed as dist

    shares: list[BatchSummary | None] = [None] * info.world
    dist.all_gather_object(shares, summary)
    if not info.is_main:
        return dataclasses.replace(summary, printed=False)
    whole = dataclasses.replace(summary, done=[], skipped=[], failures=[])
    for share in shares:
        assert share is not None
        whole.done += share.done
        whole.skipped += share.skipped
        whole.failures += share.failures
    whole.seconds = max(share.seconds for share in shares if share is not None)
    return whole
