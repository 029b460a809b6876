"""`radar eval-catalog`: result folders matched to a catalogue table by object id, the fitted ratios and the profile
error against a digitised drawing, on generated fixtures (fake result folders and a table)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from radar_cli.cli import cli as cli_main
from radar_cli.evaluate import profiles as P
from radar_cli.evaluate.catalogue import evaluate_catalogue
from radar_cli.sizes import read_size_table

TABLE = "object\taccession\theight_cm\trim_cm\tbody_cm\tfoot_cm\n" \
        "AB1\tA.B.1\t40\t30\t32\t16\n" \
        "AB12\tA.B.12\t20\t10\t20\t10\n" \
        "FRAG\tF\t\t\t\t\n"


def _profile(rows: int = 64) -> np.ndarray:
    """Radius column top to bottom: rim 0.6 (top 2 rows), body 0.64 at mid-height, foot 0.32 (bottom 6 rows)."""
    t = np.linspace(0.0, 1.0, rows)  # 0 = top
    r = 0.35 + 0.29 * np.sin(np.pi * t)
    r[:2] = 0.6
    r[-6:] = 0.32
    return r


def _result(root, name: str, radius: np.ndarray, half_height: float, pitch: float = 2.0, status: str = "ok"):
    folder = root / name
    folder.mkdir(parents=True)
    record = {"pitch": pitch, "height": half_height, "radius": radius.tolist(), "quality": {"status": status}}
    (folder / "material.json").write_text(json.dumps(record))


def test_match_takes_the_longest_id(tmp_path):
    (tmp_path / "objects.tsv").write_text(TABLE)
    table = read_size_table(tmp_path / "objects.tsv")
    assert table.match("AB12_front") == ("ab12", "front")
    assert table.match("AB1_side-ab") == ("ab1", "side-ab")
    assert table.match("ab1") == ("ab1", "")
    assert table.match("AB123_front") is None and table.match("FRAG_front") is None  # no height: left out


def test_ratios_and_errors_against_the_table(tmp_path):
    (tmp_path / "objects.tsv").write_text(TABLE)
    radius = _profile()
    # half-height 0.8 r_max: height 1.6, body 2 x 0.64 = 1.28 -> 0.8, the catalogue's 32 / 40
    _result(tmp_path / "res", "AB1_front", radius, 0.8)
    _result(tmp_path / "res", "XY9_back", radius, 0.8)
    report = evaluate_catalogue(tmp_path / "res", tmp_path / "objects.tsv")
    assert report.unmatched_results == ["XY9_back"] and report.unmatched_rows == ["ab12"]
    (record,) = report.records
    assert record.object_id == "AB1" and record.view == "front" and record.status == "ok"
    body_height, rim_body, foot_body = record.fitted
    assert body_height == pytest.approx(0.8, abs=0.01)
    assert rim_body == pytest.approx(0.6 / 0.64, abs=0.01)
    assert foot_body == pytest.approx(0.32 / 0.64, abs=0.01)
    assert record.error_pct[0] == pytest.approx(0.0, abs=1.5)
    assert record.error_pct[1] == pytest.approx(abs(0.6 / 0.64 - 30 / 32) / (30 / 32) * 100, abs=1.0)


def test_profile_error_against_a_drawing(tmp_path):
    radius = _profile(128)
    t, r = P.profile_from_material(radius.tolist(), 0.8)
    same = "height_cm,radius_cm\n" + "\n".join(f"{h * 40:.3f},{v * 40:.4f}" for h, v in zip(t, r))
    assert P.profile_error((t, r), P.read_drawn_profile(same))["worst"] < 0.05
    wider = "height_cm,radius_cm\n" + "\n".join(f"{h * 40:.3f},{v * 40 + 0.8:.4f}" for h, v in zip(t, r))
    error = P.profile_error((t, r), P.read_drawn_profile(wider))  # 0.8 cm of 40: 2% of the height everywhere
    for key in ("mean", "worst", "neck", "shoulder", "foot"):
        assert error[key] == pytest.approx(2.0, abs=0.05)


def test_cli_reports_rows_and_exits_1_when_nothing_matches(tmp_path):
    (tmp_path / "objects.tsv").write_text(TABLE)
    (tmp_path / "drawings").mkdir()
    _result(tmp_path / "res", "AB12_side-ab", _profile(), 0.5)
    t, r = P.profile_from_material(_profile().tolist(), 0.5)
    (tmp_path / "drawings" / "AB12.csv").write_text(
        "height_cm,radius_cm\n" + "\n".join(f"{h * 20:.3f},{v * 20:.4f}" for h, v in zip(t, r)))
    runner = CliRunner()
    out = runner.invoke(cli_main, ["eval-catalog", str(tmp_path / "res"), "--dimensions", str(tmp_path / "objects.tsv"),
                                   "--drawings", str(tmp_path / "drawings"), "--json", str(tmp_path / "r.json")])
    assert out.exit_code == 0, out.output
    assert "AB12_side-ab" in out.output and "eval-catalog: 1 results of 1 objects" in out.output
    saved = json.loads((tmp_path / "r.json").read_text())
    assert saved["results"][0]["profile"]["mean"] < 0.1
    _result(tmp_path / "other", "ZZ_front", _profile(), 0.5)
    out = runner.invoke(cli_main, ["eval-catalog", str(tmp_path / "other"), "--dimensions",
                                   str(tmp_path / "objects.tsv")])
    assert out.exit_code == 1 and "no result" in out.output
