"""CUDA correctness of the model and the training step (skipped without CUDA): the same weights and batch give the
same prediction and the same loss terms on CPU and GPU, and a few GPU steps lower the loss like CPU ones do."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import torch

from radar_cli import distributed as D
from radar_cli.derender.run.predictor import Predictor
from radar_cli.model.config import RunConfig
from radar_cli.train.benchmark import elliptic_batch
from radar_cli.train.step import generator_losses
from radar_cli.train.trainer import build_state, train_step

from .conftest import tiny_config

pytestmark = [pytest.mark.gpu, pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")]


@pytest.fixture(autouse=True)
def full_float32():
    """No TF32 in cuDNN convolutions or matrix products, so CPU and GPU differ only by float32 rounding."""
    saved = torch.backends.cudnn.allow_tf32, torch.backends.cuda.matmul.allow_tf32
    torch.backends.cudnn.allow_tf32 = torch.backends.cuda.matmul.allow_tf32 = False
    yield
    torch.backends.cudnn.allow_tf32, torch.backends.cuda.matmul.allow_tf32 = saved


def _config() -> RunConfig:
    cfg = tiny_config()
    render = dataclasses.replace(cfg.model.render, image_size=64)
    return dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, render=render))


def test_losses_agree_on_cpu_and_cuda():
    config = _config()
    terms = {}
    for name in ("cpu", "cuda"):
        dev = torch.device(name)
        state = build_state(config, dev)  # seeded: identical weights on both devices
        batch = elliptic_batch(config, 4, dev)
        pred = state.model(batch.image)
        terms[name], _ = generator_losses(pred, batch, config, state.disc)
        terms[name]["radius"] = pred.radius.sum()
        terms[name]["albedo"] = pred.albedo.abs().sum()
    assert terms["cpu"].keys() == terms["cuda"].keys()
    for key, cpu in terms["cpu"].items():
        gpu = terms["cuda"][key].cpu()
        assert torch.isfinite(gpu), key
        assert abs(float(cpu - gpu)) <= 1e-3 * max(1.0, abs(float(cpu))), (key, float(cpu), float(gpu))


def test_cuda_steps_lower_the_loss():
    config = _config()
    dev = torch.device("cuda")
    state = build_state(config, dev)
    batch = elliptic_batch(config, 4, dev)
    info = D.DistInfo(0, 1, dev)
    totals = [train_step(state, state.model, state.disc, batch, config, info, Path("."))[0]["total"] for _ in range(12)]
    assert all(np.isfinite(totals))
    assert min(totals[-3:]) < totals[0]


def test_bundled_model_predicts_the_same_on_cuda():
    rng = np.random.default_rng(0)
    cpu = Predictor.from_checkpoint(None, "cpu")
    gpu = Predictor.from_checkpoint(None, "cuda")
    size = cpu.setup.render.image_size
    images = [rng.integers(0, 256, (size, size, 3), dtype=np.uint8) for _ in range(3)]
    a, b = cpu.predict(images), gpu.predict(images)
    for x, y in zip(a.tensors(), b.tensors()):
        assert torch.allclose(x, y, atol=1e-3, rtol=1e-3)
