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


def _mouth_and_edge_images(size: int = 256) -> tuple[torch.Tensor, torch.Tensor, tuple[torch.Tensor, ...]]:
    """A cylinder's rim seen at 15 deg and two 1 x 2 x S x S images (grey, coverage; the object covers the frame):
    its mouth drawn dark on a pale wall, and a straight dark-over-pale edge through the rim's front arc's lowest
    point (a painted band's edge that a steep candidate's arc only touches)."""
    from radar_cli.config import CameraConfig
    from radar_cli.sor.outline import disc_conics
    from radar_cli.sor.solid import Solid

    solid = Solid(torch.full((1, 64), 0.5, dtype=torch.float64), torch.tensor([0.7], dtype=torch.float64),
                  torch.tensor([[15.0, 0.0, 0.0, 0.0]], dtype=torch.float64))
    q = disc_conics(solid, 2, CameraConfig())[0, 0]  # the rim's conic, normalised x right, y up
    centres = (torch.arange(size, dtype=torch.float64) + 0.5) / size * 2 - 1
    y, x = -centres[:, None].expand(size, size), centres[None, :].expand(size, size)
    m = torch.stack([x, y, torch.ones_like(x)], -1)  # S x S x 3
    value = torch.einsum("...i,ij,...j->...", m, q, m)
    inside = value * value[0, 0].sign() < 0  # the image's corner is outside the ellipse
    lowest = float(y[inside].min())  # the front arc's lowest point
    full = torch.ones(size, size)
    mouth = torch.where(inside, 0.1, 0.6).float()
    edge = torch.where(y > lowest - 1.0 / size, 0.1, 0.6).float()
    return (torch.stack([mouth, full])[None], torch.stack([edge, full])[None],
            (solid.radius, solid.height, solid.pose))


def test_a_mouth_is_darker_along_its_whole_arc_an_edge_it_touches_is_not():
    from radar_cli.config import CameraConfig
    from radar_cli.derender.refine.pitch_cues import lip_contrast

    mouth, edge, shape = _mouth_and_edge_images()
    contrast, _, share = lip_contrast(mouth, *shape, 2.0, CameraConfig())
    assert float(contrast) > 0.4 and float(share) > 0.95, (contrast, share)
    contrast, _, share = lip_contrast(edge, *shape, 2.0, CameraConfig())
    assert float(share) < ShapeFitConfig().lip_share, share  # a contrast at the middle, none along the rest


def test_a_faint_dark_mouth_under_the_old_bound_picks_the_pitch():
    """A vase at 12.3 deg whose black mouth over a dark neck reads a relative lip of 0.38, all along its arc."""
    grey, mask, truth = synthetic_vase(17, 36)
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "dark_lip" and abs(pitch - truth) <= 1.0, (pitch, cue, truth)
    level, _ = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), lip_relative=0.5))
    assert truth - level > 8.0, level
