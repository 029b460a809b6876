"""Outline support: a silhouette on the object's edge has an edge across nearly all its outline; the same
silhouette moved sideways off the object does not, and the quality status sends it to review."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from radar_cli.derender.export.quality import QualityLimits, assess_drawn, support
from radar_cli.derender.export.renders import InputDrawing
from radar_cli.derender.run.inputs import Prepared, located_input, white_backdrop
from radar_cli.masks.crop import CropBox
from radar_cli.masks.outline import edge_contrast, outline_support
from radar_cli.masks.synthetic import composite, render_vases
from radar_cli.masks.variants import make_variant

SIZE = 64  # the network's side; the outline is measured at the output side (256 here)


@pytest.fixture(scope="module")
def vase() -> tuple[np.ndarray, np.ndarray]:
    """A rendered vase pasted over a gradient studio backdrop, framed tight: (photo, truth)."""
    vases, alpha, masks = render_vases(1, 160, seed=5)
    rng = np.random.default_rng(6)
    photo, truth = composite(vases[0], alpha[0], masks[0], "gradient", rng, shape=(360, 300))
    tight = make_variant("tight", photo, truth, rng)
    return tight.image, tight.truth


def shifted(prepared, fraction: float = 0.2):
    """The prepared input with its silhouette moved sideways by `fraction` of its width (the photo kept)."""
    cols = np.nonzero(prepared.photo_silhouette.any(0))[0]
    moved = np.roll(prepared.photo_silhouette, int(fraction * (cols.max() - cols.min())), axis=1)
    return dataclasses.replace(prepared, photo_silhouette=moved,
                               photo_image=white_backdrop(prepared.photo_scene, moved))


def test_a_disc_on_a_plain_backdrop_is_supported_and_a_moved_one_is_not() -> None:
    yy, xx = np.mgrid[:128, :128]
    disc = (yy - 64) ** 2 + (xx - 64) ** 2 < 30**2
    image = np.where(disc[..., None], np.uint8(90), np.uint8(200)).repeat(3, axis=2)
    assert outline_support(image, disc) == 1.0
    assert outline_support(image, np.roll(disc, 20, axis=1)) < 0.6
    assert outline_support(image, disc, contrast=200.0) == 0.0  # the colour step is ~190


def test_unmeasurable_readings_are_left_out() -> None:
    yy, xx = np.mgrid[:128, :128]
    disc = (yy - 64) ** 2 + (xx - 64) ** 2 < 30**2
    image = np.full((128, 128, 3), 200, np.uint8)
    everywhere = len(edge_contrast(image, disc))
    right = np.ones((128, 128), bool)
    right[:, 90:] = False
    assert 0 < len(edge_contrast(image, disc, right)) < everywhere
    assert outline_support(image, disc, np.zeros((128, 128), bool)) is None


def _drawn_as_located(prepared) -> InputDrawing:
    """A solid drawn exactly on the located silhouette, the photo its reconstruction, no highlight."""
    sil = prepared.photo_silhouette
    return InputDrawing(sil, np.zeros_like(sil), prepared.photo_image, np.zeros(sil.shape, np.uint8))


def test_located_silhouette_is_supported_and_shifted_one_is_review(vase: tuple) -> None:
    photo, _ = vase
    prepared = located_input(photo, SIZE, "vase", resolution=256)
    assert prepared.side == 256 and prepared.photo_scene is not prepared.photo_image
    assert support(prepared) >= 0.9
    moved = shifted(prepared)
    assert support(moved) < QualityLimits().review_support
    # the solid drawn exactly on the shifted silhouette, its reconstruction the input: only the outline tells
    record = assess_drawn(moved, _drawn_as_located(moved))
    assert record["status"] in ("review", "failed")
    assert any("edge" in r for r in record["reasons"]), record["reasons"]
    good = assess_drawn(prepared, _drawn_as_located(prepared))
    assert good["outline_support"] >= 0.9 and not any("edge" in r for r in good["reasons"])


def test_frame_cut_is_not_counted() -> None:
    """A disc that the photo's top edge cuts: the crop's padding above the photo shows no edge against it (it
    is painted in the disc's colour here) and is left out, so the support stays full."""
    yy, xx = np.mgrid[:128, :128]
    disc = ((yy - 40) ** 2 + (xx - 64) ** 2 < 30**2) & (yy >= 32)  # the photo starts at the crop's row 32
    scene = np.where(disc[..., None], np.uint8(90), np.uint8(200)).repeat(3, axis=2)
    scene[:32] = 90
    prepared = Prepared(scene, CropBox(0, -32, 128), (128, 96), silhouette=disc)
    assert outline_support(scene, disc) < 0.9  # the cut itself has no edge
    assert support(prepared) == 1.0
