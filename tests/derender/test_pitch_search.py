"""The test-time pitch search: its parabola, that it finds the pitch a silhouette was drawn at, and that the
predictor applies it only where the silhouette is known."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import torch

from radar_cli.derender.refine.pitch_search import PitchSearch, _grid_scores, parabola_vertex, score, search_pitch
from radar_cli.derender.run.predictor import ASSETS, Predictor
from radar_cli.errors import InputError
from radar_cli.model.losses import distance_transform
from radar_cli.sor.solid import Solid

from .test_predictor import save_weights, tiny_config

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_parabola_vertex_is_exact_on_a_parabola() -> None:
    grid = torch.arange(-1.5, 1.51, 0.5)  # G = 7
    vertex = torch.tensor([0.3, -0.2, 1.2, -1.7])
    scores = (grid[None] - vertex[:, None]) ** 2 + 5.0  # B x G
    best = grid[scores.argmin(1)]
    found = best + parabola_vertex(scores, 0.5)
    assert torch.allclose(found[:2], vertex[:2], atol=1e-5)
    assert torch.allclose(found[2], vertex[2], atol=1e-5)  # its best grid point, 1.0, is inner
    assert found[3] == -1.5  # best at the end of the grid: no extrapolation


def test_flat_scores_give_no_offset() -> None:
    assert torch.equal(parabola_vertex(torch.ones(2, 5), 0.5), torch.zeros(2))


@pytest.mark.skipif(not any(ASSETS.glob("*.safetensors")) or not EXAMPLES.is_dir(), reason="no bundled model")
def test_search_finds_the_pitch_a_silhouette_was_drawn_at() -> None:
    """With the silhouette term alone and outlines drawn from f_S's own profile at known pitches, the search lands
    near each pitch whatever f_S said (at 64 px a hard outline pins pitch to about a degree: measured mean error
    0.57 deg over these nine, 1.6 at most; f_S 4.6), and it keeps f_S's profile and the rest of the pose."""
    from PIL import Image

    from radar_cli.render.raycast import cast_rays

    model = Predictor.from_checkpoint(None, "cpu").model
    cfg = model.config
    outline_only = PitchSearch(im_weight=0.0, alb_weight=0.0, prior_weight=0.0, dt_margin_px=0.0)
    searched, guessed = [], []
    for path in sorted(EXAMPLES.glob("*.png"))[:3]:
        photo = np.array(Image.open(path).convert("RGB").resize((64, 64)))
        image = torch.from_numpy(photo).permute(2, 0, 1)[None].float() / 255  # 1 x 3 x 64 x 64
        with torch.no_grad():
            first = model(image)
        for true_pitch in (3.7, 9.1, 15.8):
            pose = first.pose.clone()
            pose[:, 0] = true_pitch
            with torch.no_grad():
                sil = cast_rays(Solid(first.radius, first.height, pose), 64, cfg.camera, cfg.render.sil_sigma_px).sil
            found = search_pitch(model, image, [sil[0].numpy() > 0.5], first, outline_only)
            assert torch.equal(found.radius, first.radius) and torch.equal(found.pose[:, 1:], first.pose[:, 1:])
            searched.append(abs(found.pose[0, 0].item() - true_pitch))
            guessed.append(abs(first.pose[0, 0].item() - true_pitch))
    assert np.mean(searched) < 1.2 and max(searched) < 2.5, searched
    assert np.mean(searched) < 0.3 * np.mean(guessed), (searched, guessed)


def test_predictor_searches_only_where_the_silhouette_is_known(tmp_path: Path) -> None:
    path = save_weights(tmp_path / "tiny.safetensors", tiny_config())
    rng = np.random.default_rng(2)
    images = [rng.integers(0, 256, (32, 32, 3), dtype=np.uint8) for _ in range(3)]
    disc = np.hypot(*np.mgrid[-16:16, -16:16]) < 10
    network = Predictor.from_checkpoint(path, "cpu", albedo="network").predict(images)
    searched = Predictor.from_checkpoint(path, "cpu", albedo="network", pitch="search").predict(
        images, [disc, None, disc])
    assert torch.equal(searched.pose[1], network.pose[1]) and torch.equal(searched.albedo[1], network.albedo[1])
    assert torch.equal(searched.radius, network.radius) and torch.equal(searched.pose[:, 1:], network.pose[:, 1:])
    lo, hi = tiny_config().model.geometry.pitch_range
    assert ((searched.pose[:, 0] >= lo) & (searched.pose[:, 0] <= hi)).all()
    # where searched, f_L and f_A re-read the texture at the new pitch
    moved = [i for i in (0, 2) if searched.pose[i, 0] != network.pose[i, 0]]
    assert moved, "the search kept f_S's pitch on both objects"
    for i in moved:
        assert not torch.equal(searched.albedo[i], network.albedo[i])
    with pytest.raises(InputError, match="silhouettes"):
        Predictor.from_checkpoint(path, "cpu", pitch="search").predict(images, [np.ones((16, 16), bool)] * 3)
    # no silhouettes at all: f_S's pitch
    assert torch.equal(Predictor.from_checkpoint(path, "cpu", albedo="network", pitch="search").predict(images).pose,
                       network.pose)


def test_grid_scores_in_chunks_equal_one_redraw_per_candidate(tmp_path: Path) -> None:
    """The candidates are redrawn as one batch, cut into chunks by `max_pixels`: every chunking (a sample at a
    time, two, all five) gives each candidate the score it gets redrawn alone."""
    model = Predictor.from_checkpoint(save_weights(tmp_path / "tiny.safetensors", tiny_config()), "cpu").model
    torch.manual_seed(0)
    image = torch.rand(5, 3, 32, 32)
    masks = [np.hypot(*np.mgrid[-16:16, -16:16]) < r for r in (6, 8, 10, 12, 14)]
    mask = torch.from_numpy(np.stack(masks).astype(np.float32))  # 5 x 32 x 32
    dt = torch.from_numpy(np.stack([distance_transform(m) for m in masks]))
    candidates = torch.tensor([[0.0, 4.0, 8.0], [3.0, 11.0, 30.0], [1.5, 2.5, 19.0], [7.0, 7.0, 9.0],
                               [-5.0, 12.0, 16.0]])  # 5 x 3, two outside the range (clamped)
    with torch.no_grad():
        first = model(image)
        lo, hi = model.config.geometry.pitch_range
        alone = torch.stack([score(model, image, mask, dt, first, candidates[:, j].clamp(lo, hi), PitchSearch())
                             for j in range(3)], dim=1)
        for samples_per_pass in (1, 2, 5):
            chunked = PitchSearch(max_pixels=samples_per_pass * 3 * 32 * 32)
            got = _grid_scores(model, image, mask, dt, first, candidates, chunked)
            assert got.shape == (5, 3)
            assert torch.allclose(got, alone, rtol=1e-5, atol=1e-6), samples_per_pass
    assert torch.equal(alone[3, 0], alone[3, 1])  # the same pitch twice scores the same


def test_pitch_source_is_checked(tmp_path: Path) -> None:
    path = save_weights(tmp_path / "tiny.safetensors", tiny_config())
    with pytest.raises(InputError, match="pitch source"):
        Predictor.from_checkpoint(path, "cpu", pitch="guess")  # type: ignore[arg-type]
    predictor = Predictor.from_checkpoint(path, "cpu")
    with pytest.raises(InputError, match="RadarModel"):
        Predictor(lambda x: predictor.model(x), predictor.setup, "fake", "cpu", pitch="search")
    assert dataclasses.is_dataclass(PitchSearch())
