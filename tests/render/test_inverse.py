"""Inverse rendering from a cylinder at zero pose on the silhouette loss alone."""

from __future__ import annotations

import pytest
import torch

from radar_cli.config import GeometryConfig
from radar_cli.render.raycast import cast_rays
from radar_cli.sor.profile import rescale
from radar_cli.sor.solid import Solid

SIZE = 64
STEPS = 300


def iou(a: torch.Tensor, b: torch.Tensor) -> float:
    return float((a & b).sum() / (a | b).sum())


@pytest.mark.slow
def test_silhouette_fit_recovers_shape_and_pose(random_sor):
    geo = GeometryConfig()
    radius, height, pose = random_sor(1, seed=11, dtype=torch.float32)
    pose[0, 0] = 12.0  # a clearly tilted target, so pitch is observable from the outline alone
    target = cast_rays(Solid(radius, height, pose), SIZE).mask.float()
    # unconstrained parameters squashed into the paper's ranges, starting from a cylinder at zero pose
    logit_r = torch.zeros(1, radius.shape[1], requires_grad=True)  # r = 0.475 everywhere
    logit_h = torch.zeros(1, requires_grad=True)
    free_pose = torch.zeros(1, 4, requires_grad=True)
    opt = torch.optim.Adam([logit_r, logit_h, free_pose], lr=0.05)
    lo = torch.tensor([geo.pitch_range[0] - 10, geo.roll_range[0], geo.trans_range[0], geo.trans_range[0]])
    hi = torch.tensor([geo.pitch_range[1] + 10, geo.roll_range[1], geo.trans_range[1], geo.trans_range[1]])

    def params():
        r = rescale(torch.sigmoid(logit_r), *geo.radius_range)
        h = rescale(torch.sigmoid(logit_h), *geo.height_range)
        p = rescale(torch.sigmoid(free_pose), lo, hi)
        return r, h, p

    for step in range(STEPS):
        sigma = 2.0 if step < STEPS // 2 else 1.0
        r, h, p = params()
        loss = ((cast_rays(Solid(r, h, p), SIZE, sigma_px=sigma).sil - target) ** 2).mean()
        opt.zero_grad()
        loss.backward()
        opt.step()
    r, h, p = (t.detach() for t in params())
    fitted = cast_rays(Solid(r, h, p), SIZE).mask
    assert iou(fitted, target.bool()) >= 0.98
    assert abs(float(p[0, 0]) - float(pose[0, 0])) <= 1.0, (p, pose)
