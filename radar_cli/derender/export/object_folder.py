"""Everything written for one de-rendered object, in order, with material.json last: its presence marks the
folder complete, so a killed run redoes half-written folders and skips finished ones."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from radar_cli.derender.export.maps import write_maps, write_picture
from radar_cli.derender.export.mesh import write_meshes
from radar_cli.derender.export.quality import assess_drawn
from radar_cli.derender.export.renders import write_renders
from radar_cli.derender.run.inputs import InputItem, Prepared
from radar_cli.derender.run.predictor import AlbedoSource, PitchSource
from radar_cli.derender.run.state import ObjectState
from radar_cli.fileio import write_json
from radar_cli.model.config import ModelConfig
from radar_cli.results import APPENDAGES_FILE, INPUT_FILE, MATERIAL_FILE, SILHOUETTE_FILE
from radar_cli.sizes import ObjectSize

MIN_VIEW_SIZE = 128


@dataclass(frozen=True)
class ExportConfig:
    """What is rendered per object besides the maps and meshes."""

    views: int = 8
    """Turntable frames (0 = no turntable)."""
    view_size: int | None = None
    """Side in pixels of the turntable frames, relit views and the material sphere; None: the output side, at
    least MIN_VIEW_SIZE."""

    def view_side(self, output_side: int) -> int:
        """The views' side for objects exported at `output_side`."""
        return self.view_size if self.view_size is not None else max(MIN_VIEW_SIZE, output_side)


def is_complete(folder: Path) -> bool:
    """True if `folder` holds a finished export (material.json is written last)."""
    return (folder / MATERIAL_FILE).is_file()


def export_object(folder: Path, item: InputItem, prepared: Prepared, state: ObjectState, setup: ModelConfig,
                  version: str, envs: dict[str, np.ndarray], config: ExportConfig = ExportConfig(),
                  albedo_source: AlbedoSource = "network", pitch_source: PitchSource = "network",
                  refine: dict | None = None, size: ObjectSize | None = None, extra: dict | None = None,
                  description: str = "", scores: dict | None = None) -> dict:
    """Write all files of one object; image-space outputs at the output side N = prepared.side.

    Args:
        folder: RESULTS/<name>.
        item, prepared: the input and its crops (input.png is prepared.photo_image).
        state: the object (upsample.full_resolution_state; its albedo any size, 1 x 3 x Ht x 3Wt).
        setup: the model's configuration.
        version: model label for material.json.
        envs: relighting environments by name (He x We each).
        config: turntable and view settings.
        albedo_source: where the albedo came from (`network` or `divided`, see Predictor).
        pitch_source: where the pitch came from (`network` or `search`, see Predictor).
        refine: what the per-object refinement did (derender.refine.driver.RefineReport.record()), if it ran.
        size: the object's catalogued size, if known (meshes in metres at its height); one without a height
            leaves them unitless and says why in material.json.
        extra: more entries for material.json (an object with several views: derender.multiview.driver).
        description: the object's catalogue description (its harvested record's title), read by the status.
        scores: more quality scores, judged with the input view's (an object with several views: its views').

    Returns:
        The material.json record.
    """
    folder.mkdir(parents=True, exist_ok=True)
    (folder / MATERIAL_FILE).unlink(missing_ok=True)  # incomplete until rewritten at the end
    side = prepared.side
    assert prepared.photo_image is not None  # Prepared sets it
    write_picture(folder / INPUT_FILE, prepared.photo_image)
    if prepared.photo_silhouette is not None:
        write_picture(folder / SILHOUETTE_FILE, prepared.photo_silhouette.astype(np.uint8) * 255)
    if prepared.appendages is not None and prepared.appendages.any():  # written only where something was left out
        write_picture(folder / APPENDAGES_FILE, prepared.appendages.astype(np.uint8) * 255)
    write_maps(folder, state, setup.render)
    real = write_meshes(folder, state, setup.geometry.n_cols, size.height_cm if size and size.known else None)
    drawing = write_renders(folder, state, side, config.view_side(side), config.views, envs)
    record = state.record()
    record.update({
        "source": str(item.image_path),
        **prepared.crop.record(),
        "photo_size": list(prepared.photo_size),
        "backdrop": prepared.backdrop,
        "image_size": setup.render.image_size,
        "resolution": side,
        "view_size": config.view_side(side),
        "model": version,
        "albedo_source": albedo_source,
        "pitch_source": pitch_source,
        **({"refine": refine} if refine is not None else {}),
        "environments": sorted(envs),
        "quality": assess_drawn(prepared, drawing, description=description, more=scores),
        **size_record(size, real),
        **(extra or {}),
    })
    write_json(folder / MATERIAL_FILE, record)
    return record


def size_record(size: ObjectSize | None, mesh_cm: dict | None) -> dict:
    """material.json's size keys: `size_cm` (the catalogue's lengths), `size_source`, `mesh_unit` and `mesh_cm`
    (the meshes' height and widest diameter) when the meshes are in metres; `size_note` when a size was looked
    for but not usable; nothing when no size is known."""
    if size is None:
        return {}
    if mesh_cm is None:
        return {"size_source": size.source, "size_note": f"{size.status}: {size.note}".rstrip(": ")}
    record = {"size_cm": size.lengths(), "size_source": size.source, "mesh_unit": "m", "mesh_cm": mesh_cm}
    return {**record, "size_note": size.note} if size.note else record
