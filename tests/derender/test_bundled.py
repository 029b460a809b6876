"""The bundled model de-renders the repository's examples with no flags (what `make demo` runs)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.derender.run.predictor import ASSETS
from radar_cli.results import list_results

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
no_model = pytest.mark.skipif(not any(ASSETS.glob("*.safetensors")), reason="no bundled model")


@no_model
@pytest.mark.skipif(not EXAMPLES.is_dir(), reason="no examples")
def test_examples_with_the_bundled_model(tmp_path: Path) -> None:
    for name in sorted(p.name for p in EXAMPLES.glob("*.png"))[:2]:
        shutil.copy(EXAMPLES / name, tmp_path / name)
    result = CliRunner().invoke(cli, ["derender", str(tmp_path), "--out", str(tmp_path / "out"), "--views", "2"])
    assert result.exit_code == 0, result.output
    assert "2 de-rendered" in result.stdout and str(tmp_path / "out" / "index.html") in result.stdout
    assert all(p.is_complete() for p in list_results(tmp_path / "out")) and len(list_results(tmp_path / "out")) == 2


@no_model
def test_divided_albedo_beats_the_network_albedo(tmp_path: Path) -> None:
    """On synthetic vases the bundled model's albedo is closer to the truth with the shading divided out (the 460
    test vases: docs/accuracy.md); here on 8."""
    synth = pytest.importorskip("radar_cli.synth.generator")
    scorer = pytest.importorskip("radar_cli.evaluate.scorer")
    synth.generate(tmp_path / "data", {"test": 8}, synth.SynthConfig(size=64, seed=11), workers=1, progress=False)
    errors = {}
    for albedo in ("network", "divided"):
        out = tmp_path / albedo
        result = CliRunner().invoke(cli, ["derender", str(tmp_path / "data"), "--out", str(out), "--views", "0",
                                          "--albedo", albedo])
        assert result.exit_code == 0, result.output
        scores = scorer.evaluate(out, tmp_path / "data", progress=False).scores
        errors[albedo] = sum(s.albedo for s in scores) / len(scores)
    assert errors["divided"] < 0.85 * errors["network"], errors
