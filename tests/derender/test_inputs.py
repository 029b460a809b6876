"""Collecting inputs (files, folders, datasets, bad paths) and cutting the network's crop."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from radar_cli.dataset import sample_ref, write_sample
from radar_cli.derender.run.inputs import collect_inputs, prepare
from radar_cli.errors import InputError

from .conftest import SIZE, vase_photo, write_photo


def test_collect_files_folders_and_datasets(tmp_path: Path) -> None:
    write_photo(tmp_path / "photos" / "a.png", 1)
    write_photo(tmp_path / "photos" / "sub" / "a.webp", 2)  # same stem: a unique name is made
    (tmp_path / "photos" / "SOURCES.tsv").write_text("id\turl\n")  # not an image: ignored inside a folder
    ref = sample_ref(tmp_path / "data", "test", "v1")
    write_sample(ref, vase_photo(3), np.ones((SIZE, SIZE), bool))
    items, failures = collect_inputs([tmp_path / "photos", tmp_path / "data", tmp_path / "photos" / "a.png",
                                      tmp_path / "missing.png"])
    assert [i.name for i in items] == ["a", "a-2", "v1"]  # dataset samples keep their id (radar eval)
    assert items[2].is_crop and not items[0].is_crop
    assert [f.source for f in failures] == [str(tmp_path / "missing.png")]
    assert "no such file" in failures[0].problem


def test_dataset_sample_used_whole(tmp_path: Path) -> None:
    ref = sample_ref(tmp_path, "test", "v1")
    write_sample(ref, vase_photo(3, (128, 128)), np.ones((128, 128), bool))
    (item,), _ = collect_inputs([tmp_path])
    prepared = prepare(item, SIZE)
    assert prepared.crop.to_list() == [0, 0, 128] and prepared.image.shape == (SIZE, SIZE, 3)
    assert prepared.silhouette is not None and prepared.silhouette.all()  # its mask.png, cut like the image


def test_dataset_splits_and_split_folder(tmp_path: Path) -> None:
    for split in ("train", "test"):
        ref = sample_ref(tmp_path, split, "000000")
        write_sample(ref, vase_photo(3), np.ones((SIZE, SIZE), bool))
        (ref.folder / "albedo.png").write_bytes(b"ground truth, not an input")
    items, failures = collect_inputs([tmp_path])
    assert [i.name for i in items] == ["test_000000", "train_000000"] and not failures
    (item,), _ = collect_inputs([tmp_path / "test"])  # one split given directly: only its image.png files
    assert item.name == "000000" and item.is_crop


def test_crop_none_pads_to_square(tmp_path: Path) -> None:
    (item,), _ = collect_inputs([write_photo(tmp_path / "wide.png", 1, (96, 144))])
    prepared = prepare(item, SIZE, crop="none")
    assert prepared.crop.to_list() == [0, -24, 144] and prepared.photo_size == (144, 96)


def test_masks_folder_gives_the_crop(tmp_path: Path) -> None:
    photo = write_photo(tmp_path / "in" / "p.png", 1, (100, 100))
    mask = np.zeros((100, 100), np.uint8)
    mask[10:50, 20:40] = 255  # a box that is not where the detector would look
    (tmp_path / "masks").mkdir()
    Image.fromarray(mask).save(tmp_path / "masks" / "p.png")
    (item,), _ = collect_inputs([photo], masks=tmp_path / "masks")
    x0, y0, side = prepare(item, SIZE).crop.to_list()
    assert abs(x0 + side / 2 - 30) <= 1 and abs(y0 + side / 2 - 30) <= 1 and 45 <= side <= 49


@pytest.mark.parametrize("mode", ["L", "RGBA", "I;16", "CMYK"])
def test_unusual_image_modes(tmp_path: Path, mode: str) -> None:
    rgb = Image.fromarray(vase_photo(4, (96, 96)))
    image = {"L": rgb.convert("L"), "RGBA": rgb.convert("RGBA"), "CMYK": rgb.convert("CMYK"),
             "I;16": Image.fromarray((np.asarray(rgb.convert("L")).astype(np.uint16) * 257))}[mode]
    path = tmp_path / ("p.tiff" if mode in ("I;16", "CMYK") else "p.png")
    image.save(path)
    (item,), _ = collect_inputs([path])
    prepared = prepare(item, SIZE)
    assert prepared.image.shape == (SIZE, SIZE, 3) and prepared.image.dtype == np.uint8


def test_blank_photo_is_one_clear_error(tmp_path: Path) -> None:
    path = tmp_path / "blank.png"
    Image.new("RGB", (120, 80), (200, 200, 200)).save(path)
    (item,), _ = collect_inputs([path])
    with pytest.raises(InputError, match="blank.png"):
        prepare(item, SIZE)


def test_results_inside_an_input_folder_are_not_inputs(tmp_path: Path) -> None:
    write_photo(tmp_path / "photos" / "a.png", 1)
    write_photo(tmp_path / "photos" / "results" / "a" / "recon.png", 2)
    items, _ = collect_inputs([tmp_path / "photos"], exclude=tmp_path / "photos" / "results")
    assert [i.image_path.name for i in items] == ["a.png"]


def test_white_backdrop_through_the_silhouette(tmp_path: Path) -> None:
    photo = vase_photo(5, (96, 144))
    photo[..., 1] = np.where(photo[..., 1] == 225, 150, photo[..., 1])  # a greenish-grey studio backdrop
    path = tmp_path / "p.png"
    Image.fromarray(photo).save(path)
    (item,), _ = collect_inputs([path])
    kept, white = prepare(item, SIZE, backdrop="keep"), prepare(item, SIZE, backdrop="white")
    assert kept.backdrop == "kept" and white.backdrop == "white"
    assert tuple(kept.image[1, 1]) == (225, 150, 225) and tuple(white.image[1, 1]) == (255, 255, 255)
    centre = (slice(SIZE // 2 - 4, SIZE // 2 + 4),) * 2
    np.testing.assert_array_equal(white.image[centre], kept.image[centre])  # the object itself is untouched
    for prepared in (kept, white):  # the located silhouette travels with the crop, for the divided albedo
        assert prepared.silhouette is not None and prepared.silhouette.shape == (SIZE, SIZE)
        assert prepared.silhouette[centre].all() and not prepared.silhouette[1, 1]
    assert prepare(item, SIZE, crop="none").silhouette is None  # nothing located, nothing known


def test_a_fetch_folder_gives_one_object_per_record(tmp_path: Path) -> None:
    """`radar fetch --out data` keeps one-photo objects as data/met/<id>.jpg and several-photo ones as
    data/met/<id>/: `radar derender data` makes one object of each, not one of the whole `met` folder."""
    (tmp_path / "data" / "met").mkdir(parents=True)
    (tmp_path / "data" / "catalog.sqlite").write_bytes(b"")
    for stem in ("101", "102"):
        write_photo(tmp_path / "data" / "met" / f"{stem}.jpg", int(stem))
    for view in range(3):
        write_photo(tmp_path / "data" / "met" / "103" / f"103_{view}.jpg", view)
    (tmp_path / "data" / "met" / "101.json").write_text("{}")  # the stored record: not an image
    items, failures = collect_inputs([tmp_path / "data"])
    assert not failures
    assert [(i.name, len(i.views)) for i in items] == [("101", 0), ("102", 0), ("103", 3)]
    plain, _ = collect_inputs([tmp_path / "data" / "met"])  # the photos' folder itself: the same objects
    assert [(i.name, len(i.views)) for i in plain] == [("101", 0), ("102", 0), ("103", 3)]
