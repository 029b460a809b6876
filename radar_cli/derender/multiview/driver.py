"""`radar derender` for an object photographed from several sides (a sub-folder of photos, run.inputs): its views
read and cropped (an unreadable photo is left out with one line, the object goes on with the others), the network
run on them as one batch, the object fitted from all of them (multiview.fit) and exported from its first used view
with the fused albedo, coverage.png, a picture per view (views/) and material.json's `views`."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Callable

import numpy as np

from radar_cli.derender.export.maps import write_picture
from radar_cli.derender.export.object_folder import ExportConfig, export_object
from radar_cli.derender.multiview.fit import MultiviewConfig, ObjectFit, ViewFit, fit_object, object_state, views_record
from radar_cli.derender.multiview.pictures import write_view_pictures
from radar_cli.derender.run.inputs import (
    Backdrop,
    CropMode,
    Failure,
    InputItem,
    Prepared,
    Resolution,
    prepare,
    resize_image,
    resize_mask,
)
from radar_cli.derender.run.object_record import ObjectRecord
from radar_cli.derender.run.predictor import Predictor
from radar_cli.errors import InputError, RadarError
from radar_cli.results import COVERAGE_FILE, MATERIAL_FILE
from radar_cli.threads import thread_map


def same_side(prepared: Prepared, side: int) -> Prepared:
    """A view's output-side crops at `side` (views cropped from photos of different sizes)."""
    if prepared.side == side:
        return prepared
    mask = lambda m: None if m is None else resize_mask(m, side)  # noqa: E731
    image = lambda m: None if m is None else resize_image(m, side)  # noqa: E731
    return dataclasses.replace(prepared, photo_image=image(prepared.photo_image),
                               photo_scene=image(prepared.photo_scene),
                               photo_silhouette=mask(prepared.photo_silhouette), appendages=mask(prepared.appendages))


UNREADABLE = "unreadable"  # a view's `reason` in material.json when its photo could not be read: "unreadable (...)"


def left_out(source: str, problem: str, name: str) -> Failure:
    """The Failure of a photo that the object `name` was fitted without (`problem`: why it could not be read)."""
    return Failure(source, f"{problem}; left out, {name} goes on with its other views")


def recorded_left_out(folder: Path, name: str) -> list[Failure]:
    """The Failures of the photos a finished multi-view object (folder/material.json) was fitted without because
    they could not be read, as its run reported them: a run that skips the object reports them again, so that
    failures.csv keeps them and the run still exits non-zero. Empty if the record cannot be read."""
    try:
        views = json.loads((folder / MATERIAL_FILE).read_text()).get("views", [])
    except (OSError, ValueError, AttributeError):
        return []
    failures = []
    for view in views if isinstance(views, list) else []:
        reason = view.get("reason") if isinstance(view, dict) else None
        if isinstance(reason, str) and reason.startswith(f"{UNREADABLE} (") and reason.endswith(")"):
            failures.append(left_out(str(view.get("source", "")), reason[len(UNREADABLE) + 2 : -1], name))
    return failures


def read_views(item: InputItem, size: int, crop: CropMode, backdrop: Backdrop, resolution: Resolution,
               say: Callable[[str], None], workers: int = 1) -> tuple[list[ViewFit], list[Failure]]:
    """Every photo of the object prepared (prepare, `workers` at a time) at the smallest view's output side; an
    unreadable one is a ViewFit without crops, a Failure and one line."""
    def read(path: Path) -> Prepared | RadarError:
        try:
            return prepare(InputItem(item.name, path), size, crop, backdrop, resolution)
        except RadarError as e:
            return e

    views, failures = [], []
    for path, prepared in zip(item.views, thread_map(read, item.views, workers)):
        if isinstance(prepared, RadarError):
            problem = str(prepared).removeprefix(f"{path}: ")
            failure = left_out(str(path), problem, item.name)
            say(failure.line())
            failures.append(failure)
            views.append(ViewFit(str(path), None, reason=f"{UNREADABLE} ({problem})"))
        else:
            views.append(ViewFit(str(path), prepared))
    readable = [v for v in views if v.prepared is not None]
    if not readable:
        raise InputError(f"{item.image_path.parent}: none of the object's {len(item.views)} photos could be read")
    side = min(v.crops.side for v in readable)
    for view in readable:
        view.prepared = same_side(view.crops, side)
    return views, failures


def fit_views(item: InputItem, predictor: Predictor, crop: CropMode, backdrop: Backdrop, resolution: Resolution,
              say: Callable[[str], None], config: MultiviewConfig = MultiviewConfig(),
              workers: int = 1) -> tuple[ObjectFit, list[Failure]]:
    """Read, predict and fit one multi-view object, its views `workers` at a time (its Failures: the photos left
    out unread)."""
    views, failures = read_views(item, predictor.setup.render.image_size, crop, backdrop, resolution, say, workers)
    readable = [v.crops for v in views if v.prepared is not None]
    dec = predictor.predict([p.image for p in readable], [p.silhouette for p in readable])
    decs = [dec.select(k) for k in range(len(readable))]
    return fit_object(views, decs, predictor, config, workers), failures


def derender_views(item: InputItem, predictor: Predictor, out: Path, crop: CropMode, backdrop: Backdrop,
                   resolution: Resolution, envs: dict[str, np.ndarray], export: ExportConfig,
                   say: Callable[[str], None], record: ObjectRecord = ObjectRecord(), workers: int = 1
                   ) -> list[Failure]:
    """De-render one multi-view object into out/<name>/ (at its catalogued size if known, its status read with
    its catalogue description, as export_object), its views read and fitted `workers` at a time; returns the
    photos left out unread (the object is done).

    Raises:
        RadarError, ValueError, RuntimeError, OSError: the object could not be de-rendered.
    """
    fit, failures = fit_views(item, predictor, crop, backdrop, resolution, say, workers=workers)
    for view in fit.views:
        if view.prepared is not None and not view.used:
            say(f"{view.source}: left out of {item.name}'s fit: {view.reason}")
    first = fit.used[0]
    folder = out / item.name
    folder.mkdir(parents=True, exist_ok=True)
    write_picture(folder / COVERAGE_FILE, fit.fused_map.coverage_image())
    pictures = write_view_pictures(folder, fit, predictor)
    assert first.report is not None
    export_object(folder, InputItem(item.name, Path(first.source)), first.crops, object_state(fit, predictor),
                  predictor.setup, predictor.version, envs, export, "divided", predictor.pitch, first.report.record(),
                  size=record.size, description=record.description, extra=views_record(fit, pictures),
                  scores=fit.scores())
    return failures
