"""Textured meshes of one object: mesh.glb (PBR material: 360 deg albedo, roughness from the shininess) and
mesh.obj + .mtl + texture, via trimesh: axis = +y, the photographed side facing +z (the glTF/OBJ viewers' default
front), i.e. the canonical object frame turned 180 deg about the axis. In the model's units, or in metres (glTF's
unit) with the object's catalogued height when its size is known."""

from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np
import trimesh
from PIL import Image

from radar_cli.derender.export.maps import chw_image
from radar_cli.derender.run.state import ObjectState, roughness_from_shininess
from radar_cli.fileio import write_bytes
from radar_cli.render.lighting import tone_map
from radar_cli.results import ALBEDO_FILE, MESH_GLB_FILE, MESH_OBJ_FILE
from radar_cli.sor.mesh import triangulate

# canonical frame (seen side at -z) -> export frame (seen side at +z): a proper rotation, so winding is kept
TO_VIEWER_FRONT = np.array([-1.0, 1.0, -1.0])
MAX_SPECULAR_FACTOR = 1.0  # MTL Ks lies in [0, 1]; rho (0..2) is halved and clipped for it
OBJ_MTL = "mesh.mtl"
OBJ_HEADER = "https://github.com/mikedh/trimesh"  # the meshes' geometry and materials are trimesh's
TEXTURE_PNG = {"compress_level": 1}
"""How trimesh's PNG of the texture in mesh.glb is encoded (and beside mesh.obj, the same bytes taken from the
GLB): zlib level 1 took 0.04 CPU s for a 1,536 x 512 albedo where Pillow's default took 0.17 s; the pixels are the
same."""


def build_mesh(state: ObjectState, n_cols: int) -> trimesh.Trimesh:
    """A trimesh of the SoR with uv texture coordinates and the albedo as texture.

    Args:
        state: the object.
        n_cols: K, angles around the axis.
    """
    sor = triangulate(state.solid.radius, state.solid.height, n_cols, closed_bottom=True, camera=state.camera)
    texture = Image.fromarray(chw_image(tone_map(state.material.albedo, state.render.gamma)))
    texture.encoderinfo = dict(TEXTURE_PNG)  # Pillow's save() takes its options from here (trimesh passes none)
    material = trimesh.visual.material.PBRMaterial(
        name="albedo", baseColorTexture=texture, metallicFactor=0.0,
        roughnessFactor=roughness_from_shininess(float(state.material.alpha[0])), doubleSided=True)
    visual = trimesh.visual.TextureVisuals(uv=sor.uv.numpy(), material=material)
    vertices = sor.vertices.numpy().astype(np.float64) * TO_VIEWER_FRONT
    return trimesh.Trimesh(vertices, sor.faces.numpy(), visual=visual, process=False)


def to_real_size(mesh: trimesh.Trimesh, height_cm: float) -> dict[str, float]:
    """Scale a mesh (axis +y) about its origin so that its height is `height_cm`, in metres.

    Returns:
        The scaled mesh's `height` and widest `max_diameter` about the axis, in cm.
    """
    mesh.apply_scale(height_cm / 100.0 / float(np.ptp(mesh.vertices[:, 1])))
    radial = float(np.hypot(mesh.vertices[:, 0], mesh.vertices[:, 2]).max())
    return {"height": round(float(np.ptp(mesh.vertices[:, 1])) * 100.0, 3), "max_diameter": round(200.0 * radial, 3)}


def write_meshes(folder: Path, state: ObjectState, n_cols: int, height_cm: float | None = None) -> dict | None:
    """mesh.glb, and mesh.obj with its material.mtl and texture PNG (ALBEDO_FILE, the object's albedo map),
    written atomically; in metres when the object's `height_cm` is given.

    Returns:
        The meshes' height and widest diameter in cm (to_real_size), or None when unitless.
    """
    mesh = build_mesh(state, n_cols)
    real = to_real_size(mesh, height_cm) if height_cm is not None else None
    glb = mesh.export(file_type="glb")
    assert isinstance(glb, bytes)  # a binary format
    write_bytes(folder / MESH_GLB_FILE, glb)
    # OBJ/MTL is Phong: white Kd so viewers show the texture as is, Ns = shininess, Ks from the specular albedo
    spec = int(round(255 * min(float(state.material.rho[0]) / 2.0, MAX_SPECULAR_FACTOR)))
    phong = trimesh.visual.material.SimpleMaterial(
        name="albedo", diffuse=(255, 255, 255, 255), ambient=(255, 255, 255, 255),
        specular=(spec, spec, spec, 255), glossiness=float(state.material.alpha[0]))
    files, name = phong.to_obj(name=Path(ALBEDO_FILE).stem)  # the Phong material, its texture named below
    mtl = files.pop(f"{name}.mtl") + f"\nmap_Kd {ALBEDO_FILE}".encode()
    write_bytes(folder / OBJ_MTL, f"# {OBJ_HEADER}\n\n".encode() + mtl)
    write_bytes(folder / ALBEDO_FILE, glb_texture(glb))  # the PNG trimesh encoded for the GLB, not encoded again
    write_bytes(folder / MESH_OBJ_FILE, obj_text(mesh.vertices, mesh.visual.uv, mesh.faces, name))  # type: ignore[union-attr]
    return real


def glb_texture(glb: bytes) -> bytes:
    """The PNG of a GLB's first image (its buffer view, less the zeros that pad it to four bytes), as the glTF
    2.0 binary layout has it: a 12-byte header, then chunks of (length, type, data), JSON first, then BIN."""
    chunks, offset = {}, 12
    while offset + 8 <= len(glb):
        length, kind = struct.unpack_from("<I4s", glb, offset)
        chunks[kind] = glb[offset + 8 : offset + 8 + length]
        offset += 8 + length
    gltf = json.loads(chunks[b"JSON"])
    view = gltf["bufferViews"][gltf["images"][0]["bufferView"]]
    start = view.get("byteOffset", 0)
    data = chunks[b"BIN\x00"][start : start + view["byteLength"]]
    end = data.rfind(b"IEND")  # a PNG ends with its IEND chunk: the type, then a 4-byte CRC
    if not data.startswith(b"\x89PNG") or end < 0:
        raise OSError("the GLB's texture is not a PNG")
    return data[: end + 8]


def _lines(line: str, values: np.ndarray) -> str:
    """One `line` (%-style, one field per column) per row of an M x C array, joined by newlines."""
    return "\n".join([line] * len(values)) % tuple(values.ravel().tolist())


def obj_text(vertices: np.ndarray, uv: np.ndarray, faces: np.ndarray, material: str) -> bytes:
    """mesh.obj's text: V x 3 positions, V x 2 texture coordinates and F x 3 vertex indices (0-based), each
    vertex's uv under its own index, the material `material` from OBJ_MTL. The lines trimesh's OBJ exporter
    writes (8 decimals), formatted from Python floats at a fraction of its cost (docs/performance.md)."""
    corners = np.repeat(faces.astype(np.int64) + 1, 2, axis=1)  # F x 6: v/vt pairs
    parts = [f"# {OBJ_HEADER}", f"mtllib {OBJ_MTL}", f"usemtl {material}", _lines("v %.8f %.8f %.8f", vertices),
             _lines("vt %.8f %.8f", uv), _lines("f %d/%d %d/%d %d/%d", corners), "\n"]
    return "\n".join(parts).encode("utf-8")
