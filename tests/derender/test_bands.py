"""Painted bands as a pitch cue: their edges run straightest across the texture unwrapped at the true pitch, and
they pick the pitch of a banded vase whose lip cue alone is fooled by a wavy line under the rim."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.bands import BandCue, band_coherence, high_pass
from radar_cli.derender.refine.fit_shape import axis_from_outline, closed_form, downsample, search_pitch
from radar_cli.derender.refine.shape_config import ShapeFitConfig
from radar_cli.sor.outline import mask_outline
from radar_cli.synth.generator import SynthConfig, make_sample

CAMERA = CameraConfig()


@functools.cache
def synthetic_vase(seed: int, index: int) -> tuple[np.ndarray, np.ndarray, float]:
    """(512 x 512 grey image, bool silhouette, true pitch) of the `radar synth --size 512 --seed SEED` test sample
    INDEX."""
    files, params = make_sample(SynthConfig(size=512, seed=seed), "test", index, None)
    grey = np.clip(files["image.png"], 0, 1).mean(axis=2).astype(np.float32)
    return grey, files["mask.png"] > 0.5, params["pose"][0]


def _banded_vase():
    """A dark vase at 2.7 deg painted with a meander band, flowers and a wavy line just under the rim."""
    return synthetic_vase(7, 45)


def _candidates(mask: np.ndarray, pitches: list[float]):
    target = mask_outline(downsample(mask, 256))
    roll, tx = axis_from_outline(target, 256, CAMERA)
    return closed_form(target, 256, torch.tensor(pitches, dtype=torch.float64), roll, tx, ShapeFitConfig(), CAMERA)


def searched_pitch(grey: np.ndarray, mask: np.ndarray, config: ShapeFitConfig) -> tuple[float, str]:
    """The searched pitch and its cue (fit_shape before the polish, which holds the pitch)."""
    target = mask_outline(downsample(mask, 256))
    image = torch.from_numpy(np.stack([grey, mask.astype(np.float32)]))[None]
    shapes, cue = search_pitch(target, image, 256, config, CAMERA, None, high_pass(grey, mask, BandCue().sigma_px))
    return float(shapes[2][0, 0]), cue


def test_band_edges_are_straightest_at_the_true_pitch():
    grey, mask, truth = _banded_vase()
    shapes = _candidates(mask, [max(truth - 4.0, 0.0), truth, truth + 4.0, truth + 8.0])
    coherence = band_coherence(*high_pass(grey, mask, BandCue().sigma_px), *shapes, BandCue(), CAMERA)
    assert int(coherence.argmax()) == 1, coherence
    assert float(coherence[1]) > 2 * float(coherence[3])


def test_bands_pick_the_pitch_where_the_lip_is_fooled():
    grey, mask, truth = _banded_vase()
    pitch, cue = searched_pitch(grey, mask, ShapeFitConfig())
    assert cue == "band" and abs(pitch - truth) <= 0.5
    fooled, cue = searched_pitch(grey, mask, dataclasses.replace(ShapeFitConfig(), band_ratio=float("inf")))
    assert cue == "lip" and abs(fooled - truth) > 5.0


def test_an_unbanded_vase_is_no_band_cue():
    """A speckled glaze under shading that darkens downwards: no pitch makes its edges run straight, so the
    coherence stays flat over the grid (below the cue's ratio) and the rim and foot do not count as bands."""
    _, mask, _ = _banded_vase()
    rows = np.linspace(0.8, 0.2, mask.shape[0], dtype=np.float32)[:, None]
    speckle = np.random.default_rng(0).normal(0.0, 0.05, mask.shape).astype(np.float32)
    shaded = np.where(mask, rows + speckle, 1.0).astype(np.float32)
    shapes = _candidates(mask, [float(p) for p in np.arange(0.0, 25.1, 0.5)])
    coherence = band_coherence(*high_pass(shaded, mask, BandCue().sigma_px), *shapes, BandCue(), CAMERA)
    assert float(coherence.max()) < ShapeFitConfig().band_ratio * float(coherence.min())
