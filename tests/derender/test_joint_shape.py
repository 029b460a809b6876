"""The shared profile of a multi-view object keeps the corners each view's own fit keeps: a column-krater's rim
over the neck and its shoulder's step (the bending is capped at corners as in the single-view fit)."""

from __future__ import annotations

import numpy as np
import pytest

from radar_cli.derender.multiview.joint_shape import fit_jointly
from radar_cli.derender.refine.fit_shape import fit_shape

from .test_level_krater import render_level_krater


@pytest.fixture(scope="module")
def krater():
    photo, mask, radius = render_level_krater()
    own = fit_shape(mask, photo.astype(np.float32).mean(2) / 255.0)
    return mask, radius, own


def _step(profile: np.ndarray) -> float:
    """The shoulder's step of a 64-row profile (radii over half-height): the widest of the shoulder's rows less
    the narrowest of the neck's just above it."""
    return float(profile[18:24].max() - profile[12:18].min())


def test_the_shared_profile_keeps_the_rim_and_the_shoulder_step(krater) -> None:
    mask, radius, own = krater
    mirrored = mask[:, ::-1].copy()  # the back: the same solid, its outline mirrored
    geos, errors = fit_jointly([mask, mirrored], [own, own])
    shared = (geos[0].radius[0] / geos[0].height[0]).numpy()
    alone = (own.radius[0] / own.height[0]).numpy()
    assert _step(alone) > 0.9 * _step(radius / 0.8)  # the single view reads the step
    # the shared profile is the views' own (they agree): no corner rounded off, no step overshot
    assert abs(_step(shared) - _step(alone)) < 0.05 * _step(alone), (_step(shared), _step(alone))
    assert float(np.abs(shared - alone).mean()) < 0.005
    assert max(errors) < 1.5 * own.outline_error + 0.2, (errors, own.outline_error)
