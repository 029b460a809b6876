"""DistributedDataParallel: 2 CPU processes on gloo under torchrun end a few steps with identical weights (every
loss term on, both cycles included: their second passes through f_S, f_L and f_A run outside DDP's forward)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import torch
from safetensors.torch import load_file

from radar_cli.train.data import StepBatchSampler
from radar_cli.train.trainer import build_state

from .conftest import tiny_config

REPO = Path(__file__).resolve().parents[2]

SCRIPT = textwrap.dedent('''
    import dataclasses, os, sys
    import torch
    from safetensors.torch import save_file
    sys.path.insert(0, sys.argv[3])
    from conftest import tiny_config
    from radar_cli.train.trainer import train

    torch.set_num_threads(1)
    config = tiny_config(iterations=3)
    cycles = dataclasses.replace(config.loss, cycle_weight=1.0, light_cycle_weight=1.0)
    config = dataclasses.replace(config, loss=cycles)
    rank = os.environ["RANK"]
    budget = None  # the ranks of a real run share --max-minutes; here rank 1's clock runs out first
    if sys.argv[4] == "rank1-out-of-time":
        budget = 1e-9 if rank == "1" else 60.0
    summary = train(config, sys.argv[1], sys.argv[2], progress=False, max_minutes=budget)
    assert summary.end == (3 if budget is None else 1), summary.end
    state = {k: v.contiguous() for k, v in summary.state.model.state_dict().items()}
    state.update({"disc." + k: v.contiguous() for k, v in summary.state.disc.state_dict().items()})
    save_file(state, os.path.join(sys.argv[2], f"rank{rank}.safetensors"))
''')


def test_sampler_splits_the_global_batch_across_ranks():
    whole = list(StepBatchSampler(10, 4, seed=3, start=0, end=5))
    ranks = [list(StepBatchSampler(10, 4, seed=3, start=0, end=5, rank=r, world=2)) for r in range(2)]
    for step in range(5):
        assert sorted(ranks[0][step] + ranks[1][step]) == sorted(whole[step])
    assert list(StepBatchSampler(10, 4, seed=3, start=2, end=5)) == whole[2:]
    epoch0 = [i for b in whole[:2] for i in b] + whole[2][:2]
    assert sorted(epoch0) == list(range(10))  # every sample once per epoch


def _torchrun(vases32, run: Path, mode: str) -> None:
    script = run.parent / "ddp_train.py"
    script.write_text(SCRIPT)
    env = dict(os.environ, OMP_NUM_THREADS="1", PYTHONPATH=str(REPO), TMPDIR=str(run.parent))  # torchrun's logs
    cmd = [sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node=2", str(script),
           str(vases32), str(run), str(Path(__file__).parent), mode]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]


@pytest.mark.slow
def test_ddp_two_gloo_processes_end_with_identical_weights(vases32, tmp_path):
    run = tmp_path / "run"
    _torchrun(vases32, run, "full")
    a, b = load_file(str(run / "rank0.safetensors")), load_file(str(run / "rank1.safetensors"))
    assert a.keys() == b.keys()
    for k in a:
        assert torch.equal(a[k], b[k]), k
    init = build_state(tiny_config(), torch.device("cpu")).model.state_dict()
    assert any(not torch.equal(init[k], a["" + k]) for k in init)  # the ranks trained, in step
    assert len(list((run / "checkpoints").iterdir())) == 2  # only rank 0 writes checkpoints


@pytest.mark.slow
def test_ddp_ranks_stop_together_when_one_runs_out_of_time(vases32, tmp_path):
    run = tmp_path / "run"
    _torchrun(vases32, run, "rank1-out-of-time")  # the script asserts both end at step 1
    assert [p.name for p in (run / "checkpoints").iterdir()] == ["step_0000001.safetensors"]
