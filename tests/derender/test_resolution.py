"""`radar derender --resolution`: every output at the crop's side N (never more than the photo's pixels), the
smooth profile, the divided albedo at N, the same bytes twice, and the CLI's option."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
from click.testing import CliRunner
from PIL import Image
from scipy.ndimage import binary_erosion

from radar_cli.cli import cli
from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.inputs import InputItem, output_side, prepare
from radar_cli.derender.run.predictor import ASSETS, Predictor
from radar_cli.derender.run.upsample import PROFILE_ROWS, full_resolution_state
from radar_cli.errors import InputError
from radar_cli.masks import crop as crops

from .conftest import SETUP, SIZE, FakeModel, vase_photo, write_photo

SIDE = 128
IMAGE_SIDE = ("input.png", "mask.png", "mask_front.png", "recon.png", "albedo_rendered.png", "normal_rendered.png",
              "diffuse_rendered.png", "specular_rendered.png", "texture.png", "normal.png", "diffuse.png",
              "specular.png", "relit_studio.png", "material_sphere.png")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _run(root: Path, out: str, resolution, views: int = 2) -> Path:
    options = DerenderOptions(out=root / out, export=ExportConfig(views=views), resolution=resolution, workers=1)
    summary = derender([root / "in"], Predictor(FakeModel(), SETUP, "fake-model", "cpu"), options,
                       say=lambda line: None)
    assert summary.done and not summary.failures
    return root / out


@pytest.fixture(scope="module")
def big(tmp_path_factory) -> Path:
    """One 240 x 200 photo (its crop window ~190 px) de-rendered at 128 px."""
    root = tmp_path_factory.mktemp("res")
    write_photo(root / "in" / "vase.png", 4, (240, 200))
    _run(root, "out", SIDE)
    return root


def test_every_output_at_the_output_side(big: Path) -> None:
    folder = big / "out" / "vase"
    for name in IMAGE_SIDE:
        with Image.open(folder / name) as im:
            assert im.size == (SIDE, SIDE), name
    with Image.open(folder / "albedo.png") as im:
        assert im.size == (3 * SIDE, SIDE)  # 360 deg, the frontal third at the crop's side
    with Image.open(folder / "turntable.png") as im:
        assert im.size == (2 * SIDE, SIDE)  # views at max(128, N)
    mask = np.asarray(Image.open(folder / "mask.png")) == 255
    diffuse = np.asarray(Image.open(folder / "diffuse_rendered.png"))
    assert diffuse.ndim == 2 and (diffuse[~mask] == 0).all() and diffuse[mask].mean() > 20  # shading in the view
    record = json.loads((folder / "material.json").read_text())
    assert record["resolution"] == SIDE and record["view_size"] == SIDE and record["image_size"] == SIZE
    assert len(record["radius"]) == PROFILE_ROWS
    (mesh,) = trimesh.load(folder / "mesh.glb").geometry.values()
    assert mesh.visual.material.baseColorTexture.size == (3 * SIDE, SIDE)
    rings = np.unique(np.round(mesh.vertices[:, 1], 6)).size
    assert rings >= PROFILE_ROWS  # the mesh carries the smooth profile's rows


def test_same_input_same_bytes(big: Path) -> None:
    again = _run(big, "again", SIDE)

    def digests(root: Path) -> dict[str, str]:
        return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted((root / "vase").iterdir())
                if p.name != "material.json"}

    assert digests(again) == digests(big / "out")
    first, second = (json.loads((r / "vase" / "material.json").read_text()) for r in (big / "out", again))
    assert first == second


def test_never_above_the_photo_and_photo_means_its_own_size(tmp_path: Path) -> None:
    write_photo(tmp_path / "in" / "small.png", 5, (90, 90))
    item = InputItem("small", tmp_path / "in" / "small.png")
    prepared = prepare(item, SIZE, resolution=512)
    native = prepared.crop.side
    assert prepared.side == native < 512 and prepared.image.shape == (SIZE, SIZE, 3)
    assert prepared.photo_image.shape == (native, native, 3) and prepared.photo_silhouette.shape == (native, native)
    assert prepare(item, SIZE, resolution="photo").side == native
    assert prepare(item, SIZE, resolution=32).side == 32
    assert output_side("photo", 10_000) == 1024 and output_side(100, 60) == 60
    for bad in (8, 2048, "big", 1.5):
        with pytest.raises(InputError, match="resolution"):
            output_side(bad, 100)


def test_the_silhouette_at_the_output_side_matches_the_network_one(big: Path) -> None:
    """The N px silhouette and crop are the S px ones at a finer grid (the same window)."""
    prepared = prepare(InputItem("vase", big / "in" / "vase.png"), SIZE, resolution=SIDE)
    small = np.asarray(Image.fromarray(prepared.photo_silhouette.astype(np.uint8) * 255).resize(
        (SIZE, SIZE), Image.BILINEAR)) > 127
    assert (small == prepared.silhouette).mean() > 0.98
    shrunk = np.asarray(Image.fromarray(prepared.photo_image).resize((SIZE, SIZE), Image.BILINEAR), np.float64)
    assert np.abs(shrunk - prepared.image).mean() < 6  # grey levels


def _striped_photo(path: Path) -> Path:
    """A 240 x 200 photo of an ellipse painted with 6 x 8 px checks: detail a 64 px crop cannot hold."""
    image = vase_photo(4, (240, 200))
    yy, xx = np.mgrid[0:240, 0:200]
    checks = (image[..., 0] < 200) & ((xx // 6 + yy // 8) % 2 == 0)
    image[checks] = (image[checks] * 0.6).astype(np.uint8)
    Image.fromarray(image).save(path)
    return path


def test_divided_albedo_at_the_output_side_draws_the_crop_back(tmp_path: Path) -> None:
    """The divided albedo re-shaded and drawn at N gives the N px crop back where the surface lies on the object
    (median 2 grey levels measured); f_A's albedo upsampled cannot (14)."""
    from radar_cli.derender.export.renders import ViewRenderer

    predictor = Predictor(FakeModel(), SETUP, "fake-model", "cpu")
    prepared = prepare(InputItem("v", _striped_photo(tmp_path / "v.png")), SIZE, resolution=SIDE)
    dec = predictor.predict([prepared.image], [prepared.silhouette])
    divided = full_resolution_state(dec, prepared, SETUP, "divided")
    network = full_resolution_state(dec, prepared, SETUP, "network")
    assert divided.material.albedo.shape == network.material.albedo.shape == (1, 3, SIDE, 3 * SIDE)
    assert divided.solid.radius.shape == (1, PROFILE_ROWS)

    def median_error(state) -> float:
        view = ViewRenderer(state, SIDE)
        drawn = view.draw(view.shading()).astype(np.float64)
        on_both = binary_erosion((view.hits.mask & ~view.hits.inner)[0].numpy() & prepared.photo_silhouette,
                                 iterations=3)
        return float(np.median(np.abs(drawn - prepared.photo_image)[on_both]))

    assert median_error(divided) <= 4 and median_error(network) > 3 * median_error(divided)


def test_cli_resolution_option(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["derender", str(tmp_path), "--out", str(tmp_path / "o"), "--resolution", "8"])
    assert result.exit_code == 2 and "8 is not in [16, 1024]" in result.output
    result = CliRunner().invoke(cli, ["derender", str(tmp_path), "--out", str(tmp_path / "o"), "--resolution", "x"])
    assert result.exit_code == 2 and "'photo'" in result.output


@pytest.mark.skipif(not any(ASSETS.glob("*.safetensors")) or not EXAMPLES.is_dir(), reason="no model/examples")
def test_cli_photo_resolution_with_the_bundled_model(tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "synthetic_vase_0.png", tmp_path / "v.png")  # 256 px, used whole (--crop none)
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "v.png"), "--out", str(tmp_path / "o"), "--views",
                                      "1", "--crop", "none", "--resolution", "photo"])
    assert result.exit_code == 0, result.output
    with Image.open(tmp_path / "o" / "v" / "recon.png") as im:
        assert im.size == (256, 256)
    assert json.loads((tmp_path / "o" / "v" / "material.json").read_text())["resolution"] == 256


def test_large_exports_encode_fast_and_keep_their_pixels(tmp_path: Path) -> None:
    from radar_cli.derender.export.maps import FAST_ENCODE_PIXELS, write_picture
    from radar_cli.derender.export.renders import gif_frames

    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (512, 512, 3), dtype=np.uint8)
    assert image.shape[0] * image.shape[1] >= FAST_ENCODE_PIXELS
    write_picture(tmp_path / "big.png", image)
    np.testing.assert_array_equal(np.asarray(Image.open(tmp_path / "big.png")), image)  # lossless
    ramp = np.broadcast_to(np.linspace(0, 255, 512, dtype=np.uint8)[None, :, None], (512, 512, 3))
    views = [np.ascontiguousarray(np.roll(ramp, 64 * k, axis=1)) for k in range(3)]
    frames = gif_frames(views)
    assert all(f.mode == "P" and f.getpalette() == frames[0].getpalette() for f in frames)  # one shared palette
    for frame, view in zip(frames, views):
        assert np.abs(np.asarray(frame.convert("RGB"), np.float64) - view).mean() < 0.5  # grey levels
    assert all(f.mode == "RGB" for f in gif_frames([v[:256, :256] for v in views]))  # small: Pillow's own


def test_known_mask_is_cut_at_both_sides(tmp_path: Path) -> None:
    photo = write_photo(tmp_path / "in" / "m.png", 6, (200, 160))
    dark = np.asarray(Image.open(photo)).max(axis=-1) < 200
    Image.fromarray((dark * 255).astype(np.uint8)).save(tmp_path / "m_mask.png")
    item = InputItem("m", photo, tmp_path / "m_mask.png")
    prepared = prepare(item, SIZE, resolution=96)
    assert prepared.side == 96 and prepared.silhouette.shape == (SIZE, SIZE) and prepared.backdrop == "white"
    assert prepared.photo_silhouette.shape == (96, 96)
    assert prepared.photo_silhouette.mean() == pytest.approx(prepared.silhouette.mean(), abs=0.02)
    assert (prepared.photo_image[~prepared.photo_silhouette] > 230).all()  # the backdrop whitened at N too


def test_divided_albedo_keeps_the_photo_beyond_the_frontal_third() -> None:
    """A vase rendered with a stripe painted 50-58 deg from the view, de-rendered at its own shape, pose and
    light: the map shows the stripe there and plain paint at 63-67 deg, as the photo does (mirroring the frontal
    third about 60 deg put a second stripe there: a painted face drawn twice on real photographs)."""
    import torch

    from radar_cli.derender.run.inputs import Prepared
    from radar_cli.model.outputs import Decomposition
    from radar_cli.render.material import Material
    from radar_cli.render.scene import render_synthetic
    from radar_cli.sor.solid import Solid

    side, render = 3 * SIDE // 2, SETUP.render
    phi = (np.arange(3 * side) + 0.5) / (3 * side) * 360 - 180  # each column's angle from the view
    albedo = torch.full((1, 3, side, 3 * side), 0.8)
    albedo[:, 1:, :, torch.from_numpy((phi > 50) & (phi < 58))] = 0.1  # red
    y = torch.linspace(1, -1, 16)
    solid = Solid((0.6 + 0.15 * torch.cos(2 * y))[None], torch.tensor([0.8]), torch.tensor([[8.0, 0.0, 0.0, 0.0]]))
    env = torch.full((1, render.env_height, render.env_width), 0.3)
    material = Material(albedo, env, torch.tensor([20.0]), torch.tensor([0.0]))
    image, hits, _ = render_synthetic(solid, material, side, render, SETUP.camera, 1.0)
    photo = (image[0].permute(1, 2, 0).numpy() * 255 + 0.5).astype(np.uint8)
    mask = hits.mask[0].numpy()
    small = np.asarray(Image.fromarray(photo).resize((SIZE, SIZE), Image.BILINEAR))
    prepared = Prepared(small, crops.CropBox(0, 0, side), (side, side),
                        silhouette=np.asarray(Image.fromarray(mask).resize((SIZE, SIZE))), photo_image=photo,
                        photo_silhouette=mask)
    dec = Decomposition(solid.radius, solid.height, solid.pose, torch.full((1, 3, 32, 32), 0.8), env,
                        material.alpha, material.rho)
    got = full_resolution_state(dec, prepared, SETUP, "divided").material.albedo[0, :, side // 4 : 3 * side // 4]
    redness = (got[0] - got[1:].mean(0)).mean(0).numpy()  # per column
    assert redness[(phi > 51) & (phi < 57)].min() > 0.4  # the stripe, as painted
    assert np.abs(redness[(phi > 63) & (phi < 67)]).max() < 0.1  # plain, as painted (no mirrored stripe)
