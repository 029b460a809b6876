"""A steep vase whose mouth is black and whose neck just below the lip is dark too: the rim's front arc is a
faint edge (contrast 0.06), but the mouth is several times darker than the neck, and that picks the pitch the
silhouette alone cannot (at a low pitch a profile closing into a dome draws the same outline)."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from radar_cli.derender.refine.fit_shape import ShapeFitConfig
from radar_cli.synth.generator import SynthConfig, make_sample

from .test_bands import searched_pitch


@functools.cache
def _dark_necked_vase() -> tuple[np.ndarray, np.ndarray, float]:
    """(512 x 512 grey image, bool silhouette, true pitch 17.3 deg) of a vase with a dark brown neck ringed by
    small olive squares, a black mouth, seen from above (the `radar synth --size 512 --seed 7` test sample 21)."""
    files, params = make_sample(SynthConfig(size=512, seed=7), "test", 21, None)
    grey = np.clip(files["image.png"], 0, 1).mean(axis=2).astype(np.float32)
    return grey, files["mask.png"] > 0.5, params["pose"][0]


def test_a_dark_mouth_over_a_dark_neck_picks_the_steep_pitch():
    grey, mask, truth = _dark_necked_vase()
    assert truth > 15.0
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "dark_lip" and abs(pitch - truth) <= 1.0, (pitch, truth)
    level, cue = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), lip_relative=None))
    assert cue == "outline" and pitch - level > 10.0, level  # the silhouette alone reads it level

