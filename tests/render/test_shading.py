"""One-texel environment light: Lambert diffuse value and the Eq. 7-8 specular peak within 2%."""

from __future__ import annotations

import math

import torch

from radar_cli.config import RenderConfig
from radar_cli.render import lighting
from radar_cli.render.lighting import compose, decompose, env_directions, power, shading_factors, tone_map
from radar_cli.render.material import Material
from radar_cli.render.scene import shade
from radar_cli.sor.solid import Solid

HE, WE = 16, 48


def one_texel_env(i: int, j: int, value: float = 3.0) -> torch.Tensor:
    env = torch.zeros(1, HE, WE)
    env[0, i, j] = value
    return env


def test_lambert_value_on_a_white_cylinder():
    i, j, value = 6, 20, 3.0
    env = one_texel_env(i, j, value)
    dirs, solid = env_directions(HE, WE)
    light, w = dirs[i * WE + j], solid[i * WE + j]
    radius = torch.full((1, 32), 0.4)
    height, pose = torch.tensor([0.8]), torch.zeros(1, 4)
    cfg = RenderConfig(shading_height=32, shading_width=32)
    albedo = torch.ones(1, 3, 32, 32)
    shading = shade(Solid(radius, height, pose), Material(albedo, env, torch.tensor([10.0]), torch.tensor([0.0])), cfg)
    # a cylinder at zero pose: normals are horizontal, n = (sin phi, 0, -cos phi)
    expected = value * w * (shading.normals[0].permute(1, 2, 0) @ light).clamp_min(0)  # Ht x Wt
    assert (shading.normals[0, 1].abs() < 1e-5).all()
    lit = expected > 0.05 * expected.max()
    assert lit.any()
    rel = (shading.diffuse[0, 0][lit] - expected[lit]).abs() / expected[lit]
    assert rel.max() <= 0.02
    assert torch.allclose(shading.texture[0, :, lit], tone_map(expected[lit]).expand(3, -1), rtol=0.02)


def test_specular_peak_matches_normalised_phong():
    i, j, value = 5, 27, 2.0
    dirs, solid = env_directions(HE, WE)
    light, w = dirs[i * WE + j], solid[i * WE + j]
    view = torch.tensor([0.3, -0.2, -1.0])
    view = view / view.norm()
    half = (light + view) / (light + view).norm()  # mirror direction: R = P exactly at this normal
    tilt = torch.tensor([0.0, 1.0, 0.0])
    axis = torch.linalg.cross(half, tilt)
    tilted = half * math.cos(0.05) + axis / axis.norm() * math.sin(0.05)
    normals = torch.stack([half, tilted])[None, None]  # 1 x 1 x 2 x 3
    views = view.expand(1, 1, 2, 3)
    for alpha in (1.0, 20.0, 150.0):
        diffuse, specular = shading_factors(normals, views, one_texel_env(i, j, value), torch.tensor([alpha]))
        peak = (alpha + 1) / (2 * math.pi) * value * w
        assert abs(float(specular[0, 0, 0]) - peak) <= 0.02 * peak
        assert float(specular[0, 0, 1]) < float(specular[0, 0, 0])  # the lobe falls off away from the mirror
        assert abs(float(diffuse[0, 0, 0]) - value * w * float(light @ half)) <= 0.02 * value * w


def test_compose_is_tone_mapped_sum():
    albedo = torch.rand(2, 3, 4, 5)
    diffuse, specular = torch.rand(2, 4, 5), torch.rand(2, 4, 5)
    rho = torch.tensor([0.3, 0.7])
    out = compose(albedo, diffuse, specular, rho)
    ref = (albedo * diffuse[:, None] + rho[:, None, None, None] * specular[:, None]) ** (1 / 2.2)
    assert torch.allclose(out, ref, atol=1e-5)


def test_decompose_inverts_compose():
    g = torch.Generator().manual_seed(0)
    albedo = torch.rand(2, 3, 5, 7, generator=g) * 0.9 + 0.05  # B x 3 x Ht x Wt
    diffuse = torch.rand(2, 1, 5, 7, generator=g) + 0.2
    specular = torch.rand(2, 1, 5, 7, generator=g) * 0.3
    rho = torch.tensor([0.5, 1.2])
    texture = compose(albedo, diffuse, specular, rho)
    assert torch.allclose(decompose(texture, diffuse, specular, rho), albedo, atol=1e-5)
    # B x Ht x Wt shading maps are taken as compose takes them
    assert torch.allclose(decompose(texture, diffuse[:, 0], specular[:, 0], rho), albedo, atol=1e-5)


def test_decompose_caps_the_highlight_and_clamps():
    texture = torch.full((1, 3, 1, 2), 0.5)
    radiance = 0.5**2.2
    # a highlight twice the whole radiance: only 80% of the radiance is taken as highlight, not all of it
    specular = torch.full((1, 1, 1, 2), 2 * radiance)
    albedo = decompose(texture, torch.ones(1, 1, 1, 2), specular, torch.ones(1), max_specular_share=0.8)
    assert torch.allclose(albedo, torch.full_like(albedo, 0.2 * radiance), atol=1e-6)
    # no diffuse light on a lit texel: the albedo is unknown and clamped into [0, 1]
    dark = decompose(texture, torch.zeros(1, 1, 1, 2), torch.zeros(1, 1, 1, 2), torch.ones(1))
    assert dark.min() >= 0 and dark.max() <= 1


def test_fast_forward_and_autograd_paths_match_the_direct_sum(monkeypatch):
    """The in-place forward used without gradients, the kept-chunk forward used in training and a direct float64
    sum of Eq. 6-7 agree, across several chunks."""
    monkeypatch.setattr(lighting, "CHUNK_ELEMENTS", 2 * 50 * 192)  # 50 samples a chunk: 8 chunks
    torch.manual_seed(3)
    n = torch.nn.functional.normalize(torch.randn(2, 9, 40, 3), dim=-1)
    view = torch.nn.functional.normalize(torch.randn(2, 9, 40, 3) + torch.tensor([0.0, 0.0, 2.0]), dim=-1)
    env, alpha = torch.rand(2, 8, 24), torch.tensor([3.0, 150.0])
    dirs, solid = env_directions(8, 24, dtype=torch.float64)
    nd, vd = n.double().reshape(2, -1, 3), view.double().reshape(2, -1, 3)
    ln = nd @ dirs.T
    mirror = 2 * (nd * vd).sum(-1, keepdim=True) * nd - vd
    rp = (mirror @ dirs.T).clamp_min(0) * (ln > 0)
    rad = env.double().reshape(2, -1) * solid
    want_d = (ln.clamp_min(0) * rad[:, None]).sum(-1).view(2, 9, 40)
    a = alpha.double()[:, None, None]
    want_s = ((a + 1) / (2 * math.pi) * rp ** a * rad[:, None]).sum(-1).view(2, 9, 40)
    with torch.no_grad():
        fast = shading_factors(n, view, env, alpha)
    kept = shading_factors(n.requires_grad_(), view, env, alpha)
    for got in (fast, kept):
        torch.testing.assert_close(got[0].double(), want_d, rtol=1e-4, atol=1e-5)
        torch.testing.assert_close(got[1].double(), want_s, rtol=1e-4, atol=1e-5)


def test_power_matches_pow_with_its_gradient():
    x = torch.rand(50, dtype=torch.float64).add_(1e-3).requires_grad_()
    y = power(x, 1 / 2.2)
    torch.testing.assert_close(y, x.detach() ** (1 / 2.2))
    (g,) = torch.autograd.grad(y.sum(), x)
    torch.testing.assert_close(g, (1 / 2.2) * x.detach() ** (1 / 2.2 - 1))
