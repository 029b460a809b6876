"""The refinement's Adam gives torch.optim.Adam's bits, step for step, without importing torch._dynamo."""

from __future__ import annotations

import subprocess
import sys

import torch

from radar_cli.derender.refine.adam import Adam


def _run(make_optimizer, steps: int = 40) -> list[torch.Tensor]:
    gen = torch.Generator().manual_seed(5)
    a = torch.randn(7, 3, dtype=torch.float64, generator=gen).requires_grad_(True)
    b = torch.randn(3, dtype=torch.float64, generator=gen).requires_grad_(True)
    target = torch.randn(7, 3, dtype=torch.float64, generator=gen)
    opt = make_optimizer([a, b])
    for _ in range(steps):
        opt.zero_grad()
        loss = ((torch.tanh(a * b) - target) ** 2).sum() + (a.abs() ** 1.5).sum()
        loss.backward()
        opt.step()
    return [a.detach(), b.detach()]


def test_the_same_bits_as_torch_adam() -> None:
    ours = _run(lambda p: Adam(p, lr=0.05))
    theirs = _run(lambda p: torch.optim.Adam(p, lr=0.05))
    assert all(torch.equal(x, y) for x, y in zip(ours, theirs))
    assert not torch.equal(ours[0], _run(lambda p: Adam(p, lr=0.05), steps=39)[0])  # the steps did move it


def test_no_dynamo_import() -> None:
    code = ("import sys, torch; from radar_cli.derender.refine.adam import Adam; x = torch.ones(2, requires_grad=True);"
            "o = Adam([x], 0.1); x.sum().backward(); o.step(); print('torch._dynamo' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
