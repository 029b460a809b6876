"""The ground-truth files `radar synth` writes next to each sample's image.png and mask.png, named once here.

    DATA/<split>/<id>/image.png              rendered RGB (tone-mapped) over a plain background
    DATA/<split>/<id>/mask.png               silhouette (L, 255 = a ray meets the surface, inside included)
    DATA/<split>/<id>/mask_front.png         frontal third of the outer surface (the region L_im is scored on)
    DATA/<split>/<id>/albedo.png             unwrapped 360 deg albedo, Ht x 3Wt, tone-mapped (middle third = front)
    DATA/<split>/<id>/albedo_rendered.png    that albedo drawn in image space (tone-mapped, black background)
    DATA/<split>/<id>/normal_rendered.png    camera-space normals of the seen surface, (n + 1) / 2 as RGB
    DATA/<split>/<id>/depth.npy              float32 H x W camera-space z of the hit, 0 where there is none
    DATA/<split>/<id>/diffuse.npy            float16 H x W diffuse factor I_d drawn in image space (linear)
    DATA/<split>/<id>/specular.npy           float16 H x W specular factor I_s drawn in image space (before rho)
    DATA/<split>/<id>/env_map.npy            float32 He x We environment map (camera frame, linear)
    DATA/<split>/<id>/env_map.png            preview of it, normalised by its maximum and tone-mapped
    DATA/<split>/<id>/params.json            radius column, height, pose, alpha, rho, lobes, shape and texture
                                             parameters; written last: its presence marks a finished sample
    DATA/synth.json                          the settings the set was made with (a rerun must match them)
    DATA/failures.csv                        samples that could not be made (split, id, problem)

Physical conventions are the renderer's (radar_cli.render): sizes in fractions of r_max, pose = (pitch deg,
roll deg, tx, ty), environment maps as in radar_cli.render.lighting.env_directions.
"""

from __future__ import annotations

from radar_cli.dataset import IMAGE_FILE, MASK_FILE

MASK_FRONT_FILE = "mask_front.png"
ALBEDO_FILE = "albedo.png"
ALBEDO_RENDERED_FILE = "albedo_rendered.png"
NORMAL_RENDERED_FILE = "normal_rendered.png"
DEPTH_FILE = "depth.npy"
DIFFUSE_FILE = "diffuse.npy"
SPECULAR_FILE = "specular.npy"
ENV_MAP_FILE = "env_map.npy"
ENV_PREVIEW_FILE = "env_map.png"
PARAMS_FILE = "params.json"
SETTINGS_FILE = "synth.json"
FAILURES_FILE = "failures.csv"

SAMPLE_FILES = (IMAGE_FILE, MASK_FILE, MASK_FRONT_FILE, ALBEDO_FILE, ALBEDO_RENDERED_FILE, NORMAL_RENDERED_FILE,
                DEPTH_FILE, DIFFUSE_FILE, SPECULAR_FILE, ENV_MAP_FILE, ENV_PREVIEW_FILE, PARAMS_FILE)
"""Every file of a finished sample; PARAMS_FILE is written last."""

# the paper's split sizes (Sec. 4.2)
DEFAULT_SPLIT_SIZES = {"train": 4115, "test": 460}
