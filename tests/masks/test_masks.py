"""Tests of the masks pipeline: detection + GrabCut accuracy on composites, crops, SoR score, batch driver."""

from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from radar_cli.cli import cli
from radar_cli.errors import InputError
from radar_cli.masks import crop as crops
from radar_cli.masks.pipeline import Settings, process_image
from radar_cli.masks.prepare import prepare, split_for
from radar_cli.masks.quality import Thresholds, score_mask, sor_score
from radar_cli.masks.refine import iou
from radar_cli.masks.synthetic import NON_SOR, composite, non_sor_mask, render_vases, sor_mask


@pytest.fixture(scope="module")
def vases():
    return render_vases(3, 128, seed=3)

def _crop_iou(photo: np.ndarray, truth: np.ndarray) -> float:
    found = process_image(photo, Settings())
    assert found, "nothing detected"
    best = max(found, key=lambda c: int(c.mask.sum()))
    return crops.reference_iou(best.mask, truth, best.box)

@pytest.mark.parametrize("kind,floor", [("plain", 0.95), ("gradient", 0.95), ("textured", 0.85),
                                        ("label", 0.93)])
def test_composite_iou(vases, kind, floor):
    image, alpha, mask = vases
    rng = np.random.default_rng(5)
    scores = [_crop_iou(*composite(image[i], alpha[i], mask[i], kind, rng)) for i in range(3)]
    assert np.mean(scores) >= floor, scores

def test_crop_geometry_object_fills_085():
    mask = np.zeros((400, 300), bool)
    mask[100:300, 120:180] = True  # 200 tall, 60 wide
    box = crops.square_box(crops.mask_box(mask))
    assert box.side == round(200 / 0.85)
    out = crops.cut(mask.astype(np.float32), box, 128) > 0.5
    warped = crops.warp_mask(mask, crops.crop_affine(box, 128), 128)
    assert iou(out, warped) > 0.97
    ys = np.nonzero(out.any(1))[0]
    assert abs((ys.max() - ys.min() + 1) / 128 - 0.85) < 0.02

def test_reference_iou_counts_what_the_crop_leaves_out():
    reference = np.zeros((400, 400), bool)
    reference[100:300, 150:250] = True
    whole = crops.square_box(crops.mask_box(reference))
    found = crops.cut(reference.astype(np.float32), whole, 128) > 0.5
    assert crops.reference_iou(found, reference, whole) == pytest.approx(1.0)
    lower = crops.CropBox(100, 200, 200)  # a crop round the lower half, the object's lower half located in it
    found = crops.cut(reference.astype(np.float32), lower, 128) > 0.5
    assert iou(found, crops.cut(reference.astype(np.float32), lower, 128, fill=0) > 0.5) == pytest.approx(1.0)
    assert crops.reference_iou(found, reference, lower) == pytest.approx(0.5, abs=0.01)


def test_a_turned_crop_of_the_photo_is_the_crop_of_the_turned_photo():
    rng = np.random.default_rng(0)
    photo = cv2.GaussianBlur(rng.uniform(0, 255, (300, 240)).astype(np.float32), (0, 0), 4)
    mask = np.zeros((300, 240), bool)
    cv2.ellipse(mask.view(np.uint8), (110, 160), (50, 100), 20, 0, 360, 1, -1)
    turned, affine = crops.turned_photo(photo, -20.0)
    turned_mask = crops.turned_photo(mask.astype(np.float32), -20.0)[0] > 0.5
    on_canvas = crops.square_box(crops.mask_box(turned_mask))
    box = crops.box_in_photo(on_canvas, affine, -20.0)
    assert box.turn == -20.0 and box.side == on_canvas.side
    direct, via_canvas = crops.cut(photo, box, 96), crops.cut(turned, on_canvas, 96)
    assert np.abs(direct - via_canvas)[8:-8, 8:-8].mean() < 1.0  # the same window, a half pixel of rounding apart
    found = crops.cut(turned_mask.astype(np.float32), on_canvas, 96) > 0.5
    assert crops.reference_iou(found, mask, box) > 0.97  # placed back on the photo as it was
    assert crops.reference_iou(found, mask, crops.CropBox(box.x0, box.y0, box.side)) < 0.8
    outside = crops.outside_mask(box, photo.shape, 96)
    assert not outside[40:56, 40:56].any()
    assert iou(crops.warp_mask(mask, crops.crop_affine(box, 96), 96), found) > 0.97  # the photo -> crop map


def test_crop_pads_outside_the_photo():
    img = np.full((50, 50, 3), 7, np.uint8)
    out = crops.cut(img, crops.CropBox(-20, -20, 100), 64)
    assert out.shape == (64, 64, 3) and (out == 7).all()
    assert crops.valid_region(crops.CropBox(-20, -20, 100), img.shape, 100) == (20, 20, 70, 70)

def test_symmetry_separates_sor_from_other_shapes():
    rng = np.random.default_rng(11)
    limit = Thresholds().min_symmetry
    sor = [sor_score(sor_mask(128, rng)) >= limit for _ in range(25)]
    other = [sor_score(non_sor_mask(NON_SOR[i % len(NON_SOR)], 128, rng)) < limit for i in range(25)]
    assert np.mean(sor + other) >= 0.9

def test_rendered_vase_scores(vases):
    for m in vases[2]:
        s = score_mask(m)
        assert s["symmetry"] >= Thresholds().min_symmetry and s["solidity"] > 0.6 and not s["touches_border"]

def test_split_is_deterministic_and_roughly_78_percent():
    splits = [split_for(f"met_{i}") for i in range(2000)]
    assert splits == [split_for(f"met_{i}") for i in range(2000)]
    assert 0.74 < splits.count("train") / 2000 < 0.82

def _png_claiming(width: int, height: int) -> bytes:
    """A PNG header announcing a huge image, with no pixel data (decompression-bomb probe)."""
    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))

def _studio(rng: np.random.Generator, size=(240, 200)) -> np.ndarray:
    h, w = size
    img = np.full((h, w, 3), 200, np.uint8)
    m = cv2.resize(sor_mask(128, rng).astype(np.uint8), (int(h * 0.7), int(h * 0.7))) > 0
    top, left = int(h * 0.15), (w - m.shape[1]) // 2
    img[top : top + m.shape[0], left : left + m.shape[1]][m] = (120, 60, 30)
    return img

def _bad_folder(folder: Path) -> None:
    rng = np.random.default_rng(0)
    good = _studio(rng)
    Image.fromarray(good).save(folder / "good.jpg")
    Image.fromarray(good).convert("L").save(folder / "grey.png")
    Image.fromarray(good).convert("RGBA").save(folder / "rgba.png")
    Image.fromarray(good).convert("CMYK").save(folder / "cmyk.jpg")
    Image.fromarray((good[..., 0].astype(np.uint16) * 257)).save(folder / "sixteen.png")
    (folder / "corrupt.jpg").write_bytes(b"not an image at all")
    data = (folder / "good.jpg").read_bytes()
    (folder / "truncated.jpg").write_bytes(data[: len(data) // 3])
    Image.fromarray(good[:20, :20]).save(folder / "tiny.png")
    Image.fromarray(np.full((100, 100, 3), 128, np.uint8)).save(folder / "flat.png")
    (folder / "huge.png").write_bytes(_png_claiming(30000, 30000))

def test_bad_inputs_are_recorded_and_the_batch_goes_on(tmp_path):
    src = tmp_path / "photos"
    src.mkdir()
    _bad_folder(src)
    result = CliRunner().invoke(cli, ["masks", str(src), "--out", str(tmp_path / "out")])
    assert result.exit_code == 1, result.output
    records = {p.stem: json.loads(p.read_text()) for p in (tmp_path / "out" / ".records").glob("*.json")}
    assert len(records) == 10
    for key in ("good", "grey", "rgba", "cmyk", "sixteen"):
        assert records[key]["status"] == "done" and records[key]["crops"], key
    for key in ("corrupt", "tiny", "flat", "huge"):
        assert records[key]["status"] == "failed" and f"{key}." in records[key]["reason"], records[key]
    assert records["truncated"]["status"] in ("failed", "done")
    failures = (tmp_path / "out" / "failures.csv").read_text()
    assert "corrupt.jpg" in failures and "huge.png" in failures and "too small" in failures
    samples = list((tmp_path / "out").glob("*/*/image.png"))
    assert samples and all((p.parent / "mask.png").is_file() and (p.parent / "meta.json").is_file()
                           for p in samples)
    assert (tmp_path / "out" / "contact_sheet-001.png").is_file()

def test_resume_skips_finished_photos(tmp_path):
    src = tmp_path / "photos"
    src.mkdir()
    rng = np.random.default_rng(1)
    for i in range(3):
        Image.fromarray(_studio(rng)).save(src / f"vase{i}.png")
    first = prepare(src, tmp_path / "out", progress=False, contact_sheet=False)
    assert first.photos == 3 and sum(first.accepted.values()) + first.rejected == 3, first
    meta = json.loads(next((tmp_path / "out").glob("*/vase0/meta.json")).read_text())
    assert meta["source"].endswith("vase0.png") and len(meta["crop_box"]) == 3 and "symmetry" in meta["scores"]
    Image.fromarray(_studio(rng)).save(src / "vase3.png")
    second = prepare(src, tmp_path / "out", progress=False, contact_sheet=False, workers=2)
    assert second.skipped_done == 3 and second.photos == 4

def test_onnx_detector_reports_missing_runtime_or_bad_model(tmp_path):
    from radar_cli.masks.onnx import OnnxDetector

    bad = tmp_path / "m.onnx"
    bad.write_bytes(b"junk")
    with pytest.raises(InputError):
        OnnxDetector(bad)

def test_real_photos_give_one_plausible_crop_each(shared_data):
    from radar_cli.masks.pipeline import process_photo

    real = shared_data("data", "real_vases")
    for name in ("met_gr_DP117199.jpg", "met_gr_DP107639.jpg"):
        found = process_photo(real / name, Settings())
        assert len(found) == 1
        s = found[0].scores
        assert 0.2 < s["area"] < 0.6 and s["symmetry"] > 0.8, s

def test_bench_masks_smoke():
    from radar_cli.masks.benchmark import bench_masks

    result = bench_masks(n_photos=2, long_side=1600, workers=1)
    assert result["photos"] == 2 and result["photos_per_second"] > 0 and result["cpu_seconds_per_photo"] > 0

def test_big_jpeg_is_draft_decoded_and_box_is_in_original_pixels(tmp_path):
    from radar_cli.masks.pipeline import load_photo, process_photo

    img = np.full((2400, 3200, 3), 190, np.uint8)
    img[600:1800, 1400:1800] = (40, 60, 120)  # a 1200 x 400 px upright block
    Image.fromarray(img).save(tmp_path / "big.jpg", quality=92)
    decoded, scale = load_photo(tmp_path / "big.jpg", min_long_side=768)
    assert scale == 0.25 and decoded.shape == (600, 800, 3)
    (found,) = process_photo(tmp_path / "big.jpg", Settings())
    x0, y0, side = found.original_box()
    assert abs(side - 1200 / 0.85) < 30 and abs(x0 + side / 2 - 1600) < 15 and abs(y0 + side / 2 - 1200) < 15


def test_cut_edges_are_the_photos_own_edges() -> None:
    """An object touching the photo's top (within 1 % of the crop) is cut there; one reaching past a crop edge
    that lies inside the photo (a handle rising above a crop framed round the core) is not."""
    mask = np.zeros((200, 200), bool)
    mask[41:180, 60:140] = True  # 1 px below the photo's top, which is row 40 of the crop
    assert crops.cut_edges(mask, crops.CropBox(0, -40, 200), (400, 400)) == ("top",)
    mask[:41, 90:110] = True  # up to the crop's top, which lies inside the photo: the crop's own edge
    assert crops.cut_edges(mask, crops.CropBox(50, 50, 200), (400, 400)) == ()
    full = np.ones((200, 200), bool)
    assert set(crops.cut_edges(full, crops.CropBox(0, 0, 200), (200, 200))) == {"top", "bottom", "left", "right"}


@pytest.mark.parametrize("size", [1.0, 0.4])
def test_the_strict_reading_is_made_only_when_it_could_win(vases, monkeypatch, size):
    """A large object whose forgiving reading sits on edges all round cannot be beaten by the reading that counts
    shading: `detect` then reads the photo once, and that reading is the one it would keep after reading twice;
    a small one is read twice."""
    from radar_cli.masks import detect as D

    image, alpha, mask = vases
    photo, _ = composite(image[0], alpha[0], mask[0], "plain", np.random.default_rng(5))
    if size < 1.0:  # the object a small part of a wider photo
        h, w = photo.shape[:2]
        photo = cv2.copyMakeBorder(photo, h, h, w, w, cv2.BORDER_REPLICATE)
    calls: list[tuple] = []
    cut = D._cut

    def counted(*args, **kwargs):
        calls.append(args)
        return cut(*args, **kwargs)

    monkeypatch.setattr(D, "_cut", counted)
    found = D.detect(photo, thorough=True)
    assert [args[-1] for args in calls] == ([True] if size == 1.0 else [True, False])
    small = calls[0][0]
    lead = 0.0 if D.is_greyscale(small) else D.SHADING_LEAD
    readings = [cut(*calls[0][:-1], shading) for shading in (True, False)]
    (forgiving, area, support), (_, strict_area, strict_support) = [D._scored(small, r[1]) for r in readings]
    if size == 1.0:  # the strict reading, made here, would not have won
        assert area >= D.READING_SHARE * max(area, strict_area) and support + lead >= strict_support
        assert not (strict_area >= D.GROWTH * area and strict_support >= support - D.GROWTH_SLACK)
        assert not (found[0].mask & ~forgiving).any()  # the object found is the forgiving reading's


def test_readings_that_start_alike_share_one_grabcut(monkeypatch):
    """A clean white backdrop read with its shading forgiven and not, once and again from all round the object,
    gives GrabCut the same start each time: it runs once, and the detection is the one of four separate runs."""
    from radar_cli.fileio import read_image
    from radar_cli.masks import detect as detection

    photo = read_image(Path(__file__).resolve().parents[2] / "examples" / "synthetic_vase_0.png")
    calls = []
    grabcut = detection.cv2.grabCut

    def counting(*args):
        calls.append(1)
        return grabcut(*args)

    monkeypatch.setattr(detection.cv2, "grabCut", counting)
    shared = detection.detect(photo, thorough=True)
    runs = len(calls)
    unshared = detection.coarse_grabcut
    monkeypatch.setattr(detection, "coarse_grabcut", lambda image, evidence, threshold, band, cuts: unshared(
        image, evidence, threshold, band))
    calls.clear()
    separate = detection.detect(photo, thorough=True)
    assert runs == 1 and len(calls) == 4
    assert len(shared) == len(separate) == 1
    assert np.array_equal(shared[0].mask, separate[0].mask) and shared[0].box == separate[0].box


def _pool_scene() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(photo, body, lower part, pool) at detection scale: a dark vessel with sharp edges on a grey sweep, its
    lower part (stem and foot) as dark, and a soft pool of light on the floor centred under it (all H x W)."""
    h = w = 320
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    pool = 55.0 * np.exp(-(((xx - w / 2) / (0.42 * w)) ** 2 + ((yy - 0.86 * h) / (0.12 * h)) ** 2))
    body = np.zeros((h, w), np.uint8)
    cv2.ellipse(body, (w // 2, 150), (75, 85), 0, 0, 360, 1, -1)
    cv2.rectangle(body, (w // 2 - 35, 50), (w // 2 + 35, 100), 1, -1)  # neck
    cv2.rectangle(body, (w // 2 - 55, 45), (w // 2 + 55, 56), 1, -1)  # rim
    lower = np.zeros((h, w), np.uint8)
    cv2.rectangle(lower, (w // 2 - 20, 230), (w // 2 + 20, 250), 1, -1)  # stem
    cv2.rectangle(lower, (w // 2 - 45, 250), (w // 2 + 45, 270), 1, -1)  # foot
    grey = np.where((body | lower) > 0, 40.0, 95.0 + 35.0 * yy / h + pool)
    return np.repeat(grey.astype(np.uint8)[..., None], 3, axis=2), body > 0, lower > 0, pool > 20.0


@pytest.mark.parametrize("extra", ["pool", "lower part"])
def test_a_symmetric_growth_counts_only_on_the_photos_edges(extra):
    """The strict reading wins where it adds a symmetric part the forgiving one took for shade: the vessel's
    dark lower part, whose outline is an edge in the photo; not where it adds the floor's pool of light under
    the vessel, as symmetric but with no edge (a greyscale photo, where the pale foot and the lit floor are one
    grey)."""
    from radar_cli.masks import detect as detection

    photo, body, lower, pool = _pool_scene()
    forgiving = body if extra == "lower part" else body | lower
    strict = forgiving | (lower if extra == "lower part" else pool)
    evidence = np.zeros(body.shape, np.float32)
    kept = detection._best_reading(photo, lambda shading: (evidence, forgiving if shading else strict), 0.0,
                                   lambda: strict)[1]
    assert np.array_equal(kept, strict if extra == "lower part" else forgiving)


def test_a_greyscale_photo_is_located_without_the_lit_floor(shared_data):
    """A krater's greyscale photograph: the lit floor under its foot is the foot's grey, and the reading that
    counts every brightness change takes it in, symmetric about the axis; the object found is the one of the
    colour photograph."""
    from radar_cli.fileio import read_image
    from radar_cli.masks import detect as detection

    photo = read_image(shared_data("data", "cva10", "photos", "83AE255", "back.jpg"))
    luma = photo.astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)
    grey = np.repeat(np.clip(luma, 0, 255).astype(np.uint8)[..., None], 3, axis=2)
    colour, plate = detection.detect(photo, thorough=True)[0], detection.detect(grey, thorough=True)[0]
    assert abs(int(plate.mask.sum()) / int(colour.mask.sum()) - 1.0) < 0.05  # with the floor: 1.34
    assert plate.box[2] - plate.box[0] < 0.95 * photo.shape[1]
