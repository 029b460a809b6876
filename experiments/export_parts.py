"""CPU seconds of four parts of a `radar derender` object, each against the way it was done before, over the
objects of a results folder (docs/performance.md):

    python -m experiments.export_parts RESULTS [--repeats 3]

- the turntable GIF's palette: Pillow's median cut of every pixel of turntable.png's frames (and its mapping)
  against export.palette.quantize; each one's mean error against the frames (levels);
- mesh.obj: trimesh's OBJ exporter against export.mesh.obj_text (the bytes compared);
- the refinement's silhouette at the output side: the hard silhouette ray-cast (render.raycast.hit_mask) against
  the pixels between the rows' ends of the closed-form outline (sor.outline.row_mask), for the profile, height and
  pose of material.json (the masks' IoU);
- the input view, its turntable (8 frames) and its 4 relit views: each view's texture composed anew (and the
  input view's shading made twice, for it and for the turntable) against ViewRenderer.draw, whose unspun views
  draw the texture their shading holds, with the turntable started from the input view's shading and
  reconstruction (the images compared).

Each figure is the best of `repeats` (one torch thread; run with OMP_NUM_THREADS=1)."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np
import torch
import trimesh
from PIL import Image

from radar_cli.config import CameraConfig
from radar_cli.derender.export.environments import builtin_environments, match_exposure
from radar_cli.derender.export.maps import chw_image
from radar_cli.derender.export.mesh import OBJ_MTL, obj_text
from radar_cli.derender.export.palette import quantize
from radar_cli.derender.export.renders import ViewRenderer
from radar_cli.derender.run.state import read_state
from radar_cli.masks.refine import iou
from radar_cli.render.lighting import compose
from radar_cli.render.raycast import hit_mask
from radar_cli.render.scene import rotate_full_map
from radar_cli.render.texture import render_texture
from radar_cli.sor.outline import outline, row_mask
from radar_cli.sor.solid import Solid


def best_cpu(fn: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    """(the least CPU seconds of `repeats` calls, the last call's result)."""
    least, out = float("inf"), None
    for _ in range(repeats):
        start = time.process_time()
        out = fn()
        least = min(least, time.process_time() - start)
    return least, out


def gif_palette(folder: Path, repeats: int) -> list[float]:
    """[Pillow s, radar s, Pillow error, radar error] for the object's turntable frames."""
    strip = np.asarray(Image.open(folder / "turntable.png").convert("RGB"))
    side = strip.shape[0]
    views = [np.ascontiguousarray(strip[:, k * side:(k + 1) * side]) for k in range(strip.shape[1] // side)]
    image = Image.fromarray(strip)
    old_s, old = best_cpu(lambda: image.quantize(256, method=Image.Quantize.MEDIANCUT), repeats)
    new_s, (indices, palette) = best_cpu(lambda: quantize(views), repeats)
    old_err = np.abs(np.asarray(old.convert("RGB"), np.float64) - strip).mean()
    new_err = np.mean([np.abs(palette[i].astype(np.float64) - v).mean() for i, v in zip(indices, views)])
    return [old_s, new_s, float(old_err), float(new_err)]


def obj_file(folder: Path, repeats: int) -> list[float]:
    """[trimesh s, radar s, 1 if the bytes agree] for the object's mesh.obj read back (the text alone: the
    texture's PNG, which both write, left out)."""
    mesh = trimesh.load(folder / "mesh.obj", force="mesh", process=False, maintain_order=True)
    mesh.metadata.pop("name", None)  # the file's name, which the exporter would write as an `o` line
    mesh.visual.material.image = None
    export = trimesh.exchange.obj.export_obj
    old_s, (text, _) = best_cpu(lambda: export(mesh, include_texture=True, return_texture=True, mtl_name=OBJ_MTL),
                                repeats)
    new_s, ours = best_cpu(lambda: obj_text(mesh.vertices, mesh.visual.uv, mesh.faces, "albedo"), repeats)
    return [old_s, new_s, float(text.encode("utf-8") == ours)]


def iou_cast(folder: Path, repeats: int) -> list[float]:
    """[hit_mask s, outline and row_mask s, the two masks' IoU] at material.json's resolution (its 128-row
    profile)."""
    record = json.loads((folder / "material.json").read_text())
    solid = Solid(torch.tensor([record["radius"]], dtype=torch.float32), torch.tensor([record["height"]]),
                  torch.tensor([[record["pitch"], record["roll"], record["tx"], record["ty"]]]))
    size, camera = int(record["resolution"]), CameraConfig()
    with torch.no_grad():
        old_s, old = best_cpu(lambda: hit_mask(solid, size, camera)[0], repeats)
        new_s, new = best_cpu(lambda: row_mask(outline(solid, size, camera))[0], repeats)
    return [old_s, new_s, iou(old.numpy(), new.numpy())]


def views(folder: Path, repeats: int) -> list[float]:
    """[composing anew s, ViewRenderer.draw s, 1 if the images agree] for the input view, 8 turntable frames and
    the 4 built-in relit views of the object (its rays cast once, outside the timing)."""
    state = read_state(folder)
    view = ViewRenderer(state, int(json.loads((folder / "material.json").read_text())["resolution"]))
    own = state.material.env[0].numpy()
    envs = [torch.from_numpy(match_exposure(env, own))[None]
            for env in builtin_environments(own.shape[0], own.shape[1]).values()]

    def anew(shading, yaw: float) -> np.ndarray:
        texture = compose(rotate_full_map(state.material.albedo, yaw), shading.diffuse, shading.specular,
                          state.material.rho, state.render.gamma)
        image, _ = render_texture(view.hits, texture, inside_dim=state.render.inside_dim, background=1.0)
        return chw_image(image)

    def before() -> list[np.ndarray]:
        recon = anew(view.shading(), 0.0)
        shading = view.shading()
        return ([recon] + [anew(shading, 45.0 * k) for k in range(8)]
                + [anew(view.shading(env), 0.0) for env in envs])

    def after() -> list[np.ndarray]:
        shading = view.shading()
        recon = view.draw(shading)
        return ([recon, recon] + [view.draw(shading, 45.0 * k) for k in range(1, 8)]
                + [view.draw(view.shading(env)) for env in envs])

    with torch.no_grad():
        old_s, old = best_cpu(before, repeats)
        new_s, new = best_cpu(after, repeats)
    return [old_s, new_s, float(all(np.array_equal(a, b) for a, b in zip(old, new)))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", type=Path)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    torch.set_num_threads(1)
    folders = sorted(p.parent for p in args.results.glob("*/material.json"))
    parts = {"gif": gif_palette, "obj": obj_file, "iou_cast": iou_cast, "views": views}
    rows = {name: np.array([fn(f, args.repeats) for f in folders]) for name, fn in parts.items()}
    print(f"{len(folders)} objects")
    for name, table in rows.items():
        extra = table[:, 2:].mean(0).round(3).tolist()
        print(f"{name}: before {table[:, 0].mean():.3f} CPU s ({table[:, 0].min():.3f}-{table[:, 0].max():.3f}), "
              f"after {table[:, 1].mean():.3f} ({table[:, 1].min():.3f}-{table[:, 1].max():.3f}); {extra}")


if __name__ == "__main__":
    main()
