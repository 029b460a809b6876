"""One training step's forward pass: render the model's prediction and evaluate every loss term (Eq. 14).

Kept apart from the loop so tests, the benchmark and the trainer share exactly the same computation.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import cast

import torch
from torch import nn

from radar_cli.model import losses as L
from radar_cli.model.config import RunConfig
from radar_cli.model.outputs import Decomposition
from radar_cli.model.radar import RadarModel
from radar_cli.render.lighting import compose, tone_map
from radar_cli.render.mouth import coverage, coverage_above, mouth_margin
from radar_cli.render.raycast import Hits
from radar_cli.render.scene import Shading, divide_shading, render_front, render_frontal, render_synthetic
from radar_cli.render.texture import full_from_front
from radar_cli.sor.solid import Solid


@dataclass(frozen=True)
class Batch:
    """A training batch on the device.

    Attributes:
        image: B x 3 x H x W tone-mapped RGB in [0, 1].
        mask: B x H x W target silhouette (0/1 float).
        dt: B x H x W distance transform of the mask (image sides).
        target: ground truth (synthetic data only) or None.
        pitch_label: B pitches (deg) from `radar derender --pitch search` (loss.pitch_label_weight) or None.
    """

    image: torch.Tensor
    mask: torch.Tensor
    dt: torch.Tensor
    target: Decomposition | None = None
    pitch_label: torch.Tensor | None = None


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


def output_ranges(config: RunConfig) -> dict[str, tuple[float, float]]:
    """The (lo, hi) range of every output, for the supervised loss."""
    g, m = config.model.geometry, config.model
    return {"radius": g.radius_range, "height": g.height_range, "pitch": g.pitch_range, "roll": g.roll_range,
            "trans": g.trans_range, "alpha": m.shininess_range, "rho": m.spec_albedo_range, "env": m.env_range}


def render_prediction(pred: Decomposition, config: RunConfig) -> tuple[Hits, Shading, torch.Tensor, torch.Tensor]:
    """Ray-cast, shade and render the frontal third of a prediction: (hits, shading, I^, S^_f)."""
    return render_frontal(pred.solid, pred.material, config.model.render, config.model.camera)


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


def background_colour(image: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean colour of each image off its silhouette (B x 3 x H x W, B x H x W 0/1) -> B x 3 x 1 x 1."""
    off = (1 - mask)[:, None]
    return (image * off).sum(dim=(2, 3), keepdim=True) / off.sum(dim=(2, 3), keepdim=True).clamp_min(1.0)


@torch.no_grad()
def redraw(pred: Decomposition, pose: torch.Tensor, background: torch.Tensor, config: RunConfig) -> torch.Tensor:
    """A prediction drawn whole from another pose, the way `radar synth` draws its images: the frontal albedo
    mirrored round the back, shaded over the full 360 deg, the inside dimmed, over a plain background, quantised
    to 8 bits. The anti-aliased inner edge uses the model's silhouette softness (render.sil_sigma_px; radar synth
    draws with the default 1 px, the sharp CPU stages train at 0.25 px).

    Args:
        pred: B objects. pose: B x 4. background: B x 3 x 1 x 1.

    Returns:
        B x 3 x H x W tone-mapped image in [0, 1].
    """
    m = config.model
    solid = Solid(pred.radius, pred.height, pose)
    material = pred.material.with_albedo(full_from_front(pred.albedo))
    image, _, _ = render_synthetic(solid, material, m.render.image_size, m.render, m.camera, background)
    return (image.clamp(0.0, 1.0) * 255).round() / 255


def shape_cycle_term(shape_net: nn.Module, pred: Decomposition, background: torch.Tensor,
                     config: RunConfig) -> torch.Tensor:
    """The shape cycle (radar's addition; loss.cycle_weight): redraw the prediction at a pitch drawn uniformly
    from the model's range (the global RNG, reseeded every step) over `background` (B x 3 x 1 x 1, the inputs'
    background_colour) and ask f_S for its radius, height and pose back (geometry_l1 against what was drawn).
    Only f_S learns from it; the redrawn image carries no gradient."""
    target = pred.detach()
    lo, hi = config.model.geometry.pitch_range
    pose = target.pose.clone()
    pose[:, 0] = lo + (hi - lo) * torch.rand(pose.shape[0]).to(pose)
    image = redraw(target, pose, background, config)
    terms = L.geometry_l1(shape_net(image), (target.radius, target.height, pose), output_ranges(config))
    return cast(torch.Tensor, sum(terms.values()))  # terms is never empty


@torch.no_grad()
def divided_prediction(pred: Decomposition, shading: Shading, batch: Batch, config: RunConfig) -> Decomposition:
    """The prediction, detached, with its albedo replaced by the batch's images divided by its shading (`shading`,
    already computed by render_prediction; render.scene.divide_shading, the true silhouette as the coverage): what
    the cycles redraw with under loss.cycle_albedo = "divided"."""
    m = config.model
    target = pred.detach()
    albedo = divide_shading(batch.image, target.solid, target.albedo, target.rho,
                            shading, m.render, m.camera, batch.mask[:, None])
    return dataclasses.replace(target, albedo=albedo)


def relit(pred: Decomposition, alpha: torch.Tensor) -> Decomposition:
    """Each object of a batch with the previous one's environment map and specular albedo (rolled by one) and the
    given shininess (B)."""
    return Decomposition(pred.radius, pred.height, pred.pose, pred.albedo, pred.env.roll(1, 0), alpha,
                         pred.rho.roll(1, 0))


def light_cycle_term(model: RadarModel, pred: Decomposition, background: torch.Tensor,
                     config: RunConfig) -> torch.Tensor:
    """The lighting cycle (radar's addition; loss.light_cycle_weight): redraw each prediction, at its own pose,
    under another object's predicted environment map and specular albedo and a shininess drawn uniformly from the
    model's range (the global RNG), over `background` as in the shape cycle; unwrap the redraw with the shape it
    was drawn with, and ask f_L for that lighting and material and f_A for the same albedo back (material_l1).
    The lighting of the redraw is known exactly, so f_L learns to read it, and f_A learns to give one albedo
    whatever the lighting. f_S is not involved; the redrawn image carries no gradient.

    The shininess is drawn, not taken from another prediction: asked to give back predicted values it cannot read
    from a 64 px image, f_L answered one constant for every object, the term was then met trivially, and the
    other losses drove that constant to the range's top (measured: every prediction 195-196 after 1,000 steps)."""
    detached = pred.detach()
    lo, hi = config.model.shininess_range
    target = relit(detached, lo + (hi - lo) * torch.rand(detached.alpha.shape[0]).to(detached.alpha))
    image = redraw(target, target.pose, background, config)
    texture, normals = model.unwrap_inputs(target.solid, image)
    env, alpha, rho = model.light_net(texture, normals)
    terms = L.material_l1((model.albedo_net(texture), env, alpha, rho),
                          (target.albedo, target.env, target.alpha, target.rho), output_ranges(config))
    return cast(torch.Tensor, sum(terms.values()))  # terms is never empty


def generator_losses(pred: Decomposition, batch: Batch, config: RunConfig, disc: nn.Module | None,
                     model: RadarModel | None = None) -> tuple[dict[str, torch.Tensor], Rendered]:
    """Every loss term of the model (not of D) and their weighted sum under the key "total".

    Args:
        pred: the model's output for batch.image.
        batch: the batch.
        config: the run's configuration (weights, switches).
        disc: the bare SAD discriminator (used with frozen weights), or None when L_SAD is off.
        model: the model (bare module, not a DDP wrapper), for the cycles; needed when loss.cycle_weight or
            loss.light_cycle_weight is > 0.

    Returns:
        (losses, rendered): scalar tensors keyed sil, im, alb, mouth, diff, sad, cycle, light_cycle (those
        enabled) and total.
    """
    lc, render = config.loss, config.model.render
    hits, shading, recon, front = render_prediction(pred, config)
    if lc.supervised:
        if batch.target is None:
            from radar_cli.errors import InputError

            raise InputError("loss.supervised needs ground truth (params.json etc.) in every training sample")
        terms = L.supervised_loss(pred, batch.target, output_ranges(config))
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
    if lc.pitch_label_weight > 0:
        if batch.pitch_label is None:
            raise ValueError("loss.pitch_label_weight > 0 needs the batch's pitch labels (radar train --pitch-labels)")
        terms["pitch_label"] = L.pitch_label_l1(pred.pose[:, 0], batch.pitch_label, output_ranges(config))
        total = total + lc.pitch_label_weight * terms["pitch_label"]
    if lc.cycle_weight > 0 or lc.light_cycle_weight > 0:
        if model is None:
            raise ValueError("loss.cycle_weight or loss.light_cycle_weight > 0 needs the model")
        background = background_colour(batch.image, batch.mask)
        drawn = divided_prediction(pred, shading, batch, config) if lc.cycle_albedo == "divided" else pred
    if lc.cycle_weight > 0:
        assert model is not None  # checked above
        terms["cycle"] = shape_cycle_term(model.shape_net, drawn, background, config)
        total = total + lc.cycle_weight * terms["cycle"]
    if lc.light_cycle_weight > 0:
        assert model is not None  # checked above
        terms["light_cycle"] = light_cycle_term(model, drawn, background, config)
        total = total + lc.light_cycle_weight * terms["light_cycle"]
    terms["total"] = total
    return terms, Rendered(hits, shading, recon, front, real, fake)
