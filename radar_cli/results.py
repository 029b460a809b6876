"""The one on-disk layout of de-rendering results: written by `radar derender`, read by `radar eval` and
`radar relight`.

    RESULTS/<object id>/input.png             the network's input crop (RGB)
    RESULTS/<object id>/mask.png              predicted silhouette (L, 255 = object)
    RESULTS/<object id>/silhouette.png        located or given silhouette, when known (L, 255 = object)
    RESULTS/<object id>/mask_front.png        rendered frontal-third silhouette (the region L_im is scored on)
    RESULTS/<object id>/albedo_rendered.png   diffuse albedo drawn in image space (tone-mapped, sRGB-like)
    RESULTS/<object id>/normal_rendered.png   camera-space normals in image space, (n + 1) / 2 as RGB
    RESULTS/<object id>/material.json         pitch, roll, tx, ty, height, radius, alpha, rho, crop box, model
    RESULTS/<object id>/env_map.npy           float32 He x We environment map (camera frame, linear)
    RESULTS/<object id>/...                   exports (meshes, maps, renders), see radar_cli.derender
    RESULTS/index.html, summary.csv, failures.csv
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

INPUT_FILE = "input.png"
MASK_FILE = "mask.png"
SILHOUETTE_FILE = "silhouette.png"  # the located or given silhouette the object was fitted to (L, 255 = object)
MASK_FRONT_FILE = "mask_front.png"
ALBEDO_RENDERED_FILE = "albedo_rendered.png"
NORMAL_RENDERED_FILE = "normal_rendered.png"
MATERIAL_FILE = "material.json"
ENV_MAP_FILE = "env_map.npy"
INDEX_FILE = "index.html"
SUMMARY_FILE = "summary.csv"
FAILURES_FILE = "failures.csv"

# exports written by radar_cli.derender (not needed by `radar eval`)
RECON_FILE = "recon.png"
APPENDAGES_FILE = "appendages.png"  # the located object's pixels left out of the solid (L, 255 = appendage)
ALBEDO_FILE = "albedo.png"  # 360 deg unwrapped albedo, tone-mapped; the meshes' texture; relight reads it
TEXTURE_FILE = "texture.png"
NORMAL_FILE = "normal.png"
DIFFUSE_FILE = "diffuse.png"
SPECULAR_FILE = "specular.png"
DIFFUSE_RENDERED_FILE = "diffuse_rendered.png"  # the diffuse shading drawn in the input view
SPECULAR_RENDERED_FILE = "specular_rendered.png"  # rho x the specular shading drawn in the input view
ENV_HDR_FILE = "env_map.hdr"
ENV_PREVIEW_FILE = "env_map.png"
MESH_GLB_FILE = "mesh.glb"
MESH_OBJ_FILE = "mesh.obj"
MATERIAL_SPHERE_FILE = "material_sphere.png"
TURNTABLE_GIF_FILE = "turntable.gif"
TURNTABLE_STRIP_FILE = "turntable.png"
COVERAGE_FILE = "coverage.png"  # objects with several views: which view gave each texel of albedo.png (black: none)
VIEWS_DIR = "views"  # objects with several views: views/<photo>.png, its crop beside the object drawn as it sees it
RELIT_PREFIX = "relit_"  # relit_<environment>.png

# material.json keys that `radar eval` reads (others may be present)
MATERIAL_KEYS = ("pitch", "roll", "tx", "ty", "height", "radius", "alpha", "rho")


@dataclass(frozen=True)
class ResultPaths:
    """Where the files of one de-rendered object live."""

    folder: Path

    @property
    def input(self) -> Path:
        return self.folder / INPUT_FILE

    @property
    def mask(self) -> Path:
        return self.folder / MASK_FILE

    @property
    def mask_front(self) -> Path:
        return self.folder / MASK_FRONT_FILE

    @property
    def albedo_rendered(self) -> Path:
        return self.folder / ALBEDO_RENDERED_FILE

    @property
    def normal_rendered(self) -> Path:
        return self.folder / NORMAL_RENDERED_FILE

    @property
    def material(self) -> Path:
        return self.folder / MATERIAL_FILE

    @property
    def env_map(self) -> Path:
        return self.folder / ENV_MAP_FILE

    def is_complete(self) -> bool:
        """True if every file `radar eval` needs is present."""
        return all(p.is_file() for p in (self.mask_front, self.albedo_rendered, self.normal_rendered,
                                         self.material, self.env_map))


def list_results(root: str | Path) -> list[ResultPaths]:
    """Every object folder under a results root (sorted by name); completeness is not checked."""
    root = Path(root)
    return [ResultPaths(d) for d in sorted(root.iterdir()) if d.is_dir() and not d.name.startswith(".")]
