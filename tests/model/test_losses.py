"""Every loss term: reference values, finite and non-negative, and gradients into exactly the right networks."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from radar_cli.model import losses as L
from radar_cli.model.discriminator import PatchDiscriminator
from radar_cli.model.radar import RadarModel
from radar_cli.render.lighting import compose, tone_map
from radar_cli.render.raycast import cast_rays
from radar_cli.render.scene import render_front, shade
from radar_cli.train.step import generator_losses

from .conftest import box_batch, tiny_config


def test_distance_transform_reference():
    mask = np.zeros((8, 8), bool)
    mask[:, 0] = True
    dt = L.distance_transform(mask)
    assert dt[:, 0].max() == 0
    np.testing.assert_allclose(dt[4, 3], 3 / 8, atol=1e-6)
    assert (L.distance_transform(np.zeros((4, 4), bool)) == 0).all()


def test_reference_values():
    sil = torch.tensor([[[1.0, 0.0], [0.5, 0.0]]])
    target = torch.tensor([[[1.0, 0.0], [0.0, 0.0]]])
    dt = torch.tensor([[[0.0, 0.5], [0.5, 1.0]]])
    # MSE = 0.25 / 4, dt term = 0.25 / 4
    assert L.silhouette_loss(sil, target, dt, 10.0, 100.0).item() == pytest.approx(10 * 0.0625 + 100 * 0.0625)
    # a 0.5 px margin (0.25 of this 2 px image's side) leaves dt = 0.5 -> 0.25 under the halo pixel
    assert L.silhouette_loss(sil, target, dt, 10.0, 100.0, margin_px=0.5).item() == pytest.approx(
        10 * 0.0625 + 100 * 0.125 / 4)
    pred, tgt = torch.zeros(1, 3, 2, 2), torch.ones(1, 3, 2, 2)
    weight = torch.tensor([[[[1.0, 0.0], [0.0, 0.0]]]])
    assert L.masked_l1(pred, tgt, weight).item() == pytest.approx(1.0)
    assert L.diffuse_loss(torch.full((2, 1, 4, 4), 0.55), 0.5, 0.1).item() == 0
    assert L.diffuse_loss(torch.full((2, 1, 4, 4), 0.8), 0.5, 0.1).item() == pytest.approx(0.04)
    albedo = torch.arange(8.0).view(1, 2, 2, 2).expand(1, 3, 2, 2, 2)[:, :, 0]
    assert torch.allclose(L.mean_color(albedo), albedo.mean(dim=(2, 3), keepdim=True).expand_as(albedo))


def test_per_sample_terms_score_each_sample_alone():
    """per_sample=True gives each sample the value a batch of one would (the pitch search ranks them so)."""
    g = torch.Generator().manual_seed(0)
    sil, target = torch.rand(3, 8, 8, generator=g), (torch.rand(3, 8, 8, generator=g) > 0.5).float()
    dt = torch.rand(3, 8, 8, generator=g)
    pred, image = torch.rand(3, 3, 8, 8, generator=g), torch.rand(3, 3, 8, 8, generator=g)
    weight = torch.rand(3, 1, 8, 8, generator=g) * (torch.arange(3) > 0).view(3, 1, 1, 1)  # one empty weight
    sil_each = L.silhouette_loss(sil, target, dt, 10.0, 100.0, 1.0, per_sample=True)
    l1_each = L.masked_l1(pred, image, weight, per_sample=True)
    assert sil_each.shape == l1_each.shape == (3,) and l1_each[0] == 0
    for i in range(3):
        one = slice(i, i + 1)
        assert sil_each[i].item() == pytest.approx(L.silhouette_loss(sil[one], target[one], dt[one], 10.0, 100.0,
                                                                     1.0).item(), rel=1e-6)
        assert l1_each[i].item() == pytest.approx(L.masked_l1(pred[one], image[one], weight[one]).item(), rel=1e-6)
    assert sil_each.mean().item() == pytest.approx(L.silhouette_loss(sil, target, dt, 10.0, 100.0, 1.0).item())


def test_patches_split_by_specular_variance():
    torch.manual_seed(0)
    albedo = torch.rand(2, 3, 32, 32)
    specular = torch.zeros(2, 1, 32, 32)
    specular[:, :, :, 16:] = torch.rand(2, 1, 32, 16) * 5  # the right half is specular
    real, fake = L.sample_patches(albedo, specular, 8, 16, 0.25)
    assert real.shape == fake.shape == (8, 3, 8, 8)
    # the "real" group comes from the flat (non-specular) left half: its patches match albedo columns < 16
    assert any(torch.equal(real[0], albedo[b, :, y : y + 8, x : x + 8]) for b in range(2)
               for y in range(25) for x in range(9))


def _grads(module: torch.nn.Module) -> bool:
    return any(p.grad is not None and p.grad.abs().sum() > 0 for p in module.parameters())


@pytest.fixture
def setup():
    torch.manual_seed(0)
    config = tiny_config()
    model = RadarModel(config.model)
    disc = PatchDiscriminator(config.loss.sad_patch, 8, 32)
    return config, model, disc, box_batch(4)


def _terms(setup):
    config, model, disc, batch = setup
    pred = model(batch.image)
    terms, rendered = generator_losses(pred, batch, config, disc)
    return pred, terms, rendered


@pytest.mark.parametrize("term,expect", [
    ("sil", {"shape_net"}),
    ("im", {"shape_net", "light_net", "albedo_net"}),
    ("alb", {"shape_net", "light_net", "albedo_net"}),
    ("diff", {"shape_net", "light_net"}),
    ("sad", {"albedo_net"}),
])
def test_loss_gradients_reach_the_right_networks(setup, term, expect):
    config, model, disc, batch = setup
    _, terms, _ = _terms(setup)
    if term == "diff":  # make sure the regulariser is active (outside the margin)
        assert terms["diff"].item() > 0 or pytest.skip("diffuse mean inside the margin at init")
    value = terms[term]
    assert torch.isfinite(value) and value.item() >= 0
    value.backward()
    got = {name for name in ("shape_net", "light_net", "albedo_net") if _grads(getattr(model, name))}
    assert got == expect
    assert all(p.grad is None for p in disc.parameters()), "a generator loss must not update D"


def test_discriminator_loss_updates_only_d(setup):
    config, model, disc, batch = setup
    _, terms, rendered = _terms(setup)
    d_loss = L.sad_discriminator_loss(disc, rendered.sad_real, rendered.sad_fake)
    assert torch.isfinite(d_loss) and d_loss.item() >= 0
    d_loss.backward()
    assert _grads(disc)
    assert all(p.grad is None for p in model.parameters())


def test_total_is_weighted_sum_and_switches(setup):
    config, model, disc, batch = setup
    _, terms, _ = _terms(setup)
    lc = config.loss
    expected = (terms["sil"] + lc.im_weight * terms["im"] + lc.alb_weight * terms["alb"]
                + lc.diff_weight * terms["diff"] + lc.sad_weight * terms["sad"])
    assert torch.allclose(terms["total"], expected)
    ablated = tiny_config(no_alb=True, no_sad=True, no_diff=True)
    terms2, _ = generator_losses(model(batch.image), batch, ablated, disc)
    assert set(terms2) == {"sil", "im", "total"}


def test_mean_colour_render_matches_compose(setup):
    """L_alb renders the same shading with the albedo replaced by its mean colour."""
    config, model, _, batch = setup
    with torch.no_grad():
        d = model(batch.image)
        sh = shade(d.solid, d.material, config.model.render)
        tex = compose(L.mean_color(d.albedo), sh.diffuse, sh.specular, d.rho)
        hits = cast_rays(d.solid, 32)
        img, front = render_front(hits, tex)
    assert img.shape == (4, 3, 32, 32) and front.shape == (4, 1, 32, 32)
    assert torch.allclose(tone_map(d.albedo.mean(dim=(2, 3))[..., None, None] * sh.diffuse
                                   + d.rho[:, None, None, None] * sh.specular), tex, atol=1e-5)


def test_supervised_loss_zero_on_truth(setup):
    config, model, _, batch = setup
    from radar_cli.train.step import output_ranges

    d = model(batch.image).detach()
    terms = L.supervised_loss(d, d, output_ranges(config))
    assert all(v.item() == 0 for v in terms.values())
    d2 = model(batch.image)
    other = d.map(lambda t: t.detach() * 0.9)
    total = sum(L.supervised_loss(d2, other, output_ranges(config)).values())
    total.backward()
    assert _grads(model.shape_net) and _grads(model.light_net) and _grads(model.albedo_net)
