"""Sine-curve radius columns, frame fitting, and spherical-Gaussian lighting baked into the env map."""

from __future__ import annotations

import math

import numpy as np
import pytest

from radar_cli.config import CameraConfig, GeometryConfig
from radar_cli.render.lighting import env_directions
from radar_cli.synth.lighting import Lobe, bake_env, sample_lobes, sg_radiance
from radar_cli.synth.shapes import fit_frame, fit_radius, sample_shape, sine_radius


def test_sine_radius_matches_the_supplementary_formula():
    rng = np.random.default_rng(3)
    r, p = sine_radius(rng, 32)
    i = 5
    expected = (p["t"] + p["a1"] * (1 + math.sin((32 - i) / 32 * p["p1"] + i / 32 * p["q1"]))
                + p["a2"] * (1 + math.sin(p["p2"] + i / 32 * p["q2"])))
    assert r[i] == pytest.approx(expected)
    assert 0.1 <= p["t"] <= 0.3 and 0 <= p["a1"] <= 0.3 and -math.pi <= p["p1"] <= 0
    assert math.pi / 2 <= p["q1"] <= 2 * math.pi and 0 <= p["a2"] <= 0.1 and math.pi / 2 <= p["q2"] <= 2 * math.pi


def test_fit_radius_scales_instead_of_clipping():
    r, scale = fit_radius(np.array([0.2, 1.1, 0.6]), 0.05, 0.9)
    assert scale == pytest.approx(0.9 / 1.1)
    assert r == pytest.approx([0.2 * scale, 0.9, 0.6 * scale])
    same, one = fit_radius(np.array([0.2, 0.5]), 0.05, 0.9)
    assert one == 1.0 and same == pytest.approx([0.2, 0.5])


def test_fit_frame_shrinks_only_large_tilted_objects():
    cam = CameraConfig()
    _, h, s = fit_frame(np.full(4, 0.3), 0.6, 5.0, cam, 0.5)
    assert s == 1.0 and h == 0.6
    r, h, s = fit_frame(np.full(4, 0.9), 0.95, 20.0, cam, 0.5)
    assert s < 1.0 and h >= 0.5 and r.max() < 0.9


@pytest.mark.parametrize("seed", range(40))
def test_sampled_shapes_stay_in_the_model_ranges(seed):
    geo = GeometryConfig()
    s = sample_shape(np.random.default_rng(seed), geo, random_roll=seed % 2 == 0, random_translation=seed % 3 == 0)
    assert s.radius.shape == (32,)
    assert geo.radius_range[0] <= s.radius.min() and s.radius.max() <= geo.radius_range[1]
    assert geo.height_range[0] <= s.height <= geo.height_range[1]
    assert 0 <= s.pose[0] <= 20
    assert geo.roll_range[0] <= s.pose[1] <= geo.roll_range[1]
    if seed % 2:
        assert s.pose[1] == 0.0


def test_lobes_come_from_the_upper_front_quarter():
    rng = np.random.default_rng(0)
    for _ in range(50):
        for lobe in sample_lobes(rng):
            x, y, z = lobe.direction
            assert y >= 0 and z <= 0 and math.isclose(x * x + y * y + z * z, 1.0, rel_tol=1e-9)
            assert 10 <= lobe.sharpness <= 30 and 0.1 <= lobe.intensity <= 0.3


def test_baked_env_peaks_where_the_lobe_points_and_keeps_its_energy():
    # a lobe straight towards the camera, level: env_directions puts azimuth 0 at the middle columns
    lobe = Lobe((0.0, 0.0, -1.0), 20.0, 0.2)
    env = bake_env([lobe], 16, 48)
    i, j = np.unravel_index(env.argmax(), env.shape)
    assert i in (7, 8) and j in (23, 24)
    dirs, solid = env_directions(16, 48)
    energy = float((env.reshape(-1) * solid.numpy()).sum())
    fine_dirs, fine_solid = env_directions(256, 768)
    exact = float((sg_radiance([lobe], fine_dirs.double().numpy()) * fine_solid.double().numpy()).sum())
    assert energy == pytest.approx(exact, rel=1e-2)
    # analytic integral of an SG over the sphere: sqrt(l) F 2 pi / l (1 - exp(-2 l))
    assert exact == pytest.approx(math.sqrt(20) * 0.2 * 2 * math.pi / 20 * (1 - math.exp(-40)), rel=1e-3)


def test_up_lobe_lights_the_top_rows():
    env = bake_env([Lobe((0.0, 1.0, 0.0), 30.0, 0.3)], 16, 48)
    assert env[0].mean() > 10 * env[-1].mean()
