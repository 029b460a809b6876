"""Everything written for one de-rendered object, in order, with material.json last: its presence marks the
folder complete, so a killed run redoes half-written folders and skips finished ones."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from radar_cli.derender.inputs import InputItem, Prepared
from radar_cli.derender.maps import write_maps
from radar_cli.derender.mesh import write_meshes
from radar_cli.derender.predictor import AlbedoSource, ModelSetup, PitchSource
from radar_cli.derender.quality import assess
from radar_cli.derender.renders import write_renders
from radar_cli.derender.state import ObjectState
from radar_cli.fileio import write_image, write_json
from radar_cli.model.outputs import Decomposition
from radar_cli.results import APPENDAGES_FILE, INPUT_FILE, MATERIAL_FILE


@dataclass(frozen=True)
class ExportConfig:
    """What is rendered per object besides the maps and meshes."""

    views: int = 8
    """Turntable frames (0 = no turntable)."""
    view_size: int = 128
    """Side in pixels of the turntable frames, relit views and the material sphere."""


def is_complete(folder: Path) -> bool:
    """True if `folder` holds a finished export (material.json is written last)."""
    return (folder / MATERIAL_FILE).is_file()


def export_object(folder: Path, item: InputItem, prepared: Prepared, dec: Decomposition, setup: ModelSetup,
                  version: str, envs: dict[str, np.ndarray], config: ExportConfig = ExportConfig(),
                  albedo_source: AlbedoSource = "network", pitch_source: PitchSource = "network") -> dict:
    """Write all files of one object.

    Args:
        folder: RESULTS/<name>.
        item, prepared: the input and its crop.
        dec: the object's Decomposition (batch of one, CPU).
        setup: the model's configuration.
        version: model label for material.json.
        envs: relighting environments by name (He x We each).
        config: turntable and view settings.
        albedo_source: where the albedo came from (`network` or `divided`, see Predictor).
        pitch_source: where the pitch came from (`network` or `search`, see Predictor).

    Returns:
        The material.json record.
    """
    folder.mkdir(parents=True, exist_ok=True)
    (folder / MATERIAL_FILE).unlink(missing_ok=True)  # incomplete until rewritten at the end
    state = ObjectState.from_decomposition(dec, setup.render, setup.camera)
    write_image(folder / INPUT_FILE, prepared.image)
    if prepared.appendages is not None:
        write_image(folder / APPENDAGES_FILE, prepared.appendages.astype(np.uint8) * 255)
    write_maps(folder, state, setup.render)
    write_meshes(folder, state, setup.geometry.n_cols)
    write_renders(folder, state, setup.image_size, config.view_size, config.views, envs)
    record = state.material()
    record.update({
        "source": str(item.image_path),
        "crop_box": prepared.crop.to_list(),
        "photo_size": list(prepared.photo_size),
        "backdrop": prepared.backdrop,
        "image_size": setup.image_size,
        "model": version,
        "albedo_source": albedo_source,
        "pitch_source": pitch_source,
        "environments": sorted(envs),
        "quality": assess(prepared, state),
    })
    write_json(folder / MATERIAL_FILE, record)
    return record
