"""Autograd against central finite differences, for a silhouette loss (r, h, pitch, roll, tx,
ty) and for a texture-rendering loss (texture and shape). Float64 so the differences are not rounding noise."""

from __future__ import annotations

import torch
import torch.nn.functional as F

from radar_cli.render.raycast import cast_rays
from radar_cli.render.texture import render_texture
from radar_cli.sor.solid import Solid

SIZE = 48
N = 3


def cosine(a: torch.Tensor, b: torch.Tensor) -> float:
    return float(F.cosine_similarity(a.reshape(1, -1), b.reshape(1, -1)).item())


def central_differences(loss_fn, params: list[torch.Tensor], which: int, step: float) -> torch.Tensor:
    """d loss_b / d params[which][b, j] for every batch item b and column j (loss_fn returns per-item losses)."""
    base = params[which]
    flat = base.reshape(N, -1)
    grad = torch.zeros_like(flat)
    for j in range(flat.shape[1]):
        plus, minus = flat.clone(), flat.clone()
        plus[:, j] += step
        minus[:, j] -= step
        args_p = [p if i != which else plus.reshape(base.shape) for i, p in enumerate(params)]
        args_m = [p if i != which else minus.reshape(base.shape) for i, p in enumerate(params)]
        grad[:, j] = (loss_fn(*args_p) - loss_fn(*args_m)) / (2 * step)
    return grad.reshape(base.shape)


def autograd(loss_fn, params: list[torch.Tensor]) -> list[torch.Tensor]:
    leaves = [p.clone().requires_grad_(True) for p in params]
    loss_fn(*leaves).sum().backward()
    return [p.grad for p in leaves]


def test_silhouette_loss_gradients_match_finite_differences(random_sor):
    radius, height, pose = random_sor(N, seed=3)
    tr, th, tp = random_sor(N, seed=4)
    target = cast_rays(Solid(tr, th, tp), SIZE).sil.detach()

    def loss(r, h, p):
        return ((cast_rays(Solid(r, h, p), SIZE).sil - target) ** 2).sum(dim=(1, 2))

    params = [radius, height, pose]
    grads = autograd(loss, params)
    fd_r = central_differences(loss, params, 0, 1e-4)
    assert cosine(grads[0], fd_r) >= 0.95, "radius"
    fd_h = central_differences(loss, params, 1, 1e-4)
    assert cosine(grads[1], fd_h) >= 0.95, "height"
    fd_p = central_differences(loss, params, 2, 1e-3)
    for k, name in enumerate(["pitch", "roll", "tx", "ty"]):
        assert cosine(grads[2][:, k], fd_p[:, k]) >= 0.95, name


def test_texture_render_loss_gradients_match_finite_differences(random_sor):
    radius, height, pose = random_sor(N, seed=5)
    # seen from the side (pitch 0, object not below the camera) the mouth and base are hidden: the rim's
    # occlusion edge (outer wall -> inner wall) is a true discontinuity that finite differences cannot follow
    pose[:, 0] = 0.0
    pose[:, 3] = pose[:, 3].abs()
    g = torch.Generator().manual_seed(6)
    texture = F.interpolate(torch.rand(N, 3, 4, 12, generator=g, dtype=torch.float64), size=(16, 48),
                            mode="bilinear", align_corners=False)
    weights = torch.rand(N, 3, SIZE, SIZE, generator=g, dtype=torch.float64)

    def loss(r, h, p, tex):
        image, _ = render_texture(cast_rays(Solid(r, h, p), SIZE), tex)
        return (image * weights).sum(dim=(1, 2, 3))

    params = [radius, height, pose, texture]
    grads = autograd(loss, params)
    # the texture enters linearly: a few texels suffice, but compare all of them through a random direction too
    direction = torch.randn(texture.shape, generator=g, dtype=torch.float64)
    fd_dir = (loss(*params[:3], texture + 1e-3 * direction) - loss(*params[:3], texture - 1e-3 * direction)) / 2e-3
    assert torch.allclose((grads[3] * direction).sum(dim=(1, 2, 3)), fd_dir, rtol=1e-6, atol=1e-8)
    # small steps: fewer pixels cross the few remaining discontinuities (argmin switches of misses' colours)
    assert cosine(grads[0], central_differences(loss, params, 0, 1e-5)) >= 0.95, "radius"
    assert cosine(grads[1], central_differences(loss, params, 1, 1e-5)) >= 0.95, "height"
    fd_p = central_differences(loss, params, 2, 1e-5)
    for k, name in enumerate(["pitch", "roll", "tx", "ty"]):
        assert cosine(grads[2][:, k], fd_p[:, k]) >= 0.95, name
