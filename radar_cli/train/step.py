"""One training step's forward pass: render the model's prediction and evaluate every loss term (Eq. 14).

Kept apart from the loop so tests, the benchmark and the trainer share exactly the same computation.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import nn

from radar_cli.model import losses as L
from radar_cli.model.config import RunConfig
from radar_cli.model.outputs import Decomposition
from radar_cli.render.lighting import compose, tone_map
from radar_cli.render.mouth import coverage, coverage_above, mouth_margin
from radar_cli.render.raycast import Hits, cast_rays
from radar_cli.render.scene import Shading, render_front, shade


@dataclass(frozen=True)
class Batch:
    """A training batch on the device.

    Attributes:
        image: B x 3 x H x W tone-mapped RGB in [0, 1].
        mask: B x H x W target silhouette (0/1 float).
        dt: B x H x W distance transform of the mask (image sides).
        target: ground truth (synthetic data only) or None.
    """

    image: torch.Tensor
    mask: torch.Tensor
    dt: torch.Tensor
    target: Decomposition | None = None


@dataclass(frozen=True)
class Rendered:
    """What the step rendered, kept for the image grid.

    Attributes:
        hits: ray casting of the predicted shape.
        shading: diffuse, specular, tone-mapped texture and normals (B x C x Ht x Wt).
        recon: B x 3 x H x W reconstruction I^ (frontal third).
        front: B x 1 x H x W rendered frontal silhouette S^_f.
        sad_real, sad_fake: k x 3 x p x p albedo patches (None without L_SAD).
    """

    hits: Hits
    shading: Shading
    recon: torch.Tensor
    front: torch.Tensor
    sad_real: torch.Tensor | None
    sad_fake: torch.Tensor | None


def geometry_ranges(config: RunConfig) -> dict[str, tuple[float, float]]:
    """The (lo, hi) range of every output, for the supervised loss."""
    g, m = config.model.geometry, config.model
    return {"radius": g.radius_range, "height": g.height_range, "pitch": g.pitch_range, "roll": g.roll_range,
            "trans": g.trans_range, "alpha": m.shininess_range, "rho": m.spec_albedo_range, "env": m.env_range}


def render_prediction(pred: Decomposition, config: RunConfig) -> tuple[Hits, Shading, torch.Tensor, torch.Tensor]:
    """Ray-cast, shade and render the frontal third of a prediction: (hits, shading, I^, S^_f)."""
    m = config.model
    hits = cast_rays(pred.radius, pred.height, pred.pose, m.render.image_size, m.camera, m.render.sil_sigma_px)
    shading = shade(pred.radius, pred.height, pred.pose, pred.albedo, pred.env, pred.alpha, pred.rho,
                    m.render, m.camera)
    recon, front = render_front(hits, shading.texture)
    return hits, shading, recon, front


def _mouth_term(pred: Decomposition, hits: Hits, recon_mu: torch.Tensor, front: torch.Tensor, batch: Batch,
                config: RunConfig) -> torch.Tensor:
    """losses.mouth_l1 scored on the true silhouette's frontal and inside pixels within 4 sigma of where the mouth
    is or would be at the largest pitch (so a flatter pose cannot hide the mouth from the term)."""
    m, lc = config.model, config.loss
    size = m.render.image_size
    margin = mouth_margin(pred.radius, pred.height, pred.pose, size, m.camera)  # B x H x W
    mouth = coverage(margin, lc.mouth_sigma_px)[:, None]
    with torch.no_grad():
        steepest = pred.pose.detach().clone()
        steepest[:, 0] = m.geometry.pitch_range[1]
        widest = torch.maximum(margin, mouth_margin(pred.radius, pred.height, steepest, size, m.camera))
        band = coverage_above(widest, 4 * lc.mouth_sigma_px, 0.01)
        seen = torch.maximum(front, hits.inner[:, None].to(front.dtype))
        region = batch.mask[:, None] * band[:, None].to(front.dtype) * seen
    return L.mouth_l1(recon_mu, front, mouth, batch.image, region, m.render.inside_dim)


def generator_losses(pred: Decomposition, batch: Batch, config: RunConfig,
                     disc: nn.Module | None) -> tuple[dict[str, torch.Tensor], Rendered]:
    """Every loss term of the model (not of D) and their weighted sum under the key "total".

    Args:
        pred: the model's output for batch.image.
        batch: the batch.
        config: the run's configuration (weights, switches).
        disc: the bare SAD discriminator (used with frozen weights), or None when L_SAD is off.

    Returns:
        (losses, rendered): scalar tensors keyed sil, im, alb, diff, sad (those enabled) and total.
    """
    lc, render = config.loss, config.model.render
    hits, shading, recon, front = render_prediction(pred, config)
    if lc.supervised:
        if batch.target is None:
            from radar_cli.errors import InputError

            raise InputError("loss.supervised needs ground truth (params.json etc.) in every training sample")
        terms = L.supervised_loss(pred, batch.target, geometry_ranges(config))
        terms = {f"sup_{k}": v for k, v in terms.items()}
        terms["total"] = sum(terms.values())
        return terms, Rendered(hits, shading, recon, front, None, None)
    weight = batch.mask[:, None] * front  # S~ = S and S^_f, B x 1 x H x W
    terms = {"sil": L.silhouette_loss(hits.sil, batch.mask, batch.dt, lc.sil_weight, lc.dt_weight,
                                         lc.dt_margin_px),
             "im": L.masked_l1(recon, batch.image, weight)}
    total = terms["sil"] + lc.im_weight * terms["im"]
    if not lc.no_alb:
        tex_mu = compose(L.mean_color(pred.albedo), shading.diffuse, shading.specular, pred.rho, render.gamma)
        recon_mu, _ = render_front(hits, tex_mu)
        terms["alb"] = L.masked_l1(recon_mu, batch.image, weight)
        total = total + lc.alb_weight * terms["alb"]
        if lc.mouth_weight > 0:
            terms["mouth"] = _mouth_term(pred, hits, recon_mu, front, batch, config)
            total = total + lc.mouth_weight * terms["mouth"]
    if not lc.no_diff:
        terms["diff"] = L.diffuse_loss(shading.diffuse, lc.diff_target, lc.diff_margin)
        total = total + lc.diff_weight * terms["diff"]
    real = fake = None
    if not lc.no_sad and disc is not None:
        real, fake = L.sample_patches(tone_map(pred.albedo, render.gamma), shading.specular, lc.sad_patch,
                                      lc.sad_patches_per_image, lc.sad_group_fraction)
        terms["sad"] = L.sad_generator_loss(disc, fake)
        total = total + lc.sad_weight * terms["sad"]
    terms["total"] = total
    return terms, Rendered(hits, shading, recon, front, real, fake)
