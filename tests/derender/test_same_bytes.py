"""The same photo gives the same bytes however the run was cut: whatever the batch size and worker count, and
when a killed run is resumed. The bundled model (real convolutions, whose sums depend on the batch they run in)
on tiny generated photos."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import torch

from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor

from .conftest import vase_photo, write_photo
from .test_shard import object_files, summary_objects

REPO = Path(__file__).resolve().parents[2]
N_INPUTS = 6
SIDE = 96  # above the bundled model's 64 px, so each object is refined at the output resolution


@pytest.fixture(scope="module")
def photos(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("photos")
    for k in range(N_INPUTS):
        write_photo(folder / f"vase_{k:02d}.png", 10 + k, (SIDE, 80))
    return folder


@pytest.fixture(scope="module")
def bundled() -> Predictor:
    return Predictor.from_checkpoint(None, "cpu", refine="none")


def test_a_photo_predicts_the_same_numbers_in_any_batch(bundled: Predictor) -> None:
    images = [vase_photo(k, (64, 64)) for k in range(5)]
    masks = [im.min(axis=-1) < 200 for im in images]
    together = bundled.predict(images, masks)
    for k in range(len(images)):
        alone = bundled.predict(images[k : k + 1], masks[k : k + 1])
        for a, b in zip(alone.tensors(), together.select(k).tensors()):
            assert torch.equal(a, b)


def _same_bytes_for_any_cut(photos: Path, predictor: Predictor, out: Path) -> None:
    """De-render `photos` with batches of 1 on one worker and with batches of 8 on two: every object file the
    same bytes."""
    export = ExportConfig(views=2, view_size=32)
    runs = {}
    for batch_size, workers in ((1, 1), (8, 2)):
        options = DerenderOptions(out=out / f"b{batch_size}w{workers}", batch_size=batch_size, workers=workers,
                                  export=export, resolution=SIDE)
        summary = derender([photos], predictor, options, say=lambda _: None)
        assert not summary.failures
        runs[batch_size] = object_files(options.out)
    assert len(runs[1]) > 10 * len(summary.done) and runs[1].keys() == runs[8].keys()
    assert [name for name in runs[1] if runs[1][name] != runs[8][name]] == []


def test_batch_size_and_workers_do_not_change_a_byte(photos: Path, bundled: Predictor, tmp_path: Path) -> None:
    _same_bytes_for_any_cut(photos, bundled, tmp_path)


@pytest.mark.slow
def test_the_same_with_the_refinement(tmp_path: Path) -> None:
    for k in range(3):
        write_photo(tmp_path / "in" / f"vase_{k}.png", 20 + k, (SIDE, 80))
    _same_bytes_for_any_cut(tmp_path / "in", Predictor.from_checkpoint(None, "cpu", refine="full"), tmp_path)


def _command(photos: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "radar_cli", "derender", str(photos), "--out", str(out), "--device", "cpu",
            "--refine", "shape", "--resolution", str(SIDE), "--views", "2", "--view-size", "32"]


def _env() -> dict[str, str]:
    return dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=str(REPO))


@pytest.mark.slow
def test_killed_at_random_points_and_resumed_gives_the_same_bytes(tmp_path: Path) -> None:
    for k in range(2 * N_INPUTS):
        write_photo(tmp_path / "in" / f"vase_{k:02d}.png", 30 + k, (SIDE, 80))
    reference = tmp_path / "reference"
    done = subprocess.run(_command(tmp_path / "in", reference), env=_env(), capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    out, rng, kills = tmp_path / "out", random.Random(34), 0
    finished = lambda: len(list(out.glob("*/material.json")))  # noqa: E731
    for _attempt in range(3):  # killed after a random number of finished objects and a random extra wait
        target, extra = finished() + rng.randint(1, 2), rng.uniform(0.0, 0.3)
        run = subprocess.Popen(_command(tmp_path / "in", out), env=_env(), stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL, start_new_session=True)
        deadline = time.monotonic() + 300
        while run.poll() is None and time.monotonic() < deadline:
            if finished() >= target:
                time.sleep(extra)
                os.killpg(run.pid, signal.SIGKILL)
                kills += finished() < 2 * N_INPUTS
                break
            time.sleep(0.02)
        run.wait(timeout=60)
    assert kills >= 2, "the run finished before it could be killed twice"
    done = subprocess.run(_command(tmp_path / "in", out), env=_env(), capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert summary_objects(out) == summary_objects(reference)  # listed by quality status, then name
    assert sorted(summary_objects(out)) == [f"vase_{k:02d}" for k in range(2 * N_INPUTS)]
    expected = object_files(reference)
    assert [name for name, data in object_files(out).items() if expected.get(name) != data] == []
    assert object_files(out).keys() == expected.keys()
