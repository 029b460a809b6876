"""Turn synthetic ground truth into a results folder (radar_cli.results layout), exactly or with known
perturbations, so that `radar eval` can be checked before any model exists: the truth scores 0 everywhere."""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from radar_cli.evaluate.loading import read_env
from radar_cli.fileio import read_image, read_json, write_image, write_json, write_npy
from radar_cli.results import ResultPaths
from radar_cli.synth import layout


@dataclass(frozen=True)
class Perturbation:
    """Changes applied to the truth; the defaults reproduce it exactly.

    albedo_gain and env_gain change only the scale, which the scale-invariant metrics ignore (up to rounding
    and clipping of the 8-bit albedo)."""

    pitch_offset: float = 0.0
    alpha_offset: float = 0.0
    rho_offset: float = 0.0
    albedo_gain: float = 1.0
    env_gain: float = 1.0


def result_from_truth(gt_folder: Path, out_folder: Path, perturb: Perturbation = Perturbation()) -> ResultPaths:
    """Write one result folder from one synthetic sample folder."""
    paths = ResultPaths(Path(out_folder))
    paths.folder.mkdir(parents=True, exist_ok=True)
    params = read_json(gt_folder / layout.PARAMS_FILE)
    shutil.copyfile(gt_folder / layout.MASK_FRONT_FILE, paths.mask_front)
    shutil.copyfile(gt_folder / layout.NORMAL_RENDERED_FILE, paths.normal_rendered)
    if perturb.albedo_gain == 1.0:
        shutil.copyfile(gt_folder / layout.ALBEDO_RENDERED_FILE, paths.albedo_rendered)
    else:
        albedo = read_image(gt_folder / layout.ALBEDO_RENDERED_FILE).astype(np.float64) / 255.0
        write_image(paths.albedo_rendered, albedo * perturb.albedo_gain)
    write_npy(paths.env_map, (read_env(gt_folder / layout.ENV_MAP_FILE) * perturb.env_gain).astype(np.float32))
    pitch, roll, tx, ty = params["pose"]
    write_json(paths.material, {
        "pitch": pitch + perturb.pitch_offset, "roll": roll, "tx": tx, "ty": ty, "height": params["height"],
        "radius": params["radius"], "alpha": params["alpha"] + perturb.alpha_offset,
        "rho": params["rho"] + perturb.rho_offset, "model": "ground truth",
    })
    return paths


def results_from_synth(gt_root: Path, out_root: Path, split: str = "test",
                       perturb: Perturbation = Perturbation()) -> list[ResultPaths]:
    """Result folders for every finished sample of a split of a synthetic set."""
    folders = sorted(d for d in (Path(gt_root) / split).iterdir() if (d / layout.PARAMS_FILE).is_file())
    return [result_from_truth(d, Path(out_root) / d.name, perturb) for d in folders]
