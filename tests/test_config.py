"""Typed configuration: the paper's values and strict TOML loading."""

import math
from dataclasses import dataclass

import pytest

from radar_cli.config import CameraConfig, GeometryConfig, RenderConfig, from_dict, load_toml, to_dict
from radar_cli.errors import ConfigError


def test_paper_values():
    cam, geo = CameraConfig(), GeometryConfig()
    assert cam.fov_deg == 10.0 and cam.distance == 5.0
    assert cam.r_max == pytest.approx(math.tan(math.radians(5.0)) * 5.0)
    assert (geo.n_rows, geo.n_cols) == (32, 96)
    assert geo.radius_range == (0.05, 0.9) and geo.height_range == (0.5, 0.95)
    assert geo.pitch_range == (0.0, 20.0) and geo.roll_range == (-10.0, 10.0) and geo.trans_range == (-0.2, 0.2)
    assert (RenderConfig().env_height, RenderConfig().env_width) == (16, 48)


def test_round_trip_and_defaults():
    geo = from_dict(GeometryConfig, {"n_rows": 16, "pitch_range": [0, 30]})
    assert geo.n_rows == 16 and geo.pitch_range == (0.0, 30.0) and geo.n_cols == 96
    assert from_dict(GeometryConfig, to_dict(geo)) == geo


@pytest.mark.parametrize(
    "data, message",
    [
        ({"n_rowz": 3}, "unknown key"),
        ({"n_rows": 3.5}, "expected an integer"),
        ({"n_rows": True}, "expected an integer"),
        ({"pitch_range": [0]}, "expected a list of 2"),
        ({"radius_range": ["a", 1]}, "expected a number"),
    ],
)
def test_strict_errors(data, message):
    with pytest.raises(ConfigError, match=message):
        from_dict(GeometryConfig, data)


def test_nested_and_literal(tmp_path):
    from typing import Literal

    @dataclass(frozen=True)
    class Root:
        camera: CameraConfig = CameraConfig()
        mode: Literal["a", "b"] = "a"

    path = tmp_path / "c.toml"
    path.write_text('mode = "b"\n[camera]\nfov_deg = 12.0\n')
    root = load_toml(Root, path)
    assert root.mode == "b" and root.camera.fov_deg == 12.0
    path.write_text('mode = "c"\n')
    with pytest.raises(ConfigError, match="expected one of"):
        load_toml(Root, path)


def test_missing_and_malformed_file(tmp_path):
    with pytest.raises(ConfigError, match="no such config file"):
        load_toml(CameraConfig, tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("fov_deg = = 3")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_toml(CameraConfig, bad)


@dataclass(frozen=True)
class Preset:
    name: str = "run"
    camera: CameraConfig = CameraConfig()
    geometry: GeometryConfig = GeometryConfig()


def write(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_base_deep_merges_along_a_chain(tmp_path):
    write(tmp_path / "a.toml", 'name = "a"\n[camera]\nfov_deg = 12.0\ndistance = 7.0\n[geometry]\nn_rows = 16\n')
    write(tmp_path / "b.toml", 'base = "a.toml"\nname = "b"\n[camera]\ndistance = 9.0\n')
    child = write(tmp_path / "c.toml", 'base = "b.toml"\n[geometry]\npitch_range = [1, 2]\n')
    got = load_toml(Preset, child)
    assert got.name == "b" and got.camera == CameraConfig(fov_deg=12.0, distance=9.0)
    assert got.geometry == GeometryConfig(n_rows=16, pitch_range=(1.0, 2.0))
    assert load_toml(Preset, tmp_path / "a.toml").camera.distance == 7.0


def test_base_is_relative_to_the_including_file(tmp_path, monkeypatch):
    write(tmp_path / "shared" / "root.toml", "[camera]\nfov_deg = 20.0\n")
    child = write(tmp_path / "runs" / "deep" / "child.toml", 'base = "../../shared/root.toml"\nname = "x"\n')
    monkeypatch.chdir(tmp_path / "runs")  # the working folder plays no part
    assert load_toml(Preset, child).camera.fov_deg == 20.0
    write(child, 'base = "root.toml"\n')
    with pytest.raises(ConfigError, match=r"child\.toml\.base: no such config file"):
        load_toml(Preset, child)


def test_base_cycle_is_refused(tmp_path):
    write(tmp_path / "a.toml", 'base = "b.toml"\n')
    write(tmp_path / "b.toml", 'base = "sub/../a.toml"\n')
    with pytest.raises(ConfigError, match="cycle"):
        load_toml(Preset, tmp_path / "a.toml")
    write(tmp_path / "self.toml", 'base = "self.toml"\n')
    with pytest.raises(ConfigError, match="cycle"):
        load_toml(Preset, tmp_path / "self.toml")


@pytest.mark.parametrize("text, message", [
    ('base = "root.toml"\n[camera]\nfov = 3.0\n', r"child\.toml\.camera: unknown key\(s\) fov"),
    ('base = "root.toml"\n[camera]\nfov_deg = "wide"\n', r"child\.toml\.camera\.fov_deg: expected a number"),
    ('base = 3\n', r"child\.toml\.base: expected a file name"),
])
def test_child_is_strict_and_named(tmp_path, text, message):
    write(tmp_path / "root.toml", "[camera]\nfov_deg = 20.0\n")
    with pytest.raises(ConfigError, match=message):
        load_toml(Preset, write(tmp_path / "child.toml", text))


def test_bad_key_in_a_base_names_the_base(tmp_path):
    write(tmp_path / "root.toml", "[camera]\nzoom = 2\n")
    with pytest.raises(ConfigError, match=r"root\.toml\.camera: unknown key"):
        load_toml(Preset, write(tmp_path / "child.toml", 'base = "root.toml"\n'))
