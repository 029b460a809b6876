"""The quality record: its status rules, summary.csv's columns and order, and what `radar derender` writes for a
tight crop of a vase with handles."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from radar_cli.cli import cli
from radar_cli.derender.export.quality import judge
from radar_cli.derender.present.report import by_status, write_summary
from radar_cli.derender.run.predictor import ASSETS
from radar_cli.results import APPENDAGES_FILE, MATERIAL_FILE

GOOD = {"silhouette_iou": 0.93, "symmetry": 0.95, "recon_psnr": 20.0, "appendage_fraction": 0.05,
        "outline_support": 0.95, "cut_edges": [], "frame_coverage": 0.3, "silhouette_area": 0.3}


def test_a_good_result_is_ok() -> None:
    assert judge(GOOD) == ("ok", [])


@pytest.mark.parametrize("change, status, words", [
    ({"frame_coverage": 0.97}, "failed", "covers 97%"),
    ({"silhouette_iou": 0.4}, "failed", "does not fit"),
    ({"silhouette_area": 0.01}, "failed", "only 1.0%"),
    ({"silhouette_iou": 0.7}, "review", "loosely"),
    ({"symmetry": 0.6}, "review", "symmetric"),
    ({"appendage_fraction": 0.3}, "review", "appendage"),
    ({"recon_psnr": 8.0}, "review", "far from the photo"),
    ({"cut_edges": ["top", "bottom", "left"]}, "review", "3 photo edges"),
    ({"outline_support": 0.4}, "review", "off the object's edge"),
    ({"silhouette_iou": None, "symmetry": None, "silhouette_area": None}, "review", "no silhouette"),
])
def test_each_score_can_demote(change: dict, status: str, words: str) -> None:
    got, reasons = judge({**GOOD, **change})
    assert got == status and any(words in r for r in reasons), reasons


def test_whole_frame_with_a_good_fit_is_still_failed() -> None:
    """A box-shaped silhouette over the whole photo fits a cylinder perfectly: coverage alone must fail it."""
    assert judge({**GOOD, "frame_coverage": 1.0, "silhouette_iou": 0.99})[0] == "failed"


def test_summary_lists_worst_first(tmp_path: Path) -> None:
    records = [(name, {"pitch": 1.0, "quality": {**GOOD, "status": status, "reasons": reasons}})
               for name, status, reasons in (("a", "ok", []), ("b", "failed", ["x"]), ("c", "review", ["y", "z"]))]
    write_summary(tmp_path, by_status(records))
    rows = list(csv.DictReader((tmp_path / "summary.csv").open()))
    assert [r["object"] for r in rows] == ["b", "c", "a"]
    assert rows[1]["status"] == "review" and rows[1]["reason"] == "y; z" and rows[0]["silhouette_iou"] == "0.93"
    assert rows[0]["outline_support"] == "0.95"


@pytest.mark.skipif(not any(ASSETS.glob("*.safetensors")), reason="no bundled model")
def test_derender_records_quality_and_appendages(tmp_path: Path) -> None:
    from radar_cli.masks.synthetic import composite, render_vases
    from radar_cli.masks.variants import make_variant, with_handles

    vases, alpha, masks = render_vases(1, 160, seed=9)
    rng = np.random.default_rng(1)
    photo, truth = composite(vases[0], alpha[0], masks[0], "gradient", rng, shape=(360, 300))
    photo, handled = with_handles(photo, truth, rng)
    tight = make_variant("tight", photo, handled, rng)
    Image.fromarray(tight.image).save(tmp_path / "amphora.png")
    Image.new("RGB", (200, 160), (128, 128, 128)).save(tmp_path / "blank.png")
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["derender", str(tmp_path), "--out", str(out), "--views", "0"])
    assert result.exit_code != 0 and "blank.png" in result.output  # the flat photo fails, the rest goes on
    record = json.loads((out / "amphora" / MATERIAL_FILE).read_text())
    quality = record["quality"]
    assert quality["status"] in ("ok", "review") and {"top", "bottom"} <= set(quality["cut_edges"])
    assert quality["appendage_fraction"] > 0.03 and quality["frame_coverage"] < 0.9
    assert quality["outline_support"] > 0.8
    appendages = np.asarray(Image.open(out / "amphora" / APPENDAGES_FILE)) > 127
    assert appendages.any() and appendages.shape == (record["resolution"],) * 2  # at the output side
    row = next(csv.DictReader((out / "summary.csv").open()))
    assert row["object"] == "amphora" and row["status"] == quality["status"] and row["cut_edges"] == "top bottom"
