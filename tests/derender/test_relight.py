"""Relighting a de-rendered folder without the network, environment maps, the fast view renderer, contact sheet."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from radar_cli.cli import cli
from radar_cli.derender.export.environments import builtin_environments, load_environment, normalise
from radar_cli.derender.export.maps import chw_image
from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.export.renders import ViewRenderer
from radar_cli.derender.present.contact_sheet import contact_sheet
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.state import read_state
from radar_cli.errors import InputError
from radar_cli.render.lighting import compose
from radar_cli.render.scene import render_view, rotate_full_map
from radar_cli.render.texture import render_texture
from radar_cli.sor.solid import Solid

from .conftest import SIZE, write_photo


@pytest.fixture(scope="module")
def obj(tmp_path_factory) -> Path:
    from radar_cli.derender.run.predictor import Predictor

    from .conftest import SETUP, FakeModel

    root = tmp_path_factory.mktemp("relight")
    write_photo(root / "in" / "vase.png", 7, (80, 80))
    predictor = Predictor(FakeModel(), SETUP, "fake-model", "cpu")
    derender([root / "in"], predictor, DerenderOptions(out=root / "out", export=ExportConfig(0, 32)))
    return root / "out" / "vase"


def _read(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64)


def test_relight_with_predicted_env_reproduces_recon(obj: Path, tmp_path: Path) -> None:
    out = tmp_path / "again.png"
    result = CliRunner().invoke(cli, ["relight", str(obj), "--env", str(obj / "env_map.npy"), "--out", str(out)])
    assert result.exit_code == 0, result.output
    again, recon = _read(out), _read(obj / "recon.png")
    side = json.loads((obj / "material.json").read_text())["resolution"]  # the crop's 65 px, not the network's
    assert again.shape == recon.shape == (side, side, 3) and side != SIZE
    assert np.abs(again - recon).max() <= 1.0  # the same render, up to float rounding


def test_relight_changes_with_env_and_view(obj: Path, tmp_path: Path) -> None:
    recon = _read(obj / "recon.png")
    hdr = tmp_path / "sunset.hdr"
    cv2.imwrite(str(hdr), np.repeat(builtin_environments(16, 48)["sunset"][..., None], 3, 2))
    runner = CliRunner()
    assert runner.invoke(cli, ["relight", str(obj), "--env", str(hdr), "--out", str(tmp_path / "a.png")]).exit_code == 0
    assert np.abs(_read(tmp_path / "a.png") - recon).mean() > 2
    args = ["relight", str(obj), "--env", str(obj / "env_map.npy"), "--yaw", "90", "--pitch", "0", "--size", "48",
            "--out", str(tmp_path / "b.png")]
    assert runner.invoke(cli, args).exit_code == 0
    assert Image.open(tmp_path / "b.png").size == (48, 48)


def test_relight_bad_folder_and_env_one_line(obj: Path, tmp_path: Path) -> None:
    runner = CliRunner()
    bad = runner.invoke(cli, ["relight", str(tmp_path), "--env", str(obj / "env_map.npy"), "--out", "x.png"])
    assert bad.exit_code == 2 and "material.json" in bad.output and len(bad.output.strip().splitlines()) == 1
    (tmp_path / "env.npy").write_bytes(b"not numpy")
    bad_env = runner.invoke(cli, ["relight", str(obj), "--env", str(tmp_path / "env.npy"), "--out", "x.png"])
    assert bad_env.exit_code == 2 and "env.npy" in bad_env.output


@pytest.mark.parametrize("name", ["studio", "overcast", "sunset", "two_lights"])
def test_relight_takes_the_builtin_environments_by_name(obj: Path, tmp_path: Path, name: str) -> None:
    env = read_state(obj).material.env[0].numpy()
    np.save(tmp_path / "map.npy", builtin_environments(*env.shape)[name])
    runner = CliRunner()
    for spec, out in ((name, "by_name.png"), (str(tmp_path / "map.npy"), "by_file.png")):
        result = runner.invoke(cli, ["relight", str(obj), "--env", spec, "--out", str(tmp_path / out)])
        assert result.exit_code == 0, result.output
    by_name = _read(tmp_path / "by_name.png")
    assert np.array_equal(by_name, _read(tmp_path / "by_file.png"))
    assert np.abs(by_name - _read(obj / "recon.png")).mean() > 0.5  # not the object's own lighting


def test_relight_refuses_unknown_names_non_image_outputs_and_missing_folders(obj: Path, tmp_path: Path) -> None:
    runner = CliRunner()
    unknown = runner.invoke(cli, ["relight", str(obj), "--env", "moonlight", "--out", str(tmp_path / "a.png")])
    assert unknown.exit_code == 2 and "moonlight: no such environment (built-in: studio" in unknown.stderr
    text = runner.invoke(cli, ["relight", str(obj), "--env", "studio", "--out", str(tmp_path / "x.txt")])
    assert text.exit_code == 2 and "x.txt: not an image file name" in text.stderr
    missing = tmp_path / "no" / "such"
    nested = runner.invoke(cli, ["relight", str(obj), "--env", "studio", "--out", str(missing / "x.png")])
    assert nested.exit_code == 2 and f"{missing}: no such folder" in nested.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing written, no folder made


def test_view_renderer_equals_render_view(obj: Path) -> None:
    state = read_state(obj)
    view = ViewRenderer(state, 40, pitch_deg=5.0)
    fast = view.draw(view.shading(), yaw_deg=100.0).astype(np.float64)
    pose = state.solid.pose.clone()
    pose[:, 0] = 5.0
    ref, _ = render_view(Solid(state.solid.radius, state.solid.height, pose), state.material, 40,
                         100.0, state.render, state.camera, 1.0)
    ref8 = np.clip(ref[0].permute(1, 2, 0).numpy(), 0, 1) * 255
    assert np.abs(fast - ref8).max() <= 1.0


@pytest.mark.parametrize("pitch, yaw", [(2.0, 0.0), (30.0, 360.0), (70.0, 200.0)])
def test_a_view_draws_the_shaded_albedo_spun(obj: Path, pitch: float, yaw: float) -> None:
    state = read_state(obj)
    view = ViewRenderer(state, 40, pitch_deg=pitch)
    shading = view.shading()  # unspun, its texture is drawn as it is
    whole = compose(rotate_full_map(state.material.albedo, yaw), shading.diffuse, shading.specular,
                    state.material.rho, state.render.gamma)
    image, _ = render_texture(view.hits, whole, inside_dim=state.render.inside_dim, background=1.0)
    np.testing.assert_array_equal(view.draw(shading, yaw), chw_image(image))


def test_environment_files_agree(tmp_path: Path) -> None:
    env = builtin_environments(8, 24)["studio"]
    np.save(tmp_path / "e.npy", env)
    cv2.imwrite(str(tmp_path / "e.hdr"), np.repeat(env[..., None], 3, 2))
    big = cv2.resize(env, (96, 32), interpolation=cv2.INTER_NEAREST)
    Image.fromarray((np.clip(big / big.max(), 0, 1) ** (1 / 2.2) * 255).astype(np.uint8)).save(tmp_path / "e.png")
    from_npy = load_environment(tmp_path / "e.npy", 8, 24)
    np.testing.assert_allclose(load_environment(tmp_path / "e.hdr", 8, 24), from_npy, rtol=0.02, atol=1e-4)
    from_png = load_environment(tmp_path / "e.png", 8, 24) * env.max()
    np.testing.assert_allclose(from_png, env, atol=0.03 * env.max())
    with pytest.raises(InputError, match="unsupported"):
        load_environment(shutil.copy(tmp_path / "e.npy", tmp_path / "e.txt"), 8, 24)
    (tmp_path / "bad.exr").write_bytes(b"v/1\x01 not really exr")
    with pytest.raises(InputError, match="bad.exr: not a readable .exr"):
        load_environment(tmp_path / "bad.exr", 8, 24)


def test_builtins_are_normalised() -> None:
    envs = builtin_environments(16, 48)
    assert set(envs) == {"studio", "sunset", "overcast", "two_lights"}
    for env in envs.values():
        assert env.min() >= 0 and np.isfinite(env).all()
        np.testing.assert_allclose(normalise(env), env, rtol=1e-4)  # already at the target irradiance
    assert envs["sunset"][:, :24].sum() < envs["sunset"][:, 24:].sum()  # the sun is on one side


def test_contact_sheet(obj: Path, tmp_path: Path) -> None:
    out = contact_sheet(obj.parent, tmp_path / "sheet.png")
    with Image.open(out) as im:
        assert im.size[1] > 100 and im.size[0] > 4 * 100
    with pytest.raises(InputError):
        contact_sheet(tmp_path / "nothing", tmp_path / "x.png")


def test_relight_matches_exposure_unless_absolute(obj: Path, tmp_path: Path) -> None:
    np.save(tmp_path / "bright.npy", 10 * np.load(obj / "env_map.npy"))  # the same light in other units
    runner = CliRunner()
    base = ["relight", str(obj), "--env", str(tmp_path / "bright.npy"), "--out"]
    assert runner.invoke(cli, base + [str(tmp_path / "m.png")]).exit_code == 0
    assert np.abs(_read(tmp_path / "m.png") - _read(obj / "recon.png")).max() <= 1.0
    assert runner.invoke(cli, base + [str(tmp_path / "a.png"), "--absolute"]).exit_code == 0
    assert _read(tmp_path / "a.png").mean() > _read(obj / "recon.png").mean() + 5
