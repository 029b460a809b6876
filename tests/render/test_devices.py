"""Check 6 of issue 2: CPU and CUDA give the same renderings within 1e-4 (skipped without CUDA)."""

from __future__ import annotations

import pytest
import torch

from radar_cli.render.raycast import cast_rays
from radar_cli.render.scene import render_view, shade


@pytest.mark.gpu
@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")
def test_cpu_and_cuda_agree(random_sor):
    radius, height, pose = random_sor(4, seed=31, dtype=torch.float32)
    g = torch.Generator().manual_seed(32)
    albedo = torch.rand(4, 3, 32, 96, generator=g)
    env = torch.rand(4, 16, 48, generator=g)
    alpha, rho = torch.tensor([5.0, 20.0, 60.0, 150.0]), torch.tensor([0.2, 0.5, 0.8, 1.0])
    outputs = {}
    for dev in ("cpu", "cuda"):
        args = [t.to(dev) for t in (radius, height, pose)]
        hits = cast_rays(*args, 128)
        image, _ = render_view(*args, albedo.to(dev), env.to(dev), alpha.to(dev), rho.to(dev), 128)
        front = shade(*args, albedo[..., 32:64].to(dev), env.to(dev), alpha.to(dev), rho.to(dev))
        outputs[dev] = [hits.sil, hits.depth, hits.normal, image, front.texture]
    for a, b in zip(outputs["cpu"], outputs["cuda"]):
        assert (a - b.cpu()).abs().max() <= 1e-4
