"""A steep vase whose mouth is black and whose neck just below the lip is dark too: the rim's front arc is a
faint edge (contrast 0.06), but the mouth is several times darker than the neck, and that picks the pitch the
silhouette alone cannot (at a low pitch a profile closing into a dome draws the same outline)."""

from __future__ import annotations

import dataclasses

import numpy as np
import torch

from radar_cli.derender.refine.pitch_cues import pick_cue
from radar_cli.derender.refine.shape_config import ShapeFitConfig

from .test_bands import searched_pitch, synthetic_vase


def _dark_necked_vase() -> tuple[np.ndarray, np.ndarray, float]:
    """(grey, silhouette, true pitch 17.3 deg) of a vase with a dark brown neck ringed by
    small olive squares, a black mouth, seen from above."""
    return synthetic_vase(7, 21)


def test_a_dark_mouth_over_a_dark_neck_picks_the_steep_pitch():
    grey, mask, truth = _dark_necked_vase()
    assert truth > 15.0
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "dark_lip" and abs(pitch - truth) <= 1.0, (pitch, truth)
    level, cue = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), lip_relative=None))
    assert cue == "outline" and pitch - level > 10.0, level  # the silhouette alone reads it level



def test_bands_too_faint_to_pick_still_rule_a_dark_lip_out():
    """An oinochoe's trefoil mouth shows its dark inside at a level view: a relative lip at 13 deg, where the
    painted bands are half as straight as at 3 deg, must not pick (the outline does)."""
    pitches = torch.arange(0.0, 25.5, 0.5, dtype=torch.float64)
    score = 1.0 + 0.01 * pitches  # every candidate in the outline's basin, the level one best
    contrast = torch.zeros_like(pitches)  # no plain lip
    relative = torch.where((pitches - 13.0).abs() < 0.3, 0.8, 0.0).double()
    coherence = (0.06 + 0.15 * torch.exp(-0.5 * ((pitches - 3.0) / 2.0) ** 2)).double()  # peak 3.5x its lowest
    config = ShapeFitConfig()
    best, cue = pick_cue(score, contrast, coherence, pitches, config, relative=relative)
    assert cue == "outline" and float(pitches[best]) == 0.0
    near_peak = torch.where((pitches - 3.5).abs() < 0.3, 0.8, 0.0).double()  # the dark lip where the bands agree
    best, cue = pick_cue(score, contrast, coherence, pitches, config, relative=near_peak)
    assert cue == "dark_lip" and float(pitches[best]) == 3.5
    best, cue = pick_cue(score, contrast, coherence, pitches, dataclasses.replace(config, dark_lip_bands=None),
                      relative=relative)
    assert cue == "dark_lip" and float(pitches[best]) == 13.0  # unchecked, the trefoil's inside would pick
