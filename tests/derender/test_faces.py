"""A face on the photographed object (a head vase, a head-shaped lid) is found; a plain or painted vessel shows none."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from PIL import Image

from radar_cli.derender.export.faces import FLOOR, face_score
from radar_cli.masks.locate import locate_object

N = 512
SHARED = Path(__file__).resolve().parents[3] / "shared" / "data" / "real_vases"


def _blob(grid: tuple[np.ndarray, np.ndarray], cx: float, cy: float, sx: float, sy: float, amp: float) -> np.ndarray:
    yy, xx = grid
    return amp * np.exp(-(((xx - cx) / sx) ** 2 + ((yy - cy) / sy) ** 2))


def _jar(face: bool, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A terracotta jar on grey (N x N x 3 uint8) and its silhouette (N x N bool); with `face`, its body is
    modelled as a head: brows, eye sockets, a nose and a mouth in relief shading."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:N, :N] / N
    half = 0.18 + 0.12 * np.sin(np.clip((yy - 0.12) / 0.8, 0, 1) * np.pi)  # neck to body to foot
    whole = (np.abs(xx - 0.5) < half) & (yy > 0.1) & (yy < 0.92)
    shade = 170 + 60 * np.cos(np.clip((xx - 0.5) / half, -1, 1) * np.pi / 2)  # lit from the front
    tone = shade + rng.normal(0, 4, (N, N))
    if face:
        grid = (yy, xx)
        tone += sum(_blob(grid, 0.5 + dx, 0.45, 0.06, 0.03, -90) for dx in (-0.12, 0.12))  # eye sockets
        tone += sum(_blob(grid, 0.5 + dx, 0.39, 0.08, 0.018, -60) for dx in (-0.12, 0.12))  # brows
        tone += _blob(grid, 0.5, 0.56, 0.025, 0.07, -25) + _blob(grid, 0.5, 0.61, 0.04, 0.015, -50)  # nose
        tone += _blob(grid, 0.5, 0.7, 0.09, 0.02, -80)  # mouth
    tone = cv2.GaussianBlur(tone.astype(np.float32), (0, 0), 3)
    photo = np.where(whole[..., None], np.stack([tone, 0.75 * tone, 0.55 * tone], -1), 128.0)
    return np.clip(photo, 0, 255).astype(np.uint8), whole


def test_a_face_modelled_on_the_body_is_found() -> None:
    photo, whole = _jar(face=True)
    assert face_score(photo, whole) > 0.0


def test_a_plain_jar_shows_no_face() -> None:
    photo, whole = _jar(face=False)
    assert face_score(photo, whole) < 0.0


def test_a_face_off_the_object_does_not_count() -> None:
    """The face is looked for on the object: the same face on the backdrop beside it scores the floor."""
    photo, whole = _jar(face=True)
    assert face_score(photo, np.roll(whole, N // 2, axis=1) & ~whole) == FLOOR
    assert face_score(photo, np.zeros_like(whole)) is None


def test_a_thin_object_is_not_blown_up() -> None:
    """A silhouette one pixel wide is looked at no larger than MAX_SIDE (not 400 x its height)."""
    photo, _ = _jar(face=False)
    sliver = np.zeros((N, N), bool)
    sliver[10:500, 200] = True
    assert face_score(photo, sliver) == FLOOR


@pytest.mark.skipif(not (SHARED / "met_gr_DP107005.jpg").exists(), reason="the shared Met photographs are absent")
@pytest.mark.parametrize("name, has_face", [("met_gr_DP107005", True), ("met_gr_DP117199", False)])
def test_a_glass_head_flask_shows_its_face(name: str, has_face: bool) -> None:
    """A glass jug blown as a head (its face fills the body) against a jug painted with a figure."""
    located = locate_object(np.asarray(Image.open(SHARED / f"{name}.jpg").convert("RGB")), N, name)
    assert (face_score(located.image, located.silhouette | located.appendages) > 0.0) == has_face
