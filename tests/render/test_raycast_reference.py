"""Silhouette and depth against trimesh ray casting of a dense (K = 256) triangle mesh."""

from __future__ import annotations

import numpy as np
import pytest
import torch
import trimesh

from radar_cli.config import CameraConfig
from radar_cli.render.raycast import cast_rays, hit_mask
from radar_cli.sor.camera import pixel_rays, project
from radar_cli.sor.mesh import triangulate
from radar_cli.sor.pose import object_to_camera
from radar_cli.sor.solid import Solid

SIZE = 128
N_SHAPES = 20


def reference_hits(radius, height, pose, camera):
    """(mask P bool, depth P) from trimesh for one shape, rays limited to the mesh's projected bounding box."""
    mesh = triangulate(radius, height, n_cols=256, camera=camera)
    verts = object_to_camera(mesh.vertices[None], pose, camera)[0]
    tm = trimesh.Trimesh(verts.numpy(), mesh.faces.numpy(), process=False)
    dirs = pixel_rays(SIZE, camera, dtype=torch.float64).reshape(-1, 3)
    dirs = dirs / dirs.norm(dim=-1, keepdim=True)
    xy = project(verts, camera)
    img = project(dirs[:, None, :] * 5.0, camera)[:, 0]
    lo, hi = xy.min(0).values - 0.05, xy.max(0).values + 0.05
    cand = ((img >= lo) & (img <= hi)).all(-1).nonzero()[:, 0].numpy()
    mask, depth = np.zeros(SIZE * SIZE, bool), np.zeros(SIZE * SIZE)
    loc, ray_idx, _ = tm.ray.intersects_location(np.zeros((len(cand), 3)), dirs[cand].numpy(), multiple_hits=False)
    mask[cand[ray_idx]] = True
    depth[cand[ray_idx]] = loc[:, 2]
    return mask, depth


@pytest.mark.slow
def test_silhouette_and_depth_match_trimesh(random_sor):
    camera = CameraConfig()
    radius, height, pose = random_sor(N_SHAPES, seed=1)
    hits = cast_rays(Solid(radius, height, pose), SIZE, camera)
    ious, depth_errs = [], []
    for i in range(N_SHAPES):
        ref_mask, ref_depth = reference_hits(radius[i : i + 1], height[i : i + 1], pose[i : i + 1], camera)
        mask = hits.mask[i].reshape(-1).numpy()
        depth = hits.depth[i].reshape(-1).detach().numpy()
        ious.append((mask & ref_mask).sum() / (mask | ref_mask).sum())
        both = mask & ref_mask
        depth_errs.append(np.abs(depth[both] - ref_depth[both]).mean() / camera.distance)
    assert np.mean(ious) >= 0.99, ious
    assert min(ious) >= 0.97, ious
    assert max(depth_errs) <= 0.005, depth_errs


def test_hits_only_search_leaves_every_hit_unchanged(random_sor):
    """soft_outside=False (synthesis draws over the hard mask) casts only the rays that can hit and skips the
    misses' margin search: every output on the object is the same as the full cast's (up to float32 rounding:
    vectorised and scalar exp differ in the last bit), and the soft silhouette is 0 off it."""
    radius, height, pose = random_sor(6, seed=3, dtype=torch.float32)
    full = cast_rays(Solid(radius, height, pose), 96, CameraConfig(), 1.0)
    hits_only = cast_rays(Solid(radius, height, pose), 96, CameraConfig(), 1.0, soft_outside=False)
    on = full.mask
    assert torch.equal(hits_only.mask, on) and torch.equal(hits_only.inner, full.inner)
    for name in ("sil", "depth", "normal", "uv", "points"):
        a, b = getattr(full, name), getattr(hits_only, name)
        assert torch.allclose(a[on], b[on], rtol=0.0, atol=1e-6), name
    assert float(hits_only.sil[~on].abs().max()) == 0.0
    assert float(full.sil[~on].max()) > 0.4  # the full cast is soft just outside the outline


@pytest.mark.parametrize("size", [64, 257])
def test_hit_mask_is_the_casts_hard_silhouette(random_sor, size):
    """hit_mask stops each ray's search at its first hits: the same mask as a full cast, bit for bit."""
    radius, height, pose = random_sor(6, seed=4, dtype=torch.float32)
    solid = Solid(radius, height, pose)
    mask = hit_mask(solid, size, CameraConfig())
    assert mask.dtype == torch.bool and mask.shape == (6, size, size)
    assert torch.equal(mask, cast_rays(solid, size, CameraConfig(), 1.0, soft_outside=False).mask)
    assert torch.equal(mask, cast_rays(solid, size, CameraConfig(), 1.0).mask)
    assert 0 < int(mask.sum()) < mask.numel()


def test_the_search_in_chunks_finds_what_it_finds_at_once(random_sor, monkeypatch):
    """The ray search runs in chunks of rays (small on the CPU, large on a GPU): each ray's result is its own, so a
    cast in 7 chunks is the same bits as in one."""
    from radar_cli.render import intersect

    radius, height, pose = random_sor(3, seed=5, dtype=torch.float32)
    solid = Solid(radius, height, pose)
    monkeypatch.setattr(intersect, "SEARCH_CHUNK", 1 << 30)
    whole = cast_rays(solid, 64, CameraConfig(), 1.0)
    monkeypatch.setattr(intersect, "SEARCH_CHUNK", 64 * 64 * 3 // 7 + 1)
    chunked = cast_rays(solid, 64, CameraConfig(), 1.0)
    for name in ("mask", "inner", "sil", "depth", "normal", "uv", "points"):
        assert torch.equal(getattr(whole, name), getattr(chunked, name)), name
