"""Training feedback: a tqdm bar with losses and ETA, scalars in metrics.jsonl, image grids every N steps, a
loss-curve PNG at the end (drawn with PIL), and TensorBoard scalars when tensorboard is installed.

    RUN_DIR/metrics.jsonl            one JSON object per logged step: {"step": s, "total": ..., "sil": ..., ...}
    RUN_DIR/images/step_0001000.png  grid: one row per sample, see `image_grid`
    RUN_DIR/loss_curve.png
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from PIL import Image, ImageDraw
from tqdm import tqdm

from radar_cli.fileio import write_image, write_text
from radar_cli.model.outputs import Decomposition
from radar_cli.render.lighting import tone_map
from radar_cli.train.step import Batch, Rendered

METRICS_FILE = "metrics.jsonl"
CURVE_FILE = "loss_curve.png"
GRID_COLUMNS = ("input", "reconstruction", "albedo", "diffuse", "specular", "normals", "env map",
                "mask", "predicted silhouette", "S~ (loss region)")
_COLORS = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40), (148, 103, 189), (140, 86, 75),
           (227, 119, 194), (127, 127, 127)]
NOT_LOSSES = ("step", "sec_per_step", "lr")  # metrics.jsonl fields kept off the progress bar and the loss curve


def read_metrics(run_dir: str | Path) -> list[dict]:
    """All records of RUN_DIR/metrics.jsonl (empty if absent); unreadable lines (a killed write) are skipped."""
    path = Path(run_dir) / METRICS_FILE
    if not path.is_file():
        return []
    records = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            records.append(json.loads(line))
        except ValueError:
            continue
    return records


class RunLogger:
    """Progress bar, metrics file, image grids and TensorBoard for the main process of a run."""

    def __init__(self, run_dir: str | Path, start: int, end: int, enabled: bool = True, bar: bool = True):
        self.run_dir, self.enabled = Path(run_dir), enabled
        self.bar = tqdm(total=end, initial=start, desc="train", dynamic_ncols=True, disable=not (enabled and bar))
        self.writer = None
        if not enabled:
            return
        kept = [r for r in read_metrics(run_dir) if r.get("step", -1) < start]  # resumed: drop the redone steps
        write_text(self.run_dir / METRICS_FILE, "".join(json.dumps(r) + "\n" for r in kept))
        self.metrics = open(self.run_dir / METRICS_FILE, "a", encoding="utf-8")
        try:
            from torch.utils.tensorboard import SummaryWriter

            self.writer = SummaryWriter(str(self.run_dir / "tensorboard"))
        except ImportError:
            self.writer = None

    def step(self, step: int, values: dict[str, float] | None) -> None:
        """Advance the bar; with values, record them for `step`."""
        self.bar.update(1)
        if not self.enabled or values is None:
            return
        self.bar.set_postfix({k: f"{v:.4f}" for k, v in values.items() if k not in NOT_LOSSES}, refresh=False)
        self.metrics.write(json.dumps({"step": step, **values}) + "\n")
        self.metrics.flush()
        if self.writer is not None:
            for k, v in values.items():
                self.writer.add_scalar(f"train/{k}", v, step)

    def grid(self, step: int, batch: Batch, pred: Decomposition, rendered: Rendered, gamma: float) -> Path | None:
        """Write the image grid for `step`; returns its path (None on non-main ranks)."""
        if not self.enabled:
            return None
        path = self.run_dir / "images" / f"step_{step:07d}.png"
        write_image(path, image_grid(batch, pred, rendered, gamma))
        return path

    def close(self) -> Path | None:
        """Close the bar and files and draw the loss curve; returns its path."""
        self.bar.close()
        if not self.enabled:
            return None
        self.metrics.close()
        if self.writer is not None:
            self.writer.close()
        path = self.run_dir / CURVE_FILE
        write_image(path, loss_curve(read_metrics(self.run_dir)))
        return path


def _tile(x: torch.Tensor, size: int) -> torch.Tensor:
    """B x C x h x w in [0, 1] -> B x 3 x size x size (grey repeated to RGB, aspect kept by letterboxing)."""
    x = x.detach().float().cpu().clamp(0, 1)
    if x.shape[1] == 1:
        x = x.expand(-1, 3, -1, -1)
    h, w = x.shape[-2:]
    scale = size / max(h, w)
    nh, nw = max(1, round(h * scale)), max(1, round(w * scale))
    x = F.interpolate(x, size=(nh, nw), mode="nearest")
    out = torch.zeros(x.shape[0], 3, size, size)
    top, left = (size - nh) // 2, (size - nw) // 2
    out[:, :, top : top + nh, left : left + nw] = x
    return out


def image_grid(batch: Batch, pred: Decomposition, rendered: Rendered, gamma: float, rows: int = 4) -> np.ndarray:
    """Rows = samples; columns = GRID_COLUMNS (texture-space maps shown as unwrapped); the last row holds SAD
    patches, low specular variance ("real") then high ("fake"). Returns H x W x 3 float in [0, 1]."""
    n, size = min(rows, batch.image.shape[0]), batch.image.shape[-1]
    sh, mask = rendered.shading, batch.mask[:n, None]
    env = pred.env[:n, None]
    cols = [batch.image[:n], rendered.recon[:n], tone_map(pred.albedo[:n], gamma),
            sh.diffuse[:n] / sh.diffuse[:n].amax(dim=(1, 2, 3), keepdim=True).clamp_min(1e-6),
            tone_map(pred.rho[:n, None, None, None] * sh.specular[:n], gamma), (sh.normals[:n] + 1) / 2,
            env / env.amax(dim=(1, 2, 3), keepdim=True).clamp_min(1e-6), mask, rendered.hits.sil[:n, None],
            mask * rendered.front[:n]]
    tiles = torch.stack([_tile(c, size) for c in cols], dim=1)  # n x K x 3 x S x S
    body = tiles.permute(0, 3, 1, 4, 2).reshape(n * size, len(cols) * size, 3)
    if rendered.sad_real is not None and rendered.sad_fake is not None:
        half = len(cols) // 2
        real, fake = _tile(rendered.sad_real[:half], size), _tile(rendered.sad_fake[:half], size)
        strip = torch.zeros(len(cols), 3, size, size)
        strip[: real.shape[0]] = real
        strip[half : half + fake.shape[0]] = fake
        body = torch.cat([body, strip.permute(2, 0, 3, 1).reshape(size, len(cols) * size, 3)], dim=0)
    return body.numpy()


def loss_curve(records: list[dict], width: int = 900, height: int = 500) -> np.ndarray:
    """Every loss term against the step, log10 scale, drawn with PIL (no matplotlib). Returns H x W x 3 uint8."""
    img = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(img)
    keys = [k for k in (records[0] if records else {}) if k not in NOT_LOSSES]
    pts = {k: [(r["step"], math.log10(max(r[k], 1e-8))) for r in records if k in r and math.isfinite(r[k])]
           for k in keys}
    allp = [p for v in pts.values() for p in v]
    if not allp:
        draw.text((10, 10), "no metrics", fill="black")
        return np.asarray(img)
    x0, x1 = min(p[0] for p in allp), max(p[0] for p in allp)
    y0, y1 = min(p[1] for p in allp), max(p[1] for p in allp)
    x1, y1 = max(x1, x0 + 1), max(y1, y0 + 1e-3)
    left, right, top, bottom = 60, width - 160, 20, height - 40

    def xy(p: tuple[float, float]) -> tuple[float, float]:
        return (left + (p[0] - x0) / (x1 - x0) * (right - left), bottom - (p[1] - y0) / (y1 - y0) * (bottom - top))

    draw.rectangle([left, top, right, bottom], outline="black")
    for i, (k, v) in enumerate(pts.items()):
        color = _COLORS[i % len(_COLORS)]
        if len(v) > 1:
            draw.line([xy(p) for p in v], fill=color, width=2)
        draw.text((right + 10, top + 16 * i), k, fill=color)
    draw.text((left, bottom + 8), f"step {x0:g} .. {x1:g}", fill="black")
    draw.text((4, top), f"1e{y1:.1f}", fill="black")
    draw.text((4, bottom - 10), f"1e{y0:.1f}", fill="black")
    return np.asarray(img)
