"""Tasks spread over the calling process and spawned helpers (derender.run.processes), and `radar derender`'s
objects on worker processes: every task once, results in task order, a helper's death reported, and the same
bytes as one worker."""

from __future__ import annotations

import functools
import os
import time
from pathlib import Path

import pytest

from radar_cli.derender.run.processes import spread


@pytest.fixture
def tasks(monkeypatch):
    """The tasks' module, importable by a spawned helper."""
    monkeypatch.syspath_prepend(str(Path(__file__).parent))
    import process_tasks

    return process_tasks


def test_every_task_runs_once_and_results_come_in_task_order(tasks, tmp_path: Path) -> None:
    marker = tmp_path / "helper-started"

    def here(task: int) -> tuple[int, int]:
        if task == 0:  # held until the helper has taken a task, however slowly it starts
            deadline = time.monotonic() + 60
            while not marker.exists() and time.monotonic() < deadline:
                time.sleep(0.05)
        return tasks.square(task)

    seen: list[tuple[int, int]] = []
    results = spread(list(range(16)), here, functools.partial(tasks.square_worker, marker), 1, seen.append,
                     lambda task, why: (-1, 0))
    assert [value for value, _ in results] == [k * k for k in range(16)]
    assert sorted(value for value, _ in seen) == sorted(k * k for k in range(16))
    assert len({pid for _, pid in results}) == 2 and results[0][1] == os.getpid()  # both processes took tasks


def test_a_task_whose_helper_died_is_reported_lost_and_the_rest_are_done(tasks, tmp_path: Path) -> None:
    marker = tmp_path / "died"

    def here(task: str) -> str:
        if task == "slow":  # held until the helper has taken "die" and ended
            deadline = time.monotonic() + 60
            while not marker.exists() and time.monotonic() < deadline:
                time.sleep(0.05)
        return f"main {task}"

    results = spread(["slow", "die", "a", "b", "c"], here, functools.partial(tasks.dying_worker, marker), 1,
                     lambda result: None,
                     lambda task, why: f"lost {task}: {why}")
    assert results[0] == "main slow"
    assert results[1].startswith("lost die: its worker process ended: exit code 3")
    assert results[2:] == ["main a", "main b", "main c"]


def test_one_task_or_no_helper_runs_here(tasks, tmp_path: Path) -> None:
    none = lambda t, w: (-1, 0)  # noqa: E731
    setup = functools.partial(tasks.square_worker, tmp_path / "helper-started")
    assert spread([3], tasks.square, setup, 4, lambda r: None, none) == [(9, os.getpid())]
    assert spread([1, 2], tasks.square, setup, 0, lambda r: None, none) == [(1, os.getpid()), (4, os.getpid())]
    assert not (tmp_path / "helper-started").exists()


@pytest.mark.parametrize("workers", [2, 3])
def test_objects_on_worker_processes_are_the_same_bytes_and_bad_photos_are_recorded(tmp_path: Path,
                                                                                      workers: int) -> None:
    from radar_cli.derender.export.object_folder import ExportConfig
    from radar_cli.derender.run.batch import DerenderOptions, derender
    from radar_cli.derender.run.predictor import Predictor

    from .conftest import write_photo
    from .test_shard import object_files

    for k in range(5):
        write_photo(tmp_path / "in" / f"vase_{k}.png", 40 + k, (96, 80))
    (tmp_path / "in" / "broken.png").write_bytes(b"\x89PNG\r\n\x1a\n not an image")
    for view in ("front", "back", "side"):  # a multi-view object: one task, its unreadable photo recorded
        write_photo(tmp_path / "in" / "pot" / f"{view}.png", 3, (96, 80))
    (tmp_path / "in" / "pot" / "broken.jpg").write_bytes(b"not a jpeg")
    predictor = Predictor.from_checkpoint(None, "cpu", refine="none")
    runs, said = {}, []
    for processes in (False, True):
        options = DerenderOptions(out=tmp_path / f"p{processes}", workers=workers if processes else 1,
                                  processes=processes, export=ExportConfig(views=2, view_size=32), resolution=96)
        summary = derender([tmp_path / "in"], predictor, options, say=said.append)
        assert summary.done == [f"vase_{k}" for k in range(5)] + ["pot"]
        assert sorted(Path(f.source).name for f in summary.failures) == ["broken.jpg", "broken.png"]
        runs[processes] = object_files(options.out)
    assert len(runs[True]) > 50 and runs[True] == runs[False]
    for name in ("broken.png", "broken.jpg"):  # said once by each run, whichever process met it
        assert sum(name in line for line in said) == 2
