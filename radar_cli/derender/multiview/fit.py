"""Fitting one object from its views: each view's own shape search, the side views chosen, one profile for them
all (multiview.joint_shape), each view's lighting and material read at its fit (derender.refine.driver), each
view's texture unwrapped over 360 deg (multiview.fuse), the turns registered (multiview.turns) and the albedo
fused in the first used view's frame."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import torch

from radar_cli.config import CameraConfig
from radar_cli.derender.export.quality import QualityLimits, frame_cut, into_the_mouth
from radar_cli.derender.multiview.fuse import FuseConfig, Fused, ViewTexture, fuse, match_exposure, unwrap_view
from radar_cli.derender.multiview.joint_shape import Geometry, fit_jointly, profile_spread
from radar_cli.derender.multiview.turns import TurnConfig, Turns, handle_phase, register_turns
from radar_cli.derender.refine.driver import FIT_ERRORS, RefineReport, read_at_shape
from radar_cli.derender.refine.fit_light import LightFitConfig
from radar_cli.derender.refine.fit_shape import ShapeFit, fit_shape
from radar_cli.derender.refine.shape_config import ShapeFitConfig
from radar_cli.derender.run.inputs import Prepared
from radar_cli.derender.run.predictor import Predictor
from radar_cli.derender.run.state import ObjectState, quantise
from radar_cli.derender.run.upsample import PROFILE_ROWS, photo_tensors
from radar_cli.masks.quality import sor_score
from radar_cli.model.outputs import Decomposition
from radar_cli.sor.outline import row_mask
from radar_cli.sor.resample import smooth_rows
from radar_cli.sor.solid import Solid
from radar_cli.threads import thread_map, torch_threads


@dataclass(frozen=True)
class MultiviewConfig:
    """How an object's views are fitted together.

    Attributes:
        max_spread: a view whose own profile (radii over half-height) lies further than this (mean relative
            difference) from the views' median is not a side view (a top view into the mouth, a detail) and is
            left out.
        max_outline_ratio: so is a view whose own fit draws its outline this many times worse than the views'
            median (and at least 2 px).
        shape, turns, fuse: the shape fit's, the turns' and the fusion's settings.
    """

    max_spread: float = 0.2
    max_outline_ratio: float = 3.0
    shape: ShapeFitConfig = ShapeFitConfig()
    turns: TurnConfig = TurnConfig()
    fuse: FuseConfig = FuseConfig()


@dataclass
class ViewFit:
    """One view of the object and what became of it.

    Attributes:
        source: the photo. prepared: its crops (None: unreadable). used: part of the shape fit and the texture.
        reason: why not.
        network: the network's reading of it (batch of one). own: its own shape fit (None if that failed).
        geometry: its solid: the shared profile at its scale, its pose.
        appearance: its Decomposition at that geometry (lighting, material). texture: its 360 deg albedo.
        turn: degrees about the axis from the first used view; registered: the turn came from the textures.
        agreement: the mean correlation with the views it overlaps at its turn.
        outline_px: the shared profile's outline distance in this view (px at the output side).
    """

    source: str
    prepared: Prepared | None
    used: bool = False
    reason: str = ""
    network: Decomposition | None = None
    own: ShapeFit | None = None
    geometry: Geometry | None = None
    appearance: Decomposition | None = None
    report: RefineReport | None = None
    texture: ViewTexture | None = None
    turn: float = 0.0
    registered: bool = False
    agreement: float = float("nan")
    outline_px: float = float("nan")

    @property
    def crops(self) -> Prepared:
        assert self.prepared is not None, f"{self.source}: not read"
        return self.prepared

    @property
    def photo(self) -> np.ndarray:
        """N x N x 3 uint8 crop at the output side."""
        assert self.crops.photo_image is not None
        return self.crops.photo_image

    @property
    def mask(self) -> np.ndarray:
        """N x N bool silhouette at the output side."""
        assert self.crops.photo_silhouette is not None, f"{self.source}: no silhouette"
        return self.crops.photo_silhouette

    @property
    def outline_share(self) -> float:
        """outline_px over the silhouette's height (NaN before the joint fit)."""
        rows = np.nonzero(self.mask.any(1))[0]
        return self.outline_px / float(rows[-1] - rows[0] + 1) if rows.size else float("nan")

    @property
    def own_fit(self) -> ShapeFit:
        assert self.own is not None, f"{self.source}: not fitted"
        return self.own

    @property
    def solid(self) -> Solid:
        assert self.geometry is not None, f"{self.source}: not fitted"
        return self.geometry

    @property
    def looks(self) -> Decomposition:
        assert self.appearance is not None, f"{self.source}: its appearance not read"
        return self.appearance

    @property
    def tex(self) -> ViewTexture:
        assert self.texture is not None, f"{self.source}: not unwrapped"
        return self.texture

    def record(self, share: float, picture: str | None = None) -> dict:
        """material.json's entry for this view (`picture`: its views/ file, relative to the object's folder)."""
        entry = {"source": self.source, "used": self.used, "reason": self.reason, "picture": picture}
        if self.used and self.geometry is not None:
            pitch, roll, tx, ty = (round(float(v), 4) for v in self.geometry.pose[0])
            clean = lambda v: None if v != v else round(v, 4)  # noqa: E731
            entry.update({"turn_deg": round(self.turn, 2), "turn_from": "texture" if self.registered else "prior",
                          "agreement": clean(self.agreement), "pitch": pitch, "roll": roll, "tx": tx, "ty": ty,
                          "height": round(float(self.geometry.height[0]), 4), "outline_px": clean(self.outline_px),
                          "texel_share": round(share, 4)})
        return entry


@dataclass
class ObjectFit:
    """All views fitted: the views (first used one first) and the fused albedo."""

    views: list[ViewFit]
    fused: Fused | None = None
    turns: Turns | None = None
    extra: dict = field(default_factory=dict)

    @property
    def used(self) -> list[ViewFit]:
        return [v for v in self.views if v.used]

    def scores(self) -> dict:
        """The object's quality scores from all its views (derender.export.quality): `views_outline`, the
        largest share of its height by which a used view's silhouette lies off the shared solid."""
        shares = [v.outline_share for v in self.used]
        worst = max((s for s in shares if s == s), default=None)
        return {"views_outline": None if worst is None else round(worst, 4)}

    @property
    def fused_map(self) -> Fused:
        assert self.fused is not None
        return self.fused


def own_fits(views: list[ViewFit], decs: list[Decomposition], config: MultiviewConfig,
             camera: CameraConfig, workers: int = 1) -> None:
    """Each view's own shape fit (fit_shape, the network's pitch as its prior), `workers` at a time; a view whose
    fit fails is left out."""
    def fit(pair: tuple[ViewFit, Decomposition]) -> None:
        view, dec = pair
        view.network = dec
        if view.crops.photo_silhouette is None:
            view.reason = "no silhouette to fit (--crop none without --masks)"
            return
        grey = view.photo.astype(np.float32).mean(axis=2) / 255.0
        try:
            with torch_threads(1):
                view.own = fit_shape(view.mask, grey, config.shape, camera, float(dec.pose[0, 0]))
            view.used = True
        except FIT_ERRORS as e:
            view.reason = f"its shape fit failed ({type(e).__name__}: {e})"

    thread_map(fit, list(zip([v for v in views if v.prepared is not None], decs)), workers)


def _not_whole(view: ViewFit) -> str | None:
    """Why a view does not show the object whole, as the status reads a single photo: its frame cuts it
    (quality.frame_cut), or what it located is not symmetric about an axis (a detail whose painting was taken for
    the object, or another object); None where it does."""
    limits = QualityLimits()
    cut = frame_cut(view.crops.cut_edges, limits)
    if cut:
        return cut
    whole = view.mask if view.crops.appendages is None else view.mask | view.crops.appendages
    symmetry = sor_score(whole)
    if symmetry < limits.review_object_symmetry:
        return f"what it shows is not symmetric about an axis ({symmetry:.2f}): a detail, or another object?"
    return None


def choose_side_views(views: list[ViewFit], config: MultiviewConfig) -> None:
    """Leave out the views that look from above into the mouth (quality.into_the_mouth) and, where another view
    shows the object whole, those that do not (`_not_whole`: a detail, another object), however many views there
    are; then those whose own profile or outline disagrees with the others' (not seen from the side)."""
    for view in (v for v in views if v.used):
        if into_the_mouth(view.photo, view.mask, row_mask(view.own_fit.drawn)[0].numpy()):
            view.used, view.reason = False, ("not a side view: it looks from above into the mouth (round, a lit "
                                             "rim round a dark inside)")
    partial = {id(v): _not_whole(v) for v in views if v.used}
    if any(reason is None for reason in partial.values()):
        for view in (v for v in views if v.used and partial[id(v)]):
            view.used, view.reason = False, f"not a whole view: {partial[id(view)]}"
    candidates = [v for v in views if v.used]
    if len(candidates) < 3:
        return  # two views cannot outvote each other
    spread = profile_spread([v.own_fit for v in candidates])
    typical = float(np.median([v.own_fit.outline_error for v in candidates]))
    for view, s in zip(candidates, spread):
        if s > config.max_spread:
            view.used, view.reason = False, f"not a side view: its own profile differs from the others' by {s:.0%}"
        elif view.own_fit.outline_error > max(config.max_outline_ratio * typical, 2.0):
            error = view.own_fit.outline_error
            view.used, view.reason = False, (f"not a side view: its own outline fits {error:.1f} px off (the "
                                             f"views' median {typical:.1f} px)")


def read_appearance(view: ViewFit, predictor: Predictor) -> None:
    """A view's lighting and material at its geometry: the networks re-read there and the light fitted
    (derender.refine.driver.read_at_shape; `--refine shape`: not fitted; `--refine none`: the network's first
    reading, the geometry replaced)."""
    solid, network = view.solid, view.network
    assert network is not None
    report = RefineReport("refined", "", view.crops.side, view.own_fit.pitch_cue, (view.outline_px, float("nan")))
    if predictor.refine == "none":
        view.appearance = dataclasses.replace(network, radius=solid.radius, height=solid.height, pose=solid.pose)
        view.report = report
        return
    image = torch.from_numpy(view.crops.image).permute(2, 0, 1)[None].float() / 255.0
    light = LightFitConfig() if predictor.refine == "full" else None
    with torch_threads(1):
        appearance, view.report = read_at_shape(
            predictor.model, image.to(predictor.device), network.to(predictor.device), solid,
            view.photo, view.mask, predictor.setup.camera, light,
            predictor.reader, report)
    view.appearance = appearance.to("cpu")


def unwrap_texture(view: ViewFit, predictor: Predictor) -> ViewTexture:
    """A view's photograph unwrapped over 360 deg at its geometry and divided by its shading."""
    a = view.looks
    photo, coverage = photo_tensors(view.crops)
    if coverage is None:
        coverage = torch.ones_like(photo[:, :1])
    render = ObjectState.export_render(predictor.setup.render)
    return unwrap_view(photo, coverage, exported_solid(a), a.material.map(torch.Tensor.float), view.crops.side,
                       render, predictor.setup.camera)


def exported_solid(dec: Decomposition) -> Solid:
    """A fitted Decomposition's solid as exported: its profile resampled to PROFILE_ROWS rows (at least), float."""
    radius = smooth_rows(dec.radius.float(), max(PROFILE_ROWS, dec.radius.shape[1]))
    return Solid(radius, dec.height.float(), dec.pose.float())


def fit_object(views: list[ViewFit], decs: list[Decomposition], predictor: Predictor,
               config: MultiviewConfig = MultiviewConfig(), workers: int = 1) -> ObjectFit:
    """Fit an object from its views (the readable ones prepared at the same output side N) and the network's
    reading of each readable one (decs, in order); the views' own work `workers` at a time.

    Raises:
        ValueError: no view could be fitted.
    """
    own_fits(views, decs, config, predictor.setup.camera, workers)
    choose_side_views(views, config)
    return fit_chosen(views, predictor, config, workers=workers)


def fit_chosen(views: list[ViewFit], predictor: Predictor, config: MultiviewConfig = MultiviewConfig(),
               turns: list[float] | None = None, workers: int = 1) -> ObjectFit:
    """The shared profile, appearances, turns (registered, or as given per used view) and fused albedo of the
    views marked used (own fits done); each view's appearance and texture `workers` at a time."""
    used = [v for v in views if v.used]
    if not used:
        raise ValueError("no view could be fitted: " + "; ".join(f"{v.source}: {v.reason}" for v in views))
    geometries, errors = fit_jointly([v.mask for v in used], [v.own_fit for v in used],
                                     config.shape, predictor.setup.camera)
    for view, geometry, error in zip(used, geometries, errors):
        view.geometry, view.outline_px = geometry, error

    def look(view: ViewFit) -> None:
        read_appearance(view, predictor)
        view.texture = unwrap_texture(view, predictor)

    thread_map(look, used, workers)
    if turns is None:
        found = register_turns([v.tex for v in used], config.turns,
                               [handle_phase(v.mask, v.crops.appendages) for v in used])
    else:
        found = Turns(tuple(turns), (False,) * len(used), (float("nan"),) * len(used))
    for view, turn, registered, agreement in zip(used, found.degrees, found.registered, found.agreement):
        view.turn, view.registered, view.agreement = turn, registered, agreement
    turned = match_exposure([v.tex.turned(v.turn) for v in used], config.fuse)
    return ObjectFit(views, fuse(turned, config.fuse), found)


def object_state(fit: ObjectFit, predictor: Predictor) -> ObjectState:
    """The exported object: the first used view's geometry, lighting and material, the fused albedo."""
    first = fit.used[0].looks
    setup = predictor.setup
    solid = exported_solid(first)
    state = ObjectState.from_decomposition(dataclasses.replace(first, radius=solid.radius), setup.render,
                                           setup.camera)
    albedo = quantise(fit.fused_map.albedo, setup.render.gamma)
    return dataclasses.replace(state, material=state.material.with_albedo(albedo))


def views_record(fit: ObjectFit, pictures: dict[int, str] | None = None) -> dict:
    """material.json's `views` (every photo: used or left out and why, turn, pose, its picture from `pictures`,
    by id(view)) and `seen_fraction`."""
    shares = {}
    if fit.fused is not None:
        total = fit.fused.share.sum(dim=0).sum()
        for view, share in zip(fit.used, fit.fused.share):
            shares[id(view)] = float(share.sum() / max(float(total), 1e-12))
    seen = None if fit.fused is None else round(fit.fused.seen_fraction(), 4)
    pictures = pictures or {}
    return {"views": [v.record(shares.get(id(v), 0.0), pictures.get(id(v))) for v in fit.views],
            "seen_fraction": seen}
