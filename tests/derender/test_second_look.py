"""A steep vase with a bulging body and a visible lip: at its true pitch the closed-form profile is drawn too wide
(each row of a steep view also shows the ellipses of the discs above and below), which left that candidate out of
the outline's basin with its lip, or in it with a top edge drawn worse than a band's; the candidates with a strong
lip are scored again with their widths corrected."""

from __future__ import annotations

import dataclasses

import numpy as np

from radar_cli.derender.refine.shape_config import ShapeFitConfig

from .test_bands import searched_pitch, synthetic_vase


def _bulging_vase() -> tuple[np.ndarray, np.ndarray, float]:
    """(grey, silhouette, true pitch 18.1 deg) of a squat violet vase with a wide shoulder,
    its black mouth seen over a pale lip."""
    return synthetic_vase(17, 24)


def test_a_strong_lip_outside_the_basin_is_looked_at_again():
    grey, mask, truth = _bulging_vase()
    assert truth > 15.0
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "lip" and abs(pitch - truth) <= 1.0, (pitch, cue, truth)
    level, cue = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), lip_width_rounds=0))
    assert truth - level > 10.0, (level, cue)  # without the second look the silhouette reads it level


def test_a_dark_lip_outside_the_top_edges_basin_is_looked_at_again():
    """A vase at 19.5 deg, a black mouth over a dark neck: at its true pitch the closed-form rim is drawn too
    wide, so its top edge left the candidate out of the cues' basin (the outline's basin held it)."""
    grey, mask, truth = synthetic_vase(17, 27)
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "dark_lip" and abs(pitch - truth) <= 1.0, (pitch, cue, truth)
    level, _ = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), lip_width_rounds=0))
    assert truth - level > 10.0, level


def test_a_strong_lip_inside_the_basin_is_looked_at_again():
    """A white vase at 20 deg, its wide mouth's black inside over a pale lip (relative 0.93): the candidate is in
    the outline's basin, but its closed-form rim drew the top edge 1.07 px off against 0.84 at the 11 deg that
    the marbling's lines make a band of, so the bands kept the pick until its widths were corrected too."""
    grey, mask, truth = synthetic_vase(31, 9)
    assert truth > 19.0
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue in ("lip", "dark_lip") and abs(pitch - truth) <= 1.0, (pitch, cue, truth)
    banded, cue = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), lip_width_rounds=0))
    assert cue == "band" and truth - banded > 5.0, (banded, cue)
