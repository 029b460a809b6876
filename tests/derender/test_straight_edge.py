"""A level photograph's rim and neck meet in straight edges. A steep candidate's front arc that crosses one reads
some contrast, but a level line along the edge reads more: such an arc is no lip (fit_shape._not_straight). A
mouth's front arc beats every level line across it."""

from __future__ import annotations

import dataclasses

import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.fit_shape import _not_straight
from radar_cli.derender.refine.pitch_cues import lip_contrast, straight_contrast
from radar_cli.derender.refine.shape_config import ShapeFitConfig

from .test_dark_lip import _mouth_and_edge_images


def test_a_level_line_beats_an_arc_across_a_straight_edge_but_not_a_mouth():
    mouth, edge, shape = _mouth_and_edge_images()
    camera, config = CameraConfig(), ShapeFitConfig()
    assert config.straight_ratio is not None
    arc, _, _ = lip_contrast(mouth, *shape, 2.0, camera)
    line, rise = straight_contrast(mouth, *shape, 2.0, camera)
    assert float(rise) >= config.straight_rise_px, rise  # the arc is curved enough to tell from a line
    assert float(line) < 0.8 * float(arc), (line, arc)
    arc, _, _ = lip_contrast(edge, *shape, 2.0, camera)
    line, _ = straight_contrast(edge, *shape, 2.0, camera)
    assert float(line) > 0.4 and float(line) >= config.straight_ratio * float(arc), (line, arc)


def test_only_the_arcs_a_level_line_explains_lose_their_contrast():
    mouth, edge, (radius, height, pose) = _mouth_and_edge_images()
    camera, config = CameraConfig(), ShapeFitConfig()
    shapes = (radius.expand(2, -1), height.expand(2), pose.expand(2, -1).clone())
    shapes[2][1, 0] = 1.0  # a near-level candidate: its arc hardly rises, a line is no test of it
    for image, kept in ((mouth, [True, True]), (edge, [False, True])):
        contrast = torch.tensor([0.3, 0.3], dtype=torch.float64)
        left = _not_straight(contrast, image, shapes, 2.0, config, camera)
        assert [bool(v > 0) for v in left] == kept, left
    off = dataclasses.replace(config, straight_ratio=None)
    contrast = torch.tensor([0.3, 0.3], dtype=torch.float64)
    assert torch.equal(_not_straight(contrast, edge, shapes, 2.0, off, camera), contrast)
