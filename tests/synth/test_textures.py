"""Procedural pottery textures and image textures: range, seamlessness, determinism, augmentation."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from radar_cli.errors import InputError
from radar_cli.synth.textures import augment, image_texture, list_texture_images, procedural_texture


@pytest.mark.parametrize("seed", range(12))
def test_procedural_texture_is_valid_and_closes_around_the_vase(seed):
    tex = procedural_texture(np.random.default_rng(seed), 64, 192)
    assert tex.shape == (64, 192, 3) and tex.dtype == np.float32
    assert 0.0 <= tex.min() and tex.max() <= 1.0
    # the seam (last column -> first column) is no rougher than a typical step between neighbouring columns
    steps = np.abs(np.diff(tex, axis=1)).mean(axis=(0, 2))
    seam = np.abs(tex[:, 0] - tex[:, -1]).mean()
    assert seam <= np.quantile(steps, 0.99) + 1e-3


def test_procedural_textures_are_deterministic_and_varied():
    a = procedural_texture(np.random.default_rng(7), 32, 96)
    b = procedural_texture(np.random.default_rng(7), 32, 96)
    c = procedural_texture(np.random.default_rng(8), 32, 96)
    assert np.array_equal(a, b)
    assert np.abs(a - c).mean() > 0.01


def test_augment_stays_in_range_and_records_values():
    tex = procedural_texture(np.random.default_rng(1), 32, 96)
    out, info = augment(tex, np.random.default_rng(2))
    assert out.shape == tex.shape and 0.02 <= out.min() and out.max() <= 1.0
    assert 1.0 <= info["brightness"] <= 1.5 and 1.0 <= info["contrast"] <= 1.6 and -180 <= info["hue"] <= 180


def test_image_textures_from_a_folder(tmp_path):
    (tmp_path / "notes.txt").write_text("not an image")
    Image.fromarray(np.random.default_rng(0).integers(0, 255, (40, 50, 3), dtype=np.uint8)).save(tmp_path / "a.png")
    files = list_texture_images(tmp_path)
    assert [f.name for f in files] == ["a.png"]
    tex = image_texture(files[0], np.random.default_rng(0), 32, 96)
    assert tex.shape == (32, 96, 3)
    assert np.allclose(tex[:, 0], tex[:, -1], atol=0.02)  # mirrored, so the seam matches


def test_texture_folder_errors(tmp_path):
    with pytest.raises(InputError, match="no texture images"):
        list_texture_images(tmp_path)
    with pytest.raises(InputError, match="no such texture folder"):
        list_texture_images(tmp_path / "missing")


@pytest.mark.parametrize("v0, v1", [(0.0, 0.05), (0.31, 0.52), (0.9, 1.0), (0.5, 0.5 + 1e-4)])
def test_band_patterns_vanish_outside_the_rows_they_are_drawn_on(v0, v1):
    """Bands are drawn on Canvas.rows only: every pattern on the full canvas is 0 outside those rows and equal to
    the sub-canvas's pattern inside them."""
    from radar_cli.synth import textures as T

    canvas = T._Canvas(64, 192)
    rows, band = canvas.rows(v0, v1)
    for draw in (T._band, T._stripes, T._zigzag, T._meander, T._dots, lambda *a: T._flowers(*a)[0]):
        full = np.broadcast_to(draw(np.random.default_rng(4), canvas, v0, v1), (64, 192))
        part = np.broadcast_to(draw(np.random.default_rng(4), band, v0, v1), (rows.stop - rows.start, 192))
        outside = np.ones(64, bool)
        outside[rows] = False
        assert float(np.abs(full[outside]).max(initial=0.0)) == 0.0
        assert np.array_equal(full[rows], part)
