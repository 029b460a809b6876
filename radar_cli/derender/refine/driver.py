"""Per-object refinement after the network (`radar derender --refine full`, the default): the shape and pose
fitted to the silhouette and the rim at the crop's resolution (derender.refine.fit_shape), the lighting, material
and albedo networks re-read at the fitted shape, the specular albedo read there by the specular-albedo reader
(model.specular_reader; or f_L's, held at most 1), then the environment map fitted to the photograph's shading
there (derender.refine.fit_light). A shape fit that fails, or draws the outline worse than the network's
prediction, falls back to the network's and says why (material.json `refine`, summary.csv); a lighting fit with
too few usable texels keeps the network's map. `--refine shape` stops after the re-reading."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.refine.fit_light import LightFitConfig, fit_environment
from radar_cli.derender.refine.fit_shape import fit_shape, outline_score
from radar_cli.derender.refine.shape_config import ShapeFitConfig
from radar_cli.masks.refine import iou
from radar_cli.model.outputs import Decomposition
from radar_cli.model.specular_reader import SpecularReader
from radar_cli.sor.outline import Outline, mask_outline, outline, row_mask
from radar_cli.sor.solid import Solid
from radar_cli.threads import torch_threads

RefineMode = Literal["full", "shape", "none"]
REFINE_MODES: tuple[RefineMode, ...] = ("full", "shape", "none")
FIT_ERRORS = (ValueError, RuntimeError, FloatingPointError)
MAX_SPECULAR_ALBEDO = 1.0  # the normalised Phong lobe reflects rho of the light arriving: above 1 it would make
# light (f_L's head reads 0..2); the cap lowers f_L's specular albedo error on every synthetic set measured


@dataclass(frozen=True)
class RefineReport:
    """What the refinement of one object did.

    Attributes:
        status: `refined`, `fallback` (the network's prediction kept, see reason) or `off` (--refine none).
        reason: why it fell back ('' if it did not).
        resolution: side of the crop the fit ran at (px).
        pitch_cue: `band` (painted bands), `lip` (the rim's front arc), `dark_lip` (that arc, its contrast taken
            relative to its grey level) or `outline` (the silhouette alone) picked the pitch.
        outline_px: mean distance between the drawn and the located outline (px at `resolution`), refined /
            network.
        iou: silhouette IoU against the located one at `resolution`, refined / network.
        specular: where the specular albedo comes from: `reader` (the specular-albedo reader at the fitted
            shape, model.specular_reader), `network` (f_L's re-reading, at most 1) or '' (no shape fit).
        light: `fitted` (the environment map fitted to the shading), `kept` (the network's map: too few texels
            were usable) or '' (not run: `--refine shape`, or no shape fit).
        light_rmse: the paints' model against the unwrapped texture (display levels), fitted / network map (a
            record, not a test: on synthetic vases the true map draws the texture better than the network's on
            fewer than half, docs/refinement.md).
        glare_scale: the factor on the specular albedo that keeps the fitted highlights under the photo
            (derender.refine.glare; 1: they were).
        seconds: time the fit took.
    """

    status: str
    reason: str = ""
    resolution: int = 0
    pitch_cue: str = ""
    outline_px: tuple[float, float] = (float("nan"), float("nan"))
    iou: tuple[float, float] = (float("nan"), float("nan"))
    specular: str = ""
    light: str = ""
    light_rmse: tuple[float, float] = (float("nan"), float("nan"))
    glare_scale: float = 1.0
    seconds: float = 0.0

    def record(self) -> dict:
        """material.json's `refine` entry (NaN written as null; no time, so the same input writes the same
        bytes)."""
        clean = lambda v: None if v != v else round(v, 4)  # noqa: E731
        return {"status": self.status, "reason": self.reason, "resolution": self.resolution,
                "pitch_cue": self.pitch_cue, "outline_px": {"refined": clean(self.outline_px[0]),
                                                            "network": clean(self.outline_px[1])},
                "silhouette_iou": {"refined": clean(self.iou[0]), "network": clean(self.iou[1])},
                "specular_albedo": self.specular, "light": self.light,
                "light_rmse": {"fitted": clean(self.light_rmse[0]), "network": clean(self.light_rmse[1])},
                "glare_scale": round(self.glare_scale, 4)}


def silhouette_iou(drawn: Outline, mask: np.ndarray) -> float:
    """IoU of the silhouette an N x N outline draws (batch of one) with an N x N bool mask."""
    return iou(row_mask(drawn)[0].cpu().numpy(), mask)


def refine_object(model, image: torch.Tensor, dec: Decomposition, crop: np.ndarray, silhouette: np.ndarray | None,
                  camera: CameraConfig, config: ShapeFitConfig = ShapeFitConfig(),
                  light: LightFitConfig | None = LightFitConfig(),
                  reader: SpecularReader | None = None) -> tuple[Decomposition | None, RefineReport]:
    """Refine one object's prediction.

    Args:
        model: the RadarModel (its read_appearance re-reads lighting, material and albedo at a shape).
        image: 1 x 3 x S x S network input in [0, 1], on the model's device. dec: its Decomposition (batch of
            one, CPU: the fits run there).
        crop: N x N x 3 uint8 crop at the output resolution; silhouette: N x N bool located silhouette (None:
            nothing to fit, the network's prediction is kept).
        camera: the fixed camera. config, light: the shape and the lighting fits' settings (light None: no
            lighting fit, the networks' re-reading is kept).
        reader: reads the specular albedo at the fitted shape (None: f_L's re-reading, at most 1).

    Returns:
        (the refined Decomposition with config.rows profile rows, or None to keep `dec`; the report).
    """
    size = crop.shape[0]
    if silhouette is None:
        return None, RefineReport("fallback", "no silhouette to fit (--crop none without --masks)", size)
    start = time.perf_counter()
    target = mask_outline(silhouette)
    network_drawn = outline(dec.solid, size, camera)
    network_iou = silhouette_iou(network_drawn, silhouette)
    network_px = float(outline_score(network_drawn, target, absolute=True)[0])
    grey = crop.astype(np.float32).mean(axis=2) / 255.0
    try:
        with torch_threads(1):  # the same bits whatever the caller's thread count (torch's sums split by thread)
            fit = fit_shape(silhouette, grey, config, camera, float(dec.pose[0, 0]))
            refined_iou = silhouette_iou(fit.drawn, silhouette)
    except FIT_ERRORS as e:
        return None, RefineReport("fallback", f"the fit failed ({type(e).__name__}: {e})", size,
                                 outline_px=(float("nan"), network_px), iou=(float("nan"), network_iou),
                                 seconds=time.perf_counter() - start)
    report = RefineReport("refined", "", size, fit.pitch_cue, (fit.outline_error, network_px),
                          (refined_iou, network_iou), seconds=time.perf_counter() - start)
    if not refined_iou >= network_iou:
        return None, dataclasses.replace(report, status="fallback",
                                        reason=f"the fit drew the silhouette worse (IoU {refined_iou:.3f} "
                                               f"against the network's {network_iou:.3f})")
    refined, report = read_at_shape(model, image, dec, Solid(fit.radius, fit.height, fit.pose), crop, silhouette,
                                    camera, light, reader, report)
    return refined, dataclasses.replace(report, seconds=time.perf_counter() - start)


def read_at_shape(model, image: torch.Tensor, dec: Decomposition, geo: Solid, crop: np.ndarray, silhouette: np.ndarray,
                  camera: CameraConfig, light: LightFitConfig | None, reader: SpecularReader | None,
                  report: RefineReport) -> tuple[Decomposition, RefineReport]:
    """The appearance at a fitted shape: lighting, material and albedo re-read there by the networks, the specular
    albedo by `reader` (None: f_L's, at most 1), the environment map fitted to the crop's shading (light None:
    the re-reading kept). geo: the fitted solid (radius 1 x L, height 1, pose 1 x 4); the rest as refine_object.
    The networks run on `image`'s device; the result is on the CPU."""
    device = image.device
    with torch.no_grad():
        solid = geo.map(lambda t: t.to(device))
        refined = model.read_appearance(image, solid).detach()
        rho = refined.rho.clamp(max=MAX_SPECULAR_ALBEDO) if reader is None else reader(image, solid)
    refined = dataclasses.replace(refined, rho=rho).to("cpu")
    report = dataclasses.replace(report, specular="network" if reader is None else "reader")
    if light is not None:
        refined, report = _fit_light(refined, dec.env.cpu(), crop, silhouette, camera, light, report)
    return refined, report


def _fit_light(refined: Decomposition, network_env: torch.Tensor, crop: np.ndarray, silhouette: np.ndarray,
               camera: CameraConfig, config: LightFitConfig, report: RefineReport) -> tuple[Decomposition,
                                                                                             RefineReport]:
    """`refined` with its environment map fitted to the crop's shading (derender.refine.fit_light), starting from the
    network's first reading `network_env` (1 x He x We), and its specular albedo lowered to the highlights the fit
    found; or with that map where too few texels are usable."""
    with torch.no_grad():
        fit = fit_environment(crop, silhouette, refined.radius, refined.height, refined.pose, network_env,
                              float(refined.alpha[0]), float(refined.rho[0]), camera, config)
    if fit is None:
        return dataclasses.replace(refined, env=network_env), dataclasses.replace(report, light="kept")
    return (dataclasses.replace(refined, env=fit.env, rho=refined.rho * fit.specular_scale),
            dataclasses.replace(report, light="fitted", light_rmse=fit.rmse, glare_scale=fit.glare_scale))
