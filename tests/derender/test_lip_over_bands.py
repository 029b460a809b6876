"""Painted bands bound the lip's search to their peak, but a few faint dots near the foot, a dotted band or a
glaze's edge can make a band: where no lip lies within the bands' reach and a strong lip elsewhere (plain, or
relative to its sides' grey level) draws the photograph's top edge better, the lip picks."""

from __future__ import annotations

import dataclasses

import torch

from radar_cli.derender.refine.pitch_cues import pick_cue
from radar_cli.derender.refine.shape_config import ShapeFitConfig

from .test_bands import searched_pitch, synthetic_vase


def test_a_strong_lip_the_bands_leave_out_picks_the_pitch():
    """A green vase at 15.8 deg, its open mouth's lip strong (0.37), a few dark dots near its foot (bands at 4.5)."""
    grey, mask, truth = synthetic_vase(5, 12)
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "lip" and abs(pitch - truth) <= 1.0, (pitch, cue, truth)
    bounded, cue = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), lip_over_bands=None))
    assert cue == "band" and truth - bounded > 8.0, (bounded, cue)


def test_a_dark_lip_the_bands_leave_out_picks_the_pitch():
    """A `--seed 31` vase at 6.0 deg, purple under a black glaze whose lower edge makes a band at 3.5 deg; its
    mouth's dark inside (relative lip 0.97, plain 0.08) lies where the outline and the top edge are best."""
    grey, mask, truth = synthetic_vase(31, 24)
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "dark_lip" and abs(pitch - truth) <= 0.5, (pitch, cue, truth)
    bounded, cue = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), dark_lip_over_bands=None))
    assert cue == "band" and truth - bounded > 2.0, (bounded, cue)


def _cues(lip_at: float, lip: float, top_at_lip: float, lip_near_bands: float) -> tuple[float, str]:
    """The pick among 0-25 deg candidates, all in the outline's basin, bands peaking at 2 deg (top edge 1.0
    px there), a lip of `lip` at `lip_at` (its top edge `top_at_lip`) and one of `lip_near_bands` at 2.5 deg."""
    pitches = torch.arange(0.0, 25.5, 0.5, dtype=torch.float64)
    score = torch.ones_like(pitches)
    coherence = (0.02 + 0.3 * (pitches == 2.0)).double()
    contrast = torch.where(pitches == lip_at, lip, 0.0).double() + torch.where(pitches == 2.5, lip_near_bands, 0.0)
    top = torch.where(pitches == lip_at, top_at_lip, 1.0).double()
    best, cue = pick_cue(score, contrast, coherence, pitches, ShapeFitConfig(), top=top)
    return float(pitches[best]), cue


def test_the_bands_stand_where_a_lip_lies_within_their_reach_or_the_lip_draws_the_top_worse():
    assert _cues(12.0, 0.4, 0.8, 0.0) == (12.0, "lip")
    assert _cues(12.0, 0.4, 0.8, 0.26) == (2.5, "lip")  # a krater's rim over its bands: a lip near their peak
    assert _cues(12.0, 0.4, 1.2, 0.0) == (2.0, "band")  # the lip's pitch draws the top edge worse
    assert _cues(12.0, 0.2, 0.8, 0.0) == (2.0, "band")  # a lip too faint to overrule them


def test_of_several_strong_lips_beyond_the_bands_the_one_drawing_the_top_edge_best_picks():
    """Two strong lips outside the bands' reach, both drawing the top edge better than the bands' peak: the
    better drawn one is looked at, not the stronger (an arc across the glaze above the mouth can be as strong)."""
    pitches = torch.arange(0.0, 25.5, 0.5, dtype=torch.float64)
    coherence = (0.02 + 0.3 * (pitches == 2.0)).double()
    contrast = torch.where(pitches == 8.0, 0.45, 0.0).double() + torch.where(pitches == 14.0, 0.35, 0.0)
    top = torch.ones_like(pitches) - 0.3 * (pitches == 8.0) - 0.6 * (pitches == 14.0)
    best, cue = pick_cue(torch.ones_like(pitches), contrast, coherence, pitches, ShapeFitConfig(), top=top)
    assert (float(pitches[best]), cue) == (14.0, "lip")
    # a `--seed 31` cup at 10.1 deg with a row of dots round its foot (bands at 3 deg): read 3.1 when the
    # strongest lip beyond the bands was looked at
    grey, mask, truth = synthetic_vase(31, 40)
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "lip" and abs(pitch - truth) <= 0.5, (pitch, cue, truth)
