"""`radar synth` end to end on tiny images: files and ground truth, determinism across workers, resume, CLI."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from radar_cli.cli import cli
from radar_cli.dataset import IMAGE_FILE, list_samples, read_sample
from radar_cli.errors import ConfigError
from radar_cli.fileio import read_image
from radar_cli.synth import layout
from radar_cli.synth.generator import SynthConfig, SynthSummary, generate, make_sample

TINY = SynthConfig(size=32, tex_size=16, shading_size=8)


def _bytes(root):
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_sample_has_every_ground_truth_file_and_consistent_maps(tmp_path):
    summary = generate(tmp_path, {"train": 2, "test": 1}, TINY, progress=False)
    assert summary.written == 3 and not summary.failed
    refs = list_samples(tmp_path, "train")
    assert [r.sample_id for r in refs] == ["000000", "000001"]
    folder = refs[0].folder
    assert sorted(p.name for p in folder.iterdir()) == sorted(layout.SAMPLE_FILES)
    image, mask = read_sample(refs[0])
    assert image.shape == (32, 32, 3) and 20 < mask.sum() < 32 * 32
    assert (image[~mask] == 255).all()  # plain white background off the object
    front = read_image(folder / layout.MASK_FRONT_FILE, "L") > 127
    assert front.sum() > 0 and not (front & ~mask).any()
    depth = np.load(folder / layout.DEPTH_FILE)
    assert depth.dtype == np.float32 and (depth[mask] > 4).all() and (depth[~mask] == 0).all()
    normal = read_image(folder / layout.NORMAL_RENDERED_FILE).astype(float) / 255 * 2 - 1
    assert np.abs(np.linalg.norm(normal[mask], axis=-1) - 1).max() < 0.05
    assert (normal[mask][:, 2] < 0.1).mean() > 0.9  # seen surfaces face the camera (-z)
    assert np.load(folder / layout.ENV_MAP_FILE).shape == (16, 48)
    albedo = read_image(folder / layout.ALBEDO_FILE)
    assert albedo.shape == (16, 48, 3)
    params = json.loads((folder / layout.PARAMS_FILE).read_text())
    assert len(params["radius"]) == 32 and len(params["lobes"]) == 3 and len(params["pose"]) == 4
    assert 1 <= params["alpha"] <= 196 and 0.1 <= params["rho"] <= 1
    assert json.loads((tmp_path / layout.SETTINGS_FILE).read_text())["size"] == 32


def test_same_seed_same_bytes_whatever_the_workers(tmp_path):
    generate(tmp_path / "a", {"train": 3}, TINY, workers=1, progress=False)
    generate(tmp_path / "b", {"train": 3}, TINY, workers=2, progress=False)
    a, b = _bytes(tmp_path / "a"), _bytes(tmp_path / "b")
    assert a.keys() == b.keys() and a == b
    generate(tmp_path / "c", {"train": 1}, SynthConfig(size=32, tex_size=16, shading_size=8, seed=1), progress=False)
    assert (tmp_path / "c/train/000000/image.png").read_bytes() != a["train/000000/image.png"]


def test_resume_skips_finished_and_redoes_unfinished(tmp_path):
    generate(tmp_path, {"train": 3}, TINY, progress=False)
    before = _bytes(tmp_path)
    # simulate a killed run: one sample lost its completion marker, one half-written temp folder remains
    (tmp_path / "train/000001" / layout.PARAMS_FILE).unlink()
    (tmp_path / ".partial/train-000002-1").mkdir(parents=True)
    summary = generate(tmp_path, {"train": 3}, TINY, progress=False)
    assert (summary.written, summary.skipped) == (1, 2)
    assert not (tmp_path / ".partial").exists()
    assert _bytes(tmp_path) == before


def test_resume_refuses_other_settings(tmp_path):
    generate(tmp_path, {"train": 1}, TINY, progress=False)
    with pytest.raises(ConfigError, match="other settings"):
        generate(tmp_path, {"train": 1}, SynthConfig(size=40, tex_size=16, shading_size=8), progress=False)


def test_resume_refuses_a_set_whose_effective_grid_differs(tmp_path):
    generate(tmp_path, {"train": 1}, TINY, progress=False)
    path = tmp_path / layout.SETTINGS_FILE
    old = json.loads(path.read_text())
    del old["effective"]  # written by a version whose default grid may differ
    path.write_text(json.dumps(old))
    with pytest.raises(ConfigError, match="effective"):
        generate(tmp_path, {"train": 1}, TINY, progress=False)


def test_steady_rate_leaves_out_start_up_and_each_workers_first_sample():
    s = SynthSummary(written=9, failed=[("test", "000001", "bad")], seconds=6.0, first_seconds=2.0, workers=2)
    assert s.rate == pytest.approx(1.5) and s.steady_rate == pytest.approx(8 / 4)
    assert SynthSummary(written=2, seconds=4.0, first_seconds=3.0, workers=2).steady_rate == pytest.approx(0.5)


def test_make_sample_is_a_pure_function_of_seed_split_index():
    f1, p1 = make_sample(TINY, "test", 4, None)
    f2, p2 = make_sample(TINY, "test", 4, None)
    f3, _ = make_sample(TINY, "train", 4, None)
    assert p1 == p2 and np.array_equal(f1[IMAGE_FILE], f2[IMAGE_FILE])
    assert not np.array_equal(f1[IMAGE_FILE], f3[IMAGE_FILE])


def test_cli_synth_writes_splits_and_reports(tmp_path):
    out = tmp_path / "syn"
    args = ["synth", "--out", str(out), "--n", "2", "--size", "32", "--tex-size", "16", "--shading-size", "8",
            "--workers", "1"]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    assert "3 written" in result.output and "samples/s" in result.output
    assert len(list_samples(out, "train")) == 2 and len(list_samples(out, "test")) == 1  # 460/4115 of 2, at least 1
    again = CliRunner().invoke(cli, args)
    assert again.exit_code == 0 and "0 written, 3 already done" in again.output


def test_cli_synth_with_texture_folder_and_bad_texture(tmp_path):
    tex = tmp_path / "tex"
    tex.mkdir()
    (tex / "broken.png").write_bytes(b"not a png")
    args = ["synth", "--out", str(tmp_path / "o"), "--split", "test", "--n", "1", "--size", "32", "--tex-size",
            "16", "--shading-size", "8", "--workers", "1", "--textures", str(tex)]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 1
    assert "broken.png" in result.output and (tmp_path / "o" / layout.FAILURES_FILE).is_file()
    (tex / "broken.png").unlink()
    stripes = np.zeros((20, 30, 3), np.uint8)
    stripes[:, ::4] = (200, 40, 10)
    Image.fromarray(stripes).save(tex / "stripes.png")
    args[args.index("--out") + 1] = str(tmp_path / "ok")
    ok = CliRunner().invoke(cli, args)
    assert ok.exit_code == 0, ok.output
    params = json.loads((tmp_path / "ok/test/000000" / layout.PARAMS_FILE).read_text())
    assert params["texture"]["source"] == "stripes.png"
    shutil.rmtree(tex)
    tex.mkdir()
    assert CliRunner().invoke(cli, args).exit_code == 2  # no texture images: one-line error
