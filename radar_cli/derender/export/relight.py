"""`radar relight`: re-render a de-rendered object folder under a new environment map from a new view, without
the network (shape, pose, material from material.json, albedo from albedo.png, lighting from the file given)."""

from __future__ import annotations

from pathlib import Path

import torch

from radar_cli.derender.export.environments import match_exposure, named_or_file_environment
from radar_cli.derender.export.renders import render_object
from radar_cli.derender.run.state import read_record, read_state
from radar_cli.errors import InputError
from radar_cli.fileio import write_image

MAX_SIZE = 4096
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".webp")


def check_output(out: Path) -> None:
    """Refuse an output that is not an image file name, or whose folder does not exist (it is never created)."""
    if out.suffix.lower() not in IMAGE_SUFFIXES:
        raise InputError(f"{out}: not an image file name (use {', '.join(IMAGE_SUFFIXES)})")
    if not out.parent.is_dir():
        raise InputError(f"{out.parent}: no such folder for --out (create it first)")


def relight(folder: str | Path, env: str | Path, out: str | Path, yaw_deg: float = 0.0,
            pitch_deg: float | None = None, size: int | None = None, match: bool = True) -> Path:
    """Render one object under another environment map.

    Args:
        folder: RESULTS/<object> written by `radar derender`.
        env: a built-in environment's name (studio, sunset, overcast, two_lights) or an .hdr, .exr, .png/.jpg or
            .npy environment map (camera frame, see radar_cli.derender.export.environments).
        out: the image to write (.png, .jpg, .jpeg, .webp) in an existing folder.
        yaw_deg: spin about the object's axis.
        pitch_deg: camera elevation in degrees (default: the predicted pitch).
        size: image side in pixels (default: the output side recorded in material.json, else the network's).
        match: scale the map to the exposure of the object's own lighting (False: use its radiance as is).

    Returns:
        The path written.
    """
    check_output(Path(out))
    state = read_state(folder)
    record = read_record(folder)
    size = size or int(record.get("resolution", record.get("image_size", 256)))
    if not 8 <= size <= MAX_SIZE:
        raise InputError(f"--size must lie in [8, {MAX_SIZE}], got {size}")
    env_map = named_or_file_environment(env, state.material.env.shape[1], state.material.env.shape[2])
    if match:
        env_map = match_exposure(env_map, state.material.env[0].numpy())
    image = render_object(state, size, yaw_deg, pitch_deg, env=torch.from_numpy(env_map)[None])
    write_image(out, image)
    return Path(out)

