"""`radar eval` on tiny synthetic sets: truth scores 0, known perturbations, bad input, mismatched sets, CLI."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.evaluate.from_truth import Perturbation, results_from_synth
from radar_cli.evaluate.scorer import (
    PAPER_TABLE2,
    SampleScore,
    constant_baseline,
    constant_env_errors,
    evaluate,
    markdown_table,
    pitch_calibration,
    report_json,
)
from radar_cli.results import ResultPaths
from radar_cli.synth.generator import SynthConfig, generate


@pytest.fixture(scope="module")
def synth_set(tmp_path_factory):
    root = tmp_path_factory.mktemp("syn")
    generate(root, {"test": 3}, SynthConfig(size=32, tex_size=16, shading_size=8), progress=False)
    return root


def test_ground_truth_against_itself_scores_zero(synth_set, tmp_path):
    results_from_synth(synth_set, tmp_path)
    report = evaluate(tmp_path, synth_set, progress=False)
    assert len(report.scores) == 3 and report.skipped == 0 and not report.truth_without_results
    summary = report.summary()
    for key in ("pitch", "normal", "albedo", "alpha", "rho", "env"):
        assert summary[key]["mean"] == pytest.approx(0.0, abs=1e-9), key
    # the no-decomposition bound (input image taken as albedo) is clearly worse than the truth
    assert summary["albedo_no_decomposition"]["mean"] > 1e-3
    assert all(s.albedo_no_decomposition > 0 for s in report.scores)


def test_known_perturbations_give_the_expected_errors(synth_set, tmp_path):
    perturb = Perturbation(pitch_offset=1.5, alpha_offset=-4.0, rho_offset=0.25, albedo_gain=0.5, env_gain=7.0)
    results_from_synth(synth_set, tmp_path, perturb=perturb)
    summary = evaluate(tmp_path, synth_set, progress=False).summary()
    assert summary["pitch"]["mean"] == pytest.approx(1.5) and summary["pitch"]["std"] == pytest.approx(0, abs=1e-9)
    assert summary["pitch"]["rmse"] == pytest.approx(1.5)
    assert summary["alpha"]["mean"] == pytest.approx(4.0)
    assert summary["rho"]["mean"] == pytest.approx(0.25)
    assert summary["env"]["mean"] == pytest.approx(0.0, abs=1e-9)  # scale only
    assert summary["albedo"]["mean"] < 1e-4  # scale only, up to 8-bit rounding
    assert summary["normal"]["mean"] == pytest.approx(0.0, abs=1e-9)


def test_bad_items_are_named_and_the_rest_scored(synth_set, tmp_path):
    results_from_synth(synth_set, tmp_path)
    (tmp_path / "000000" / "env_map.npy").unlink()
    (tmp_path / "000001" / "material.json").write_text(json.dumps({"pitch": "high", "alpha": 3, "rho": 0.5}))
    shutil.copytree(tmp_path / "000002", tmp_path / "stray")
    report = evaluate(tmp_path, synth_set, progress=False)
    assert [s.id for s in report.scores] == ["000002"]
    problems = dict(report.problems)
    assert "env_map.npy: no such file" in problems["000000"]
    assert "material.json: 'pitch' must be a finite number" in problems["000001"]
    assert report.results_without_truth == ["stray"] and report.skipped == 3


def test_non_overlapping_masks_and_nan_env_are_problems(synth_set, tmp_path):
    results_from_synth(synth_set, tmp_path)
    from radar_cli.fileio import write_image

    write_image(ResultPaths(tmp_path / "000000").mask_front, np.zeros((32, 32), np.uint8))
    np.save(tmp_path / "000001" / "env_map.npy", np.full((16, 48), np.nan, np.float32))
    report = evaluate(tmp_path, synth_set, progress=False)
    problems = dict(report.problems)
    assert "does not overlap" in problems["000000"] and "NaN" in problems["000001"]


def test_table_lists_ours_bound_and_paper(synth_set, tmp_path):
    results_from_synth(synth_set, tmp_path)
    report = evaluate(tmp_path, synth_set, progress=False)
    table = markdown_table(report)
    assert table.count("\n| ") == 6 and "| Albedo si-MSE (x 1e-2) | 0.00 ± 0.00 |" in table
    assert "3.08 ± 2.39" in table and "0.71 ± 0.92" in table and "5.91 ± 0.56" in table
    data = json.loads(json.dumps(report_json(report)))
    assert len(data["samples"]) == 3 and data["paper_table2"]["Ours full"]["pitch"] == [0.43, 0.40]
    assert set(PAPER_TABLE2) == {"Ours full", "No decomposition", "Supervised"}


def test_cli_eval_exit_codes_and_json(synth_set, tmp_path):
    pred = tmp_path / "pred"
    results_from_synth(synth_set, pred)
    out_json = tmp_path / "scores.json"
    ok = CliRunner().invoke(cli, ["eval", "--pred", str(pred), "--gt", str(synth_set), "--json", str(out_json)])
    assert ok.exit_code == 0, ok.output
    assert "3 scored, 0 skipped" in ok.output and json.loads(out_json.read_text())["summary"]["pitch"]["n"] == 3
    shutil.rmtree(pred / "000001")
    missing = CliRunner().invoke(cli, ["eval", "--pred", str(pred), "--gt", str(synth_set)])
    assert missing.exit_code == 1 and "000001" in missing.output
    subset = CliRunner().invoke(cli, ["eval", "--pred", str(pred), "--gt", str(synth_set), "--allow-missing"])
    assert subset.exit_code == 0
    (pred / "000002" / "normal_rendered.png").write_bytes(b"garbage")
    bad = CliRunner().invoke(cli, ["eval", "--pred", str(pred), "--gt", str(synth_set), "--allow-missing"])
    assert bad.exit_code == 1 and "skipped 000002" in bad.output and "normal_rendered.png" in bad.output
    gone = CliRunner().invoke(cli, ["eval", "--pred", str(tmp_path / "nope"), "--gt", str(synth_set)])
    assert gone.exit_code == 2 and "no such results folder" in gone.output


def test_pitch_calibration_slope_and_correlation():
    true = [0.0, 5.0, 10.0, 15.0, 20.0]
    calibrated = pitch_calibration([t + 1.5 for t in true], true)  # an offset keeps slope and correlation at 1
    assert calibrated["slope"] == pytest.approx(1.0) and calibrated["correlation"] == pytest.approx(1.0)
    collapsed = pitch_calibration([10.0] * 5, true)  # always the mean pitch
    assert collapsed == {"slope": 0.0, "correlation": 0.0}
    # half as steep, hand computed: pred = 10 + (t - 10) / 2
    assert pitch_calibration([5.0, 7.5, 10.0, 12.5, 15.0], true)["slope"] == pytest.approx(0.5)
    assert np.isnan(pitch_calibration([1.0], [2.0])["slope"])


def test_table_reports_pitch_calibration(synth_set, tmp_path):
    perturb = Perturbation(pitch_offset=1.5)
    results_from_synth(synth_set, tmp_path, perturb=perturb)
    report = evaluate(tmp_path, synth_set, progress=False)
    assert report.summary()["pitch_calibration"]["slope"] == pytest.approx(1.0, abs=1e-6)
    assert "Pitch calibration (predicted vs true): slope 1.00, correlation 1.00" in markdown_table(report)


def _score(pitch: float, alpha: float, rho: float) -> SampleScore:
    return SampleScore(id="x", pitch=0.0, normal=0.0, albedo=0.0, alpha=0.0, rho=0.0, env=0.0,
                       albedo_no_decomposition=0.0, region_px=1, pitch_pred=0.0, pitch_true=pitch, alpha_true=alpha,
                       rho_true=rho)


def test_constant_baseline_hand_computed():
    # truths 2, 4, 12 -> median 4 -> errors 2, 0, 8: mean 10/3
    scores = [_score(2.0, 10.0, 0.1), _score(4.0, 100.0, 0.5), _score(12.0, 190.0, 0.6)]
    got = constant_baseline(scores, [0.5, 1.5])
    assert got["pitch"]["mean"] == pytest.approx(10.0 / 3.0)
    assert got["pitch"]["rmse"] == pytest.approx(np.sqrt((4.0 + 0.0 + 64.0) / 3.0))
    assert got["alpha"]["mean"] == pytest.approx(180.0 / 3.0)  # 90, 0, 90
    assert got["rho"]["mean"] == pytest.approx(0.5 / 3.0)  # 0.4, 0, 0.1
    assert got["env"]["mean"] == pytest.approx(1.0) and got["env"]["n"] == 2
    assert np.isnan(constant_baseline([], [])["pitch"]["mean"])


def test_constant_env_is_scale_invariant_and_zero_for_one_shape():
    lobe = np.zeros((4, 8))
    lobe[1, 3:5] = 1.0
    assert constant_env_errors([lobe, 2.0 * lobe, 0.5 * lobe]) == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    other = np.zeros((4, 8))
    other[2, 2:6] = 1.0
    errors = constant_env_errors([lobe, other])
    assert len(errors) == 2 and min(errors) > 0


def test_perfect_results_beat_the_constant_guess(synth_set, tmp_path):
    """The table's constant column is scored on the same objects: ground truth (0 everywhere) beats it."""
    results_from_synth(synth_set, tmp_path)
    report = evaluate(tmp_path, synth_set, progress=False)
    const = report.summary()["constant"]
    assert const["alpha"]["mean"] > 0 and const["rho"]["mean"] > 0 and const["env"]["mean"] > 0
    assert "Best constant (same objects)" in markdown_table(report)
