"""The training losses of RADAR (paper Eq. 3, 10, 11, 12, 13) and the supervised baseline, each a pure function.

Reductions are means, so weights do not depend on image or batch size. Images are B x C x H x W, masks
B x 1 x H x W floats in [0, 1] unless said otherwise.
"""

from __future__ import annotations

import cv2
import numpy as np
import torch
from torch import nn
from torch.func import functional_call

from radar_cli.model.outputs import Decomposition

EPS = 1e-6


def distance_transform(mask: np.ndarray) -> np.ndarray:
    """dt(S): distance of every pixel to the nearest object pixel, in image sides (0 on the object).

    Args:
        mask: H x W bool target silhouette.

    Returns:
        H x W float32; all zeros if the mask is empty (no signal rather than infinity).
    """
    if not mask.any():
        return np.zeros(mask.shape, np.float32)
    background = (~mask).astype(np.uint8)
    return cv2.distanceTransform(background, cv2.DIST_L2, 5).astype(np.float32) / mask.shape[0]


def silhouette_loss(sil: torch.Tensor, target: torch.Tensor, dt: torch.Tensor, w_mse: float,
                    w_dt: float, margin_px: float = 0.0, per_sample: bool = False) -> torch.Tensor:
    """L_sil = w_mse * MSE(S, S^) + w_dt * mean(max(0, dt(S) - margin) * S^) (Eq. 3; margin 0 in the paper).

    Args:
        sil: B x H x W predicted soft silhouette in [0, 1].
        target: B x H x W target silhouette (0/1 float).
        dt: B x H x W distance transform of the target (image sides).
        margin_px: distance from the target, in pixels, within which the predicted silhouette is not penalised.
        per_sample: return the B values (each over its own pixels) instead of the batch's mean.
    """
    if margin_px > 0:
        dt = (dt - margin_px / dt.shape[-1]).clamp_min(0.0)
    dims = (1, 2) if per_sample else None
    return w_mse * ((sil - target) ** 2).mean(dims) + w_dt * (dt * sil).mean(dims)


def masked_l1(pred: torch.Tensor, target: torch.Tensor, weight: torch.Tensor,
              per_sample: bool = False) -> torch.Tensor:
    """Mean absolute error over the pixels where weight > 0 (L_im, Eq. 10, and L_alb, Eq. 11).

    Args:
        pred, target: B x C x H x W. weight: B x 1 x H x W in [0, 1] (S~ = S and S^_f).
        per_sample: return the B values (each over its own weighted pixels) instead of the batch's.
    """
    dims = (1, 2, 3) if per_sample else None
    total = (weight.sum(dims) * pred.shape[1]).clamp_min(1.0)
    return ((pred - target).abs() * weight).sum(dims) / total


def mouth_l1(recon_mu: torch.Tensor, front: torch.Tensor, mouth: torch.Tensor, image: torch.Tensor,
             region: torch.Tensor, inside_dim: float) -> torch.Tensor:
    """L_alb carried into the open mouth (radar's addition, off in the paper's presets): where the soft mouth
    coverage is on, the single-colour rendering shows the inside, its mean frontal colour dimmed by inside_dim.
    Fitting that darker ellipse to the image moves the rim, and with it the pitch, smoothly. Only the coverage
    carries gradient: the inside's colour is a crude model, and letting it teach the lighting and albedo made
    both worse (docs/training.md).

    Args:
        recon_mu: B x 3 x H x W single-colour rendering of the frontal third (0 elsewhere).
        front: B x 1 x H x W its frontal mask. mouth: B x 1 x H x W soft mouth coverage (differentiable).
        image: B x 3 x H x W target. region: B x 1 x H x W pixels scored (no gradient).
    """
    recon_mu, front = recon_mu.detach(), front.detach()
    area = front.sum(dim=(2, 3), keepdim=True).clamp_min(1.0)
    inside = inside_dim * (recon_mu * front).sum(dim=(2, 3), keepdim=True) / area  # B x 3 x 1 x 1
    pred = recon_mu * (1 - mouth) + inside * mouth
    return masked_l1(pred, image, region)


def mean_color(albedo: torch.Tensor) -> torch.Tensor:
    """A^_mu: the albedo replaced by its mean colour (B x 3 x Ht x Wt -> same shape)."""
    return albedo.mean(dim=(2, 3), keepdim=True).expand_as(albedo)


def diffuse_loss(diffuse: torch.Tensor, target: float, margin: float) -> torch.Tensor:
    """L_diff = max(|mean(I_d) - xi| - Delta, 0)^2 per image, averaged over the batch (Eq. 13).

    Args:
        diffuse: B x 1 x Ht x Wt diffuse factor.
    """
    mean = diffuse.mean(dim=(1, 2, 3))
    return ((mean - target).abs() - margin).clamp_min(0.0).pow(2).mean()


def sample_patches(albedo_tm: torch.Tensor, specular: torch.Tensor, patch: int, per_image: int,
                   fraction: float) -> tuple[torch.Tensor, torch.Tensor]:
    """Random albedo patches split by the variance of the specular factor under them (Fig. 4).

    Uses the global torch RNG (saved in checkpoints, so resumed runs draw the same patches).

    Args:
        albedo_tm: B x 3 x Ht x Wt tone-mapped albedo tau(A).
        specular: B x 1 x Ht x Wt specular factor.
        patch: side p of the square patches. per_image: patches drawn per image.
        fraction: share of the patches in each group.

    Returns:
        (real, fake): k x 3 x p x p each, the lowest and the highest specular variance ("real" and "fake").
    """
    n_batch, _, ht, wt = albedo_tm.shape
    n = n_batch * per_image
    dev = albedo_tm.device
    b = torch.arange(n_batch, device=dev).repeat_interleave(per_image)  # N
    y = torch.randint(0, ht - patch + 1, (n,)).to(dev)
    x = torch.randint(0, wt - patch + 1, (n,)).to(dev)
    offs = torch.arange(patch, device=dev)
    rows = (y[:, None] + offs)[:, :, None]  # N x p x 1
    cols = (x[:, None] + offs)[:, None, :]  # N x 1 x p
    bi = b[:, None, None]
    patches = albedo_tm.permute(0, 2, 3, 1)[bi, rows, cols].permute(0, 3, 1, 2)  # N x 3 x p x p
    spec_var = specular[:, 0][bi, rows, cols].detach().flatten(1).var(dim=1)  # N
    order = torch.argsort(spec_var)
    k = max(1, int(n * fraction))
    return patches[order[:k]], patches[order[-k:]]


def _frozen(disc: nn.Module) -> dict[str, torch.Tensor]:
    """D's parameters and buffers detached, so a loss through them never reaches D."""
    state: dict[str, torch.Tensor] = dict(disc.named_parameters())
    state.update(dict(disc.named_buffers()))
    return {k: v.detach() for k, v in state.items()}


def sad_generator_loss(disc: nn.Module, fake: torch.Tensor) -> torch.Tensor:
    """LSGAN generator side of L_SAD (Eq. 12): high-specularity albedo patches should score as "real" (1).

    D's weights are used detached: this loss updates the model, never D.

    Args:
        disc: the patch discriminator (a bare module, not a DDP wrapper).
        fake: k x 3 x p x p patches from the high-specular-variance group (with gradient to f_A).
    """
    return ((functional_call(disc, _frozen(disc), (fake,)) - 1.0) ** 2).mean()


def sad_discriminator_loss(disc: nn.Module, real: torch.Tensor, fake: torch.Tensor) -> torch.Tensor:
    """LSGAN discriminator side of L_SAD: low-specularity patches -> 1, high -> 0. Inputs are detached, so this
    loss updates D only."""
    scores = disc(torch.cat([real, fake]).detach())  # one forward, as DistributedDataParallel expects
    k = real.shape[0]
    return 0.5 * (((scores[:k] - 1.0) ** 2).mean() + (scores[k:] ** 2).mean())


def _unit(x: torch.Tensor, lo: float, hi: float) -> torch.Tensor:
    return (x - lo) / (hi - lo)


def geometry_l1(pred: tuple[torch.Tensor, ...], target: tuple[torch.Tensor, ...],
                ranges: dict[str, tuple[float, float]]) -> dict[str, torch.Tensor]:
    """L1 of a shape and pose against a target, each value mapped to [0, 1] by its range.

    Args:
        pred, target: (radius B x L, height B, pose B x 4).
        ranges: (lo, hi) for "radius", "height", "pitch", "roll", "trans".

    Returns:
        Dict of scalar terms: radius, height, pose.
    """
    (radius, height, pose), (t_radius, t_height, t_pose) = pred, target
    pose_lo = torch.tensor([ranges["pitch"][0], ranges["roll"][0], ranges["trans"][0], ranges["trans"][0]])
    pose_hi = torch.tensor([ranges["pitch"][1], ranges["roll"][1], ranges["trans"][1], ranges["trans"][1]])
    pose_lo, pose_hi = pose_lo.to(pose), pose_hi.to(pose)
    return {
        "radius": (_unit(radius, *ranges["radius"]) - _unit(t_radius, *ranges["radius"])).abs().mean(),
        "height": (_unit(height, *ranges["height"]) - _unit(t_height, *ranges["height"])).abs().mean(),
        "pose": ((pose - t_pose) / (pose_hi - pose_lo)).abs().mean(),
    }


def material_l1(pred: tuple[torch.Tensor, ...], target: tuple[torch.Tensor, ...],
                ranges: dict[str, tuple[float, float]]) -> dict[str, torch.Tensor]:
    """L1 of an albedo, lighting and material against a target; env, alpha and rho mapped to [0, 1] by their range.

    Args:
        pred, target: (albedo B x 3 x Ht x Wt linear, env B x He x We, alpha B, rho B).
        ranges: (lo, hi) for "env", "alpha", "rho".

    Returns:
        Dict of scalar terms: albedo, env, alpha, rho.
    """
    (albedo, env, alpha, rho), (t_albedo, t_env, t_alpha, t_rho) = pred, target
    return {
        "albedo": (albedo - t_albedo).abs().mean(),
        "env": (_unit(env, *ranges["env"]) - _unit(t_env, *ranges["env"])).abs().mean(),
        "alpha": (_unit(alpha, *ranges["alpha"]) - _unit(t_alpha, *ranges["alpha"])).abs().mean(),
        "rho": (_unit(rho, *ranges["rho"]) - _unit(t_rho, *ranges["rho"])).abs().mean(),
    }


def pitch_label_l1(pitch: torch.Tensor, label: torch.Tensor, ranges: dict[str, tuple[float, float]]) -> torch.Tensor:
    """Self-training on pitch (loss.pitch_label_weight): L1 of B predicted pitches against B labels (deg), both
    mapped to [0, 1] by ranges["pitch"] like the supervised pose term."""
    return (_unit(pitch, *ranges["pitch"]) - _unit(label, *ranges["pitch"])).abs().mean()


def supervised_loss(pred: Decomposition, target: Decomposition, ranges: dict[str, tuple[float, float]]) -> dict:
    """The supervised baseline of Table 2: L1 of every output against ground truth, each mapped to [0, 1] by
    its range so the terms weigh alike.

    Args:
        pred, target: Decompositions of the same batch (target albedo B x 3 x Ht x Wt, env B x He x We).
        ranges: (lo, hi) for "radius", "height", "pitch", "roll", "trans", "alpha", "rho", "env".

    Returns:
        Dict of scalar terms: radius, height, pose, albedo, env, alpha, rho.
    """
    geometry = geometry_l1((pred.radius, pred.height, pred.pose), (target.radius, target.height, target.pose),
                           ranges)
    material = material_l1((pred.albedo, pred.env, pred.alpha, pred.rho),
                           (target.albedo, target.env, target.alpha, target.rho), ranges)
    return {**geometry, **material}
