"""The bundled model de-renders the repository's examples with no flags (what `make demo` runs)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.derender.predictor import ASSETS
from radar_cli.results import list_results

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.skipif(not any(ASSETS.glob("*.safetensors")) or not EXAMPLES.is_dir(), reason="no bundled model")
def test_examples_with_the_bundled_model(tmp_path: Path) -> None:
    for name in sorted(p.name for p in EXAMPLES.glob("*.png"))[:2]:
        shutil.copy(EXAMPLES / name, tmp_path / name)
    result = CliRunner().invoke(cli, ["derender", str(tmp_path), "--out", str(tmp_path / "out"), "--views", "2"])
    assert result.exit_code == 0, result.output
    assert "2 de-rendered" in result.stdout and str(tmp_path / "out" / "index.html") in result.stdout
    assert all(p.is_complete() for p in list_results(tmp_path / "out")) and len(list_results(tmp_path / "out")) == 2
