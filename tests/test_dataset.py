"""The on-disk sample layout."""

import numpy as np
import pytest

from radar_cli import dataset
from radar_cli.errors import InputError


def test_write_list_read(tmp_path):
    img = np.zeros((8, 8, 3), np.uint8)
    mask = np.zeros((8, 8), bool)
    mask[2:6, 3:5] = True
    for sid in ("b", "a"):
        dataset.write_sample(dataset.sample_ref(tmp_path, "train", sid), img, mask)
    (tmp_path / "train" / "incomplete").mkdir()
    refs = dataset.list_samples(tmp_path, "train")
    assert [r.sample_id for r in refs] == ["a", "b"]
    image, m = dataset.read_sample(refs[0])
    assert image.shape == (8, 8, 3) and (m == mask).all()
    assert dataset.is_dataset(tmp_path)


@pytest.mark.parametrize("bad", ["../x", "a/b", "", ".."])
def test_ids_never_paths(tmp_path, bad):
    with pytest.raises(InputError):
        dataset.sample_ref(tmp_path, "train", bad)


def test_safe_id():
    assert dataset.safe_id("Met 12/34: vase") == "Met_12_34_vase"
    with pytest.raises(InputError):
        dataset.safe_id("///")


def test_mismatched_mask(tmp_path):
    ref = dataset.sample_ref(tmp_path, "test", "x")
    dataset.write_sample(ref, np.zeros((8, 8, 3), np.uint8), np.zeros((8, 8), bool))
    from radar_cli.fileio import write_image

    write_image(ref.mask_path, np.zeros((4, 4), np.uint8))
    with pytest.raises(InputError, match="does not match image"):
        dataset.read_sample(ref)
