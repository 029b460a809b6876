"""Typed configuration of a training run: the model (architecture, sizes, output ranges), the losses and the loop.

One root `RunConfig` is loaded strictly from a `pipelines/**/*.toml` file (merged over the presets it names as
`base`) and stored, resolved, inside every checkpoint, so inference needs only the checkpoint. Defaults are the
paper's (supplementary Table 4): a preset holds only what differs from them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from radar_cli.config import CameraConfig, GeometryConfig, RenderConfig, from_dict, load_toml, to_dict
from radar_cli.errors import ConfigError


@dataclass(frozen=True)
class ModelConfig:
    """Architecture and output ranges of RadarModel; image, texture and env sizes come from `render`."""

    render: RenderConfig = field(default_factory=RenderConfig)
    """Image, texture, environment-map and shading-grid sizes, silhouette softness, gamma."""
    geometry: GeometryConfig = field(default_factory=GeometryConfig)
    """L (n_rows) and the shape/pose output ranges."""
    camera: CameraConfig = field(default_factory=CameraConfig)
    shape_width: int = 64
    """Channels of the first encoder layer of f_S (doubled per layer up to max_channels)."""
    light_width: int = 64
    """Channels of the first encoder layer of f_L."""
    albedo_width: int = 64
    """Channels of the first encoder layer of the f_A U-Net."""
    disc_width: int = 64
    """Channels of the first layer of the SAD discriminator."""
    max_channels: int = 512
    latent: int = 128
    """Size of the bottleneck vector of f_S and f_L."""
    albedo_depth: int = 6
    """Down/upsampling levels of the f_A U-Net (6 for 256 px, as the paper)."""
    shininess_range: tuple[float, float] = (1.0, 196.0)
    spec_albedo_range: tuple[float, float] = (0.0, 2.0)
    env_range: tuple[float, float] = (0.0, 1.0)
    detach_shape_for_texture: bool = True
    """Unwrap the texture that f_A and f_L see with a detached shape, so the shape learns from L_sil and from
    rendering, not by moving the texture it reads."""

    def validate(self) -> None:
        """Raise ConfigError if sizes do not fit the architecture."""
        r = self.render
        if r.image_size < 8 or r.image_size & (r.image_size - 1):
            raise ConfigError(f"model.render.image_size must be a power of two >= 8, got {r.image_size}")
        if r.tex_height % (2**self.albedo_depth) or r.tex_width % (2**self.albedo_depth):
            raise ConfigError(f"texture size {r.tex_height}x{r.tex_width} must be divisible by 2^albedo_depth")
        if r.env_width != 3 * r.env_height or r.env_height < 2 or r.env_height & (r.env_height - 1):
            raise ConfigError(f"env map must be h x 3h with h a power of two >= 2, got {r.env_height}x{r.env_width}")
        n = self.geometry.n_rows
        if n < 2 or n & (n - 1):
            raise ConfigError(f"model.geometry.n_rows must be a power of two >= 2, got {n}")


@dataclass(frozen=True)
class LossConfig:
    """Loss weights (Table 4), the paper's ablation switches (Table 2) and the supervised baseline."""

    sil_weight: float = 10.0
    """lambda_s: MSE between soft and target silhouettes."""
    dt_weight: float = 100.0
    """lambda_dt: L1 of the predicted silhouette weighted by the target's distance transform (in image sides)."""
    dt_margin_px: float = 0.0
    """Pixels next to the target that the distance term leaves free (0 = the paper). The soft silhouette's own
    halo lies there; penalising it biases the fit towards smaller silhouettes, and at 64 px that bias swamps the
    pitch cue of the rim (docs/training.md)."""
    im_weight: float = 1.0
    alb_weight: float = 1.0
    sad_weight: float = 0.01
    diff_weight: float = 1.0
    diff_target: float = 0.5
    """xi: target mean of the diffuse factor."""
    diff_margin: float = 0.1
    """Delta: tolerated deviation from xi."""
    mouth_weight: float = 0.0
    """Weight of L_alb carried into the open mouth (losses.mouth_l1; 0 = off, the paper). Needs L_alb."""
    mouth_sigma_px: float = 1.0
    """Softness of the mouth's rim for that term, in pixels; it is scored within 4x this of the rim."""
    cycle_weight: float = 0.0
    """Weight of the shape cycle (radar's addition; 0 = off, the paper): the prediction, re-rendered whole at a
    random pitch over the input's background, must give back its own radius, height and pose, pitch included
    (step.shape_cycle_term). The pitch of that render is known exactly, so f_S learns to read pitch from images
    drawn the way the data is."""
    light_cycle_weight: float = 0.0
    """Weight of the lighting cycle (radar's addition; 0 = off, the paper): the prediction, re-rendered whole at
    its own pose under another object's predicted environment map and specular albedo and a random shininess,
    must give back that lighting and material (f_L) and its own albedo (f_A) (step.light_cycle_term)."""
    cycle_albedo: Literal["network", "divided"] = "network"
    """The albedo the two cycles redraw with (and f_A must give back): f_A's own (`network`), or the input's
    unwrapped texture divided by the predicted shading (`divided`, render.scene.divide_shading, as `radar derender`
    exports it), which carries the photo's detail, so f_A is taught to keep it."""
    sad_patch: int = 64
    """Side of the albedo patches shown to the discriminator (a power of two >= 8)."""
    sad_patches_per_image: int = 4
    sad_group_fraction: float = 0.5
    """Fraction of the sorted patches in each group (lowest specular variance = real, highest = fake)."""
    pitch_label_weight: float = 0.0
    """Weight of self-training on pitch (radar's addition; 0 = off): L1 of f_S's pitch, over the pitch range,
    against each training sample's pitch from `radar derender --pitch search` (`radar train --pitch-labels`), so
    the single-pass network learns what the slower analysis by synthesis finds. No ground truth is used."""
    no_alb: bool = False
    no_sad: bool = False
    no_diff: bool = False
    supervised: bool = False
    """Train every output against synthetic ground truth instead (the upper bound of Table 2)."""


@dataclass(frozen=True)
class TrainConfig:
    """The optimisation loop."""

    lr: float = 2e-4
    lr_decay_steps: int = 0
    """Decay the learning rate linearly to 0 over the last N iterations (0 = constant, as in the paper); a run
    shorter than N (e.g. --iterations) starts part-way down the ramp."""
    beta1: float = 0.9
    beta2: float = 0.999
    batch_size: int = 24
    iterations: int = 40000
    checkpoint_every: int = 1000
    keep_checkpoints: int = 3
    image_every: int = 1000
    log_every: int = 10
    seed: int = 0
    device: Literal["auto", "cpu", "cuda"] = "auto"
    threads: int = 0
    """CPU threads for torch (0 = torch's default)."""


@dataclass(frozen=True)
class RunConfig:
    """The root of a pipelines/**/*.toml file."""

    name: str = "run"
    model: ModelConfig = field(default_factory=ModelConfig)
    loss: LossConfig = field(default_factory=LossConfig)
    train: TrainConfig = field(default_factory=TrainConfig)

    def validate(self) -> "RunConfig":
        """Check cross-field constraints; returns self."""
        self.model.validate()
        p = self.loss.sad_patch
        tex = self.model.render
        if p < 8 or p & (p - 1) or p > min(tex.tex_height, tex.tex_width):
            raise ConfigError(f"loss.sad_patch must be a power of two in [8, texture size], got {p}")
        if self.loss.mouth_weight < 0 or self.loss.mouth_sigma_px <= 0:
            raise ConfigError("loss.mouth_weight must be >= 0 and loss.mouth_sigma_px > 0")
        for name in ("cycle_weight", "light_cycle_weight", "pitch_label_weight"):
            if getattr(self.loss, name) < 0:
                raise ConfigError(f"loss.{name} must be >= 0, got {getattr(self.loss, name)}")
        if not 0 < self.loss.sad_group_fraction <= 0.5:
            raise ConfigError(f"loss.sad_group_fraction must lie in (0, 0.5], got {self.loss.sad_group_fraction}")
        if self.train.batch_size < 1 or self.train.iterations < 0 or self.train.keep_checkpoints < 1:
            raise ConfigError("train.batch_size and train.keep_checkpoints must be >= 1, iterations >= 0")
        if self.train.lr_decay_steps < 0:
            raise ConfigError(f"train.lr_decay_steps must be >= 0, got {self.train.lr_decay_steps}")
        return self


def load_run_config(path: str | Path) -> RunConfig:
    """Load and validate a pipelines/**/*.toml file and its `base` chain (unknown keys and wrong types raise
    ConfigError naming the file that holds them)."""
    return load_toml(RunConfig, path).validate()


def run_config_from_dict(data: dict) -> RunConfig:
    """A RunConfig from its plain-dict form (as stored in checkpoints)."""
    return from_dict(RunConfig, data, "checkpoint config").validate()


__all__ = ["ModelConfig", "LossConfig", "TrainConfig", "RunConfig", "load_run_config", "run_config_from_dict",
           "to_dict"]
