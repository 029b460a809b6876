"""The handles split off each view's silhouette place the views where the texture cannot: a vase whose painting
repeats every 90 deg is registered with the turns of its handles' views (two views between the handles are 180
deg apart), and the phases are read from the silhouettes."""

from __future__ import annotations

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from radar_cli.derender.multiview.fuse import unwrap_view
from radar_cli.derender.multiview.turns import handle_phase, register_turns
from radar_cli.render.material import Material
from radar_cli.render.scene import render_view
from radar_cli.sor.solid import Solid

from .test_multiview import CAMERA, RENDER, ROWS, SIZE, angle_error, vase

TURNS = (0.0, 183.0, 87.0, 272.0)  # front, back, then the two handle sides
PHASES = [90.0, 90.0, 0.0, 0.0]  # the handles at the sides of the front and back, in the middle of the others


def repeating_albedo() -> torch.Tensor:
    """1 x 3 x ROWS x 3 ROWS coloured blobs repeating every 90 deg round the vase."""
    gen = torch.Generator().manual_seed(5)
    quarter = torch.rand(1, 3, 8, 6, generator=gen)
    noise = quarter.repeat(1, 1, 1, 4)  # 24 columns: 4 repeats
    wrapped = torch.cat([noise[..., -2:], noise, noise[..., :2]], -1)
    albedo = F.interpolate(wrapped, size=(ROWS, 3 * ROWS + ROWS // 3), mode="bicubic", align_corners=False)
    return albedo[..., ROWS // 6 : ROWS // 6 + 3 * ROWS].clamp(0.05, 0.95)


@pytest.fixture(scope="module")
def views():
    radius, height, pose, _, env, alpha, rho = vase()
    solid, material = Solid(radius, height, pose), Material(repeating_albedo(), env, alpha, rho)
    out = []
    for turn in TURNS:
        image, coverage = render_view(solid, material, SIZE, -turn, RENDER, CAMERA)
        out.append(unwrap_view(image, coverage, solid, material, ROWS, RENDER, CAMERA))
    return out


def test_the_handles_tell_the_back_from_a_side_where_the_painting_repeats(views) -> None:
    guided = register_turns(views, phases=PHASES)
    assert angle_error(guided.degrees[1], TURNS[1]) <= 3.0, guided.degrees
    for k in (2, 3):  # the handle sides: 90 or 270 (the repeating painting cannot say which)
        assert min(angle_error(guided.degrees[k], t) for t in (87.0, 272.0)) <= 3.0, guided.degrees
    blind = register_turns(views)
    assert angle_error(blind.degrees[1], TURNS[1]) > 45.0, blind.degrees  # without them: the first free step


def test_handle_phases_are_read_from_the_split_silhouette() -> None:
    core = np.zeros((200, 200), bool)
    core[40:180, 60:140] = True
    sides = np.zeros_like(core)
    sides[60:120, 40:55] = True
    sides[60:120, 145:160] = True
    middle = np.zeros_like(core)
    middle[25:40, 90:110] = True  # a handle's plate standing above the rim, in front of the middle
    one_side = np.zeros_like(core)
    one_side[60:120, 145:160] = True  # a jug's handle, or a spout
    assert handle_phase(core, sides) == 90.0
    assert handle_phase(core, middle) == 0.0
    assert handle_phase(core, one_side) is None
    assert handle_phase(core, sides | middle) is None
    assert handle_phase(core, None) is None


def test_a_turn_beyond_the_reach_of_every_step_keeps_its_step(views, monkeypatch) -> None:
    """Two views whose textures agree best 125 deg apart (35 from the nearest step, beyond the 30 deg reach):
    within reach the agreement only rises towards its edge, so the turn is the prior's step, not registered."""
    from radar_cli.derender.multiview import turns as module

    peak = np.exp(-0.5 * ((np.arange(360) - 125.0) / 20.0) ** 2)  # one broad peak at 125 deg
    monkeypatch.setattr(module, "correlation", lambda a, b, config: (peak, np.ones(360)))
    found = register_turns(views[:2])
    assert not found.registered[1], found
    assert found.degrees[1] in (90.0, 180.0, 270.0), found.degrees
    monkeypatch.setattr(module, "correlation", lambda a, b, config: (np.roll(peak, -20), np.ones(360)))
    found = register_turns(views[:2])  # a peak at 105, within reach of 90: found
    assert found.registered[1] and abs(found.degrees[1] - 105.0) <= 1.0, found
