"""`radar derender --device cuda` with the bundled model, the refinement and a multi-view object, against the
same run on the CPU (skipped without CUDA): every object done on both, with the same refinement outcome and about
the same pose. The fits run on the CPU either way; only the networks run on the GPU."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import torch

from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor

from .conftest import write_photo

pytestmark = [pytest.mark.gpu, pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")]


def test_cuda_derenders_what_the_cpu_does(tmp_path: Path) -> None:
    for k in range(2):
        write_photo(tmp_path / "in" / f"vase_{k}.png", k, (200, 200))
    for view in ("front", "side", "back"):
        write_photo(tmp_path / "in" / "pot" / f"{view}.png", 7, (200, 200))
    records = {}
    for device in ("cpu", "cuda"):
        predictor = Predictor.from_checkpoint(None, device, refine="full")
        out = tmp_path / device
        summary = derender([tmp_path / "in"], predictor, DerenderOptions(
            out=out, resolution=160, export=ExportConfig(views=2, view_size=32)), say=lambda line: None)
        assert not summary.failures, [f.line() for f in summary.failures]
        assert sorted(summary.done) == ["pot", "vase_0", "vase_1"]
        records[device] = {name: json.loads((out / name / "material.json").read_text()) for name in summary.done}
    for name, cpu in records["cpu"].items():
        gpu = records["cuda"][name]
        assert abs(cpu["pitch"] - gpu["pitch"]) <= 1.0, (name, cpu["pitch"], gpu["pitch"])
        if "refine" in cpu:
            assert cpu["refine"]["status"] == gpu["refine"]["status"], name
