"""The cycles: the shape cycle (loss.cycle_weight; the redraw is the synthetic image, only f_S learns from it) and
the lighting cycle (loss.light_cycle_weight; only f_L and f_A learn from it)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import torch

from radar_cli.errors import ConfigError
from radar_cli.model import losses as L
from radar_cli.model.config import load_run_config
from radar_cli.model.outputs import Decomposition
from radar_cli.model.radar import RadarModel
from radar_cli.render.lighting import tone_map
from radar_cli.render.texture import full_from_front
from radar_cli.synth.render import render_sample
from radar_cli.train.step import (
    Batch,
    background_colour,
    divided_prediction,
    generator_losses,
    light_cycle_term,
    redraw,
    relit,
    render_prediction,
)

from .conftest import box_batch, tiny_config


def _vase(config) -> Decomposition:
    """One hand-made vase with a painted frontal albedo, a two-lobe light and a glossy material."""
    r = config.model.render
    rows = config.model.geometry.n_rows
    y = torch.linspace(0, 1, rows)
    radius = (0.45 + 0.25 * torch.sin(3.0 * y) - 0.2 * y**2)[None]  # 1 x L
    v = torch.linspace(0, 1, r.tex_height)[:, None]
    u = torch.linspace(0, 1, r.tex_width)[None, :]
    albedo = torch.stack([0.2 + 0.6 * v.expand(-1, r.tex_width), 0.5 + 0.4 * torch.sin(9 * u + 4 * v),
                          0.3 + 0.2 * torch.cos(7 * v) * u])[None].clamp(0.05, 0.95)  # 1 x 3 x Ht x Wt linear
    env = torch.full((1, r.env_height, r.env_width), 0.05)
    env[0, 0, r.env_width // 2] = 2.0
    env[0, 1, r.env_width // 3] = 1.0
    return Decomposition(radius, torch.tensor([0.8]), torch.tensor([[12.0, 2.0, 0.03, -0.02]]), albedo, env,
                         torch.tensor([40.0]), torch.tensor([0.6]))


def test_redraw_is_the_image_radar_synth_draws():
    """The cycle's input is drawn exactly as the training data: same pixels as synth.render_sample given the
    mirrored albedo (up to the 8-bit quantisation the dataset's PNGs also have)."""
    config = tiny_config()
    m = config.model
    vase = _vase(config)
    display = tone_map(full_from_front(vase.albedo), m.render.gamma)[0].permute(1, 2, 0).numpy()  # Ht x 3Wt x 3
    sample = render_sample(vase.radius[0].numpy(), 0.8, tuple(vase.pose[0].tolist()), display, vase.env[0].numpy(),
                           40.0, 0.6, m.render.image_size, m.render, m.camera, background=0.9)
    got = redraw(vase, vase.pose, torch.full((1, 3, 1, 1), 0.9), config)[0].permute(1, 2, 0).numpy()
    assert sample.mask.sum() > 100 and (sample.image[~sample.mask] == np.float32(0.9)).all()
    np.testing.assert_allclose(got, sample.image, atol=0.5 / 255 + 1e-4)
    assert np.array_equal(got, np.round(got * 255) / 255)  # quantised like a PNG


def test_background_colour_is_the_mean_off_the_mask():
    image = torch.zeros(2, 3, 4, 4)
    image[0, :, :, :2] = 1.0  # left half white
    mask = torch.zeros(2, 4, 4)
    mask[0, :, 2:] = 1.0  # the object covers the right half: the background is all white
    image[1, 0] = 0.5
    got = background_colour(image, mask)
    assert got.shape == (2, 3, 1, 1)
    assert torch.allclose(got[0].flatten(), torch.ones(3))
    assert torch.allclose(got[1].flatten(), torch.tensor([0.5, 0.0, 0.0]))


def test_geometry_l1_reference():
    ranges = {"radius": (0.0, 1.0), "height": (0.5, 1.0), "pitch": (0.0, 20.0), "roll": (-10.0, 10.0),
              "trans": (-0.2, 0.2)}
    pred = (torch.full((1, 4), 0.5), torch.tensor([0.75]), torch.tensor([[10.0, 0.0, 0.0, 0.0]]))
    target = (torch.full((1, 4), 0.25), torch.tensor([1.0]), torch.tensor([[15.0, 2.0, 0.1, 0.0]]))
    got = L.geometry_l1(pred, target, ranges)
    assert got["radius"].item() == pytest.approx(0.25)
    assert got["height"].item() == pytest.approx(0.5)
    assert got["pose"].item() == pytest.approx((0.25 + 0.1 + 0.25 + 0) / 4)
    assert all(v.item() == 0 for v in L.geometry_l1(pred, pred, ranges).values())


def _model_and_batch(**loss):
    torch.manual_seed(0)
    config = tiny_config(**loss)
    return config, RadarModel(config.model), box_batch(4)


def _networks_with_gradients(model: RadarModel) -> set[str]:
    return {name for name in ("shape_net", "light_net", "albedo_net")
            if any(p.grad is not None and p.grad.abs().sum() > 0 for p in getattr(model, name).parameters())}


@pytest.fixture
def setup():
    return _model_and_batch(cycle_weight=2.0)


@pytest.mark.parametrize("weight, key, other, learners", [
    ("cycle_weight", "cycle", "light_cycle", {"shape_net"}),
    ("light_cycle_weight", "light_cycle", "cycle", {"light_net", "albedo_net"}),
])
def test_each_cycle_trains_only_its_networks_and_is_weighted(weight, key, other, learners):
    config, model, batch = _model_and_batch(**{weight: 3.0})
    terms, _ = generator_losses(model(batch.image), batch, config, None, model)
    assert other not in terms
    cycle = terms[key]
    assert torch.isfinite(cycle) and cycle.item() > 0
    rest = sum(v for k, v in terms.items() if k not in (key, "total"))
    assert torch.allclose(terms["total"], rest + 3.0 * cycle)
    cycle.backward()
    assert _networks_with_gradients(model) == learners
    with pytest.raises(ValueError, match="needs the model"):
        generator_losses(model(batch.image), batch, config, None)


def test_shape_cycle_follows_the_global_rng_and_is_off_by_default(setup):
    config, model, batch = setup
    torch.manual_seed(5)
    pred = model(batch.image)
    terms, _ = generator_losses(pred, batch, config, None, model)
    torch.manual_seed(5)  # the redrawn pitch comes from the global RNG: same seed, same term
    again, _ = generator_losses(model(batch.image), batch, config, None, model)
    assert again["cycle"].item() == terms["cycle"].item()
    off, _ = generator_losses(pred, batch, tiny_config(), None, model)
    assert "cycle" not in off and "light_cycle" not in off


def test_negative_cycle_weight_is_rejected():
    with pytest.raises(ConfigError, match="cycle_weight"):
        tiny_config(cycle_weight=-1.0)


def test_material_l1_reference():
    ranges = {"env": (0.0, 1.0), "alpha": (1.0, 196.0), "rho": (0.0, 2.0)}
    target = (torch.full((1, 3, 2, 2), 0.5), torch.zeros(1, 2, 3), torch.tensor([40.0]), torch.tensor([0.5]))
    pred = (torch.full((1, 3, 2, 2), 0.7), torch.full((1, 2, 3), 0.25), torch.tensor([79.0]), torch.tensor([1.5]))
    got = L.material_l1(pred, target, ranges)
    assert got["albedo"].item() == pytest.approx(0.2)
    assert got["env"].item() == pytest.approx(0.25)
    assert got["alpha"].item() == pytest.approx(39.0 / 195.0)
    assert got["rho"].item() == pytest.approx(0.5)
    assert all(v.item() == 0 for v in L.material_l1(pred, pred, ranges).values())


def test_relit_takes_the_previous_objects_lighting():
    torch.manual_seed(1)
    pred = RadarModel(tiny_config().model)(box_batch(3).image).detach()
    alpha = torch.tensor([5.0, 50.0, 150.0])
    got = relit(pred, alpha)
    assert torch.equal(got.alpha, alpha)
    for kept in ("radius", "height", "pose", "albedo"):
        assert torch.equal(getattr(got, kept), getattr(pred, kept))
    for moved in ("env", "rho"):
        mine, theirs = getattr(got, moved), getattr(pred, moved)
        assert torch.equal(mine[0], theirs[2]) and torch.equal(mine[1], theirs[0]) and torch.equal(mine[2], theirs[1])


@pytest.fixture
def light_setup():
    return _model_and_batch(light_cycle_weight=3.0)


def test_light_cycle_is_learnable(light_setup):
    """A few Adam steps on the term alone lower it: f_L and f_A can read a redraw's lighting and albedo."""
    config, model, batch = light_setup
    with torch.no_grad():
        target = model(batch.image)  # what is redrawn stays fixed, as it would over a short stretch of training
    params = list(model.light_net.parameters()) + list(model.albedo_net.parameters())
    opt = torch.optim.Adam(params, lr=2e-3)
    values = []
    for _ in range(20):
        opt.zero_grad()
        torch.manual_seed(3)  # the same random shininess every step
        loss = light_cycle_term(model, target, background_colour(batch.image, batch.mask), config)
        loss.backward()
        opt.step()
        values.append(loss.item())
    assert values[-1] < 0.7 * values[0]  # measured: 0.59 -> 0.28


def test_negative_light_cycle_weight_is_rejected():
    with pytest.raises(ConfigError, match="light_cycle_weight"):
        tiny_config(light_cycle_weight=-0.5)


def test_cycles_can_redraw_with_the_divided_albedo():
    """loss.cycle_albedo = "divided": the cycles redraw the prediction with the input divided by its shading
    (detached, in [0, 1], f_A's albedo kept where the true silhouette is off), and train the same networks."""
    config, model, batch = _model_and_batch(cycle_weight=1.0, light_cycle_weight=1.0, cycle_albedo="divided")
    pred = model(batch.image)
    _, shading, _, _ = render_prediction(pred, config)
    divided = divided_prediction(pred, shading, batch, config)
    assert not divided.albedo.requires_grad and divided.albedo.shape == pred.albedo.shape
    assert 0 <= divided.albedo.min() and divided.albedo.max() <= 1
    assert not torch.allclose(divided.albedo, pred.albedo.detach())
    for kept in ("radius", "height", "pose", "env", "alpha", "rho"):
        assert torch.equal(getattr(divided, kept), getattr(pred, kept).detach())
    off = Batch(batch.image, torch.zeros_like(batch.mask), batch.dt)
    assert torch.allclose(divided_prediction(pred, shading, off, config).albedo, pred.albedo.detach())
    torch.manual_seed(2)
    terms, _ = generator_losses(pred, batch, config, None, model)
    torch.manual_seed(2)
    network = dataclasses.replace(config, loss=dataclasses.replace(config.loss, cycle_albedo="network"))
    plain, _ = generator_losses(model(batch.image), batch, network, None, model)
    assert terms["light_cycle"].item() != plain["light_cycle"].item()  # another albedo redrawn and asked back
    (terms["cycle"] + terms["light_cycle"]).backward()
    assert _networks_with_gradients(model) == {"shape_net", "light_net", "albedo_net"}


def test_unknown_cycle_albedo_is_rejected(tmp_path):
    path = tmp_path / "run.toml"
    path.write_text('[loss]\ncycle_albedo = "painted"\n')
    with pytest.raises(ConfigError, match="cycle_albedo"):
        load_run_config(path)
