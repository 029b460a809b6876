"""The closed-form outline against the ray caster's silhouette (its ends, and the pixels its rows draw), and
mask_outline's sub-pixel ends."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import radar_cli.sor.conic_lines as conic_lines
from radar_cli.config import CameraConfig
from radar_cli.masks.refine import iou
from radar_cli.render.raycast import cast_rays, hit_mask
from radar_cli.sor.outline import mask_outline, outline, row_mask, vertical_extent
from radar_cli.sor.solid import Solid

SIZE = 192


def _vase(pitch: float, roll: float = 0.0, tx: float = 0.0, ty: float = 0.0):
    y = torch.linspace(1, -1, 24)
    radius = (0.4 + 0.25 * torch.sin(2.2 * y + 0.5) ** 2 - 0.1 * y)[None].clamp(0.1, 0.85)
    return radius, torch.tensor([0.75]), torch.tensor([[pitch, roll, tx, ty]])


@pytest.mark.parametrize("pose", [(0.5, 0.0, 0.0, 0.0), (3.0, 0.0, 0.0, 0.0), (12.0, 4.0, 0.05, -0.05),
                                  (22.0, -6.0, -0.1, 0.08)])
def test_outline_matches_ray_cast_silhouette(pose):
    radius, height, p = _vase(*pose)
    drawn = outline(Solid(radius, height, p), SIZE, CameraConfig())
    cast = mask_outline(cast_rays(Solid(radius, height, p), SIZE, CameraConfig(), 1.0).mask[0].numpy())
    for name in ("left", "right", "top", "bottom"):
        a, b = getattr(drawn, name)[0], getattr(cast, name)[0]
        # the same rows and columns are covered, but for one at either end that the outline grazes
        assert int((a.isnan() ^ b.isnan()).sum()) <= 2, name
        err = (a - b)[~(a.isnan() | b.isnan())].abs()
        # a binary mask's ends sit on pixel edges (half a pixel off); sampling the discs adds up to ~0.6 px
        assert err.mean() < 0.45 and err.max() < 1.25, (name, float(err.mean()), float(err.max()))


@pytest.mark.parametrize("pose", [(0.5, 0.0, 0.0, 0.0), (12.0, 4.0, 0.05, -0.05), (22.0, -6.0, -0.1, 0.08)])
def test_the_rows_of_the_outline_draw_the_ray_cast_silhouette(pose):
    radius, height, p = _vase(*pose)
    drawn = row_mask(outline(Solid(radius, height, p), SIZE, CameraConfig()))[0].numpy()
    cast = hit_mask(Solid(radius, height, p), SIZE, CameraConfig())[0].numpy()
    # only pixels that an end passes within a fraction of a pixel of differ: a few per row at most
    assert (drawn ^ cast).sum() <= 0.02 * cast.sum() and iou(drawn, cast) > 0.99
    assert not drawn[: int(np.argmax(cast.any(1))) - 2].any()  # nothing above the silhouette


def test_outline_is_differentiable_in_shape_and_pose():
    radius, height, pose = _vase(10.0)
    radius.requires_grad_(True)
    pose.requires_grad_(True)
    drawn = outline(Solid(radius, height, pose), 64, CameraConfig())
    torch.nan_to_num(drawn.right - drawn.left).sum().backward()
    assert radius.grad.abs().sum() > 0 and pose.grad[0, 0] != 0


def test_a_disc_without_a_leftmost_point_leaves_the_gradient_finite(monkeypatch):
    """A disc seen almost edge-on can have no real leftmost point (NaN): the rows it does not win must not pass
    0 x NaN back into the whole solid's gradient (a shape fit of a small crop diverged to NaN so)."""
    import radar_cli.sor.outline as module

    radius, height, pose = (t.double() for t in _vase(3.0, -0.2, 0.01, 0.02))
    plain = outline(Solid(radius, height, pose), 96, CameraConfig())
    first = []

    def roots_missing_one(qa, qb, qc):
        low, high = roots_of(qa, qb, qc)
        if not first and low.dim() == 2:  # the sides' leftmost and rightmost points, B x K: one disc loses them
            first.append(True)
            gone = torch.zeros_like(low, dtype=torch.bool)
            gone[:, low.shape[1] // 3] = True
            low, high = (torch.where(gone, torch.full_like(low, float("nan")), t) for t in (low, high))
        return low, high

    roots_of = module.roots
    monkeypatch.setattr(module, "roots", roots_missing_one)
    radius.requires_grad_(True)
    pose.requires_grad_(True)
    drawn = outline(Solid(radius, height, pose), 96, CameraConfig())
    assert first
    torch.nan_to_num(drawn.right - drawn.left).sum().backward()
    assert torch.isfinite(radius.grad).all() and torch.isfinite(pose.grad).all()
    assert torch.equal(drawn.left.isnan(), plain.left.isnan())  # its neighbours' ellipses still hold the rows
    assert float(torch.nan_to_num(drawn.left.detach() - plain.left).abs().mean()) < 0.05  # a few rows move a little


def test_mask_outline_sub_pixel():
    m = np.zeros((5, 8))
    m[1:4, 2:6] = 1.0
    m[2, 1] = 0.75  # coverage 0 -> 0.75 between pixel centres 0 and 1 crosses 0.5 at 2/3
    ends = mask_outline(m)
    assert ends.left[0, 2] == pytest.approx(2 / 3) and ends.left[0, 1] == pytest.approx(1.5)
    assert ends.right[0, 1] == pytest.approx(5.5) and np.isnan(ends.left[0, 0].item())
    assert ends.top[0, 3] == pytest.approx(0.5) and ends.bottom[0, 3] == pytest.approx(3.5)


@pytest.mark.parametrize("pitch", [0.5, 12.0, 24.0])
def test_vertical_extent_is_the_outlines_top_and_bottom(pitch):
    radius, height, pose = _vase(pitch, 3.0, 0.04, -0.03)
    drawn = outline(Solid(radius, height, pose), SIZE, CameraConfig())
    top, bottom = vertical_extent(Solid(radius, height, pose), SIZE, CameraConfig())
    assert float(top[0]) == pytest.approx(np.nanmin(drawn.top[0].numpy()), abs=1e-9)
    assert float(bottom[0]) == pytest.approx(np.nanmax(drawn.bottom[0].numpy()), abs=1e-9)


def test_outline_gradient_matches_finite_differences():
    radius, height, pose = (t.double() for t in _vase(9.0, 2.0, 0.03, 0.02))
    theta = torch.cat([radius[0], height, pose[0]]).requires_grad_(True)
    weights = torch.randn(4, 2 * SIZE, generator=torch.Generator().manual_seed(0), dtype=torch.float64)

    def loss(t: torch.Tensor) -> torch.Tensor:
        o = outline(Solid(t[None, :24], t[24:25], t[None, 25:]), SIZE, CameraConfig())
        ends = torch.stack([torch.cat([o.left[0], o.right[0]]), torch.cat([o.top[0], o.bottom[0]]),
                            torch.cat([o.right[0], o.top[0]]), torch.cat([o.bottom[0], o.left[0]])])
        return (torch.nan_to_num(ends) * weights).sum()

    loss(theta).backward()
    for i in (3, 12, 24, 25, 26, 27, 28):  # radii, height, pitch, roll, tx, ty
        step = torch.zeros_like(theta)
        step[i] = 1e-7  # small: lines that start or stop meeting the object make the sum jump
        with torch.no_grad():
            numeric = (loss(theta + step) - loss(theta - step)) / 2e-7
        assert float(theta.grad[i]) == pytest.approx(float(numeric), rel=1e-3, abs=1e-3), i


@pytest.mark.parametrize("size", [96, 256])
def test_sampled_and_grouped_discs_give_the_dense_outline_bit_for_bit(size, monkeypatch):
    """The discs evaluated in groups of similar band widths, after a sample of them has ruled the others out
    where it can, pick the same winners as every disc on every line it spans: the same ends and gradients."""
    gen = torch.Generator().manual_seed(3)
    y = torch.linspace(1, -1, 40)
    radius = (0.35 + 0.3 * torch.sin(3.0 * y[None] + torch.rand(6, 1, generator=gen) * 6) ** 2).clamp(0.05, 0.9)
    pose = torch.stack([torch.linspace(0.0, 45.0, 6), torch.randn(6, generator=gen) * 5,
                        torch.randn(6, generator=gen) * 0.05, torch.randn(6, generator=gen) * 0.05], 1)
    height = torch.linspace(0.5, 1.0, 6)

    def ends(sample_min: int):
        monkeypatch.setattr(conic_lines, "SAMPLE_MIN", sample_min)
        r = radius.double().requires_grad_(True)
        drawn = outline(Solid(r, height.double(), pose.double()), size, CameraConfig())
        values = torch.stack([drawn.left, drawn.right, drawn.top, drawn.bottom])
        torch.nan_to_num(values * torch.linspace(0.5, 2.0, size, dtype=torch.float64)).sum().backward()
        top, bottom = vertical_extent(Solid(radius, height, pose), size, CameraConfig())
        return values.detach(), r.grad, torch.stack([top, bottom])

    grouped, dense = ends(0), ends(10**12)
    for a, b in zip(grouped, dense):
        assert torch.equal(torch.nan_to_num(a, nan=-7.0), torch.nan_to_num(b, nan=-7.0))
    assert grouped[0].isfinite().sum() > 4 * 6 * size // 4  # the solids cover a good part of every image


def test_wide_ellipses_are_left_out_between_their_extremes_and_the_winners_stay(monkeypatch):
    """Seen from well above, each disc's ellipse spans most columns, but holds a column's top or bottom only near
    its own extremes: the runs between are pruned (far fewer crossings evaluated than the discs' full spans) and
    every column's winner is the one of every disc on every column."""
    evaluated = []
    evaluate = conic_lines._evaluate

    def counting(*args):
        found = evaluate(*args)
        evaluated.append(int(found[3].sum()))
        return found

    radius, height, pose = _vase(35.0, 3.0, 0.02, -0.03)
    solid = Solid(radius.double(), height.double(), pose.double())
    monkeypatch.setattr(conic_lines, "_evaluate", counting)
    monkeypatch.setattr(conic_lines, "SAMPLE_MIN", 0)
    pruned = outline(solid, 384, CameraConfig())
    monkeypatch.setattr(conic_lines, "RUN_LINES", 10**6)  # one run per disc: the disc's whole span
    whole = outline(solid, 384, CameraConfig())
    monkeypatch.setattr(conic_lines, "SAMPLE_MIN", 10**12)  # every disc on every line it spans
    dense = outline(solid, 384, CameraConfig())
    for name in ("left", "right", "top", "bottom"):
        a, b, c = (torch.nan_to_num(getattr(o, name), nan=-7.0) for o in (pruned, whole, dense))
        assert torch.equal(a, c) and torch.equal(b, c), name
    # the rows' and the columns' passes, each a sample then the rest: the columns' rest is where runs count
    assert evaluated[3] < 0.25 * evaluated[7]
