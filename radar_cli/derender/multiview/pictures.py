"""Small pictures of an object's views for a curator (views/<photo>.png): each used view's photograph crop beside
the object drawn at that view's own shape, pose, lighting and turn with the fused albedo; a view left out of the
fit shows its photograph alone, an unreadable one nothing."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import torch

from radar_cli.dataset import safe_id
from radar_cli.derender.export.maps import write_picture
from radar_cli.derender.multiview.fit import ObjectFit, ViewFit, exported_solid
from radar_cli.derender.run.predictor import Predictor
from radar_cli.derender.run.state import ObjectState
from radar_cli.errors import InputError
from radar_cli.fileio import to_uint8
from radar_cli.render.scene import render_view
from radar_cli.results import VIEWS_DIR

VIEW_TILE = 128  # px per tile: a picture is VIEW_TILE high, photo | drawing (2 VIEW_TILE wide)
DRAW_SUPERSAMPLE = 2  # the drawing is rendered this many times larger and area-averaged down (smooth outline)


def draw_view(view: ViewFit, albedo: torch.Tensor, turn: float, predictor: Predictor,
              size: int | None = None) -> np.ndarray:
    """The view's object drawn at its own shape, pose and lighting, turned by `turn` deg, over white.

    Args:
        view: a fitted view (its appearance read).
        albedo: 1 x 3 x Ht x 3Wt linear albedo in the object's frame (the first used view's).
        turn: the view's turn about the axis from the first used view, degrees.
        size: the drawing's side in px (default: the view's output side N).

    Returns:
        size x size x 3 uint8.
    """
    a = view.looks
    render = ObjectState.export_render(predictor.setup.render)
    material = a.material.map(torch.Tensor.float).with_albedo(albedo)
    with torch.no_grad():
        image, _ = render_view(exported_solid(a), material, size or view.crops.side, -turn, render,
                               predictor.setup.camera)
    return to_uint8(image[0].permute(1, 2, 0).numpy())


def picture_names(views: list[ViewFit]) -> list[str | None]:
    """views/<name>.png per readable view (None for an unreadable one): the photo's stem made a safe id, made
    unique within the object (front.jpg and front.png: front, front-2)."""
    names: list[str | None] = []
    taken: set[str] = set()
    for k, view in enumerate(views):
        if view.prepared is None:
            names.append(None)
            continue
        try:
            base = safe_id(Path(view.source).stem)
        except InputError:
            base = f"view{k + 1}"
        name, n = base, 1
        while name.lower() in taken:  # case-insensitive file systems
            n += 1
            name = f"{base}-{n}"
        taken.add(name.lower())
        names.append(f"{VIEWS_DIR}/{name}.png")
    return names


def _tile(image: np.ndarray) -> np.ndarray:
    """VIEW_TILE x VIEW_TILE x 3 uint8 of a square image (area-averaged down)."""
    interpolation = cv2.INTER_AREA if image.shape[0] >= VIEW_TILE else cv2.INTER_CUBIC
    return cv2.resize(image, (VIEW_TILE, VIEW_TILE), interpolation=interpolation)


def view_picture(view: ViewFit, fit: ObjectFit, predictor: Predictor) -> np.ndarray:
    """VIEW_TILE x (2 VIEW_TILE) x 3 uint8 (photo | drawing) for a used view, VIEW_TILE square (the photo) for
    one left out."""
    photo = _tile(view.photo)
    if not view.used or view.appearance is None:
        return photo
    drawing = draw_view(view, fit.fused_map.albedo, view.turn, predictor, DRAW_SUPERSAMPLE * VIEW_TILE)
    return np.concatenate([photo, _tile(drawing)], axis=1)


def write_view_pictures(folder: Path, fit: ObjectFit, predictor: Predictor) -> dict[int, str]:
    """folder/views/<name>.png for every readable view, written atomically.

    Returns:
        Each pictured view's file name relative to `folder`, by id(view) (views_record's `picture`).
    """
    written = {}
    for view, name in zip(fit.views, picture_names(fit.views)):
        if name is not None:
            write_picture(folder / name, view_picture(view, fit, predictor))
            written[id(view)] = name
    return written
