"""A small fixed-seed `radar synth` output pinned by checksum: a change to the generator (shapes, textures, lighting,
renderer, quantisation) that alters a picture or a parameter fails here. When the change is meant, raise
FORMAT_VERSION, update PINNED and PINNED_SUMS (the failure prints the new digests) and docs/formats.md in the same
commit, and re-measure the accuracy tables in docs/accuracy.md on the new data.

A rendered picture is a float image rounded to 8 bits, and another CPU's vector units can round a float a last
bit apart, which moves a pixel by one level: `test/000000/albedo_rendered.png` reads so on one of the Xeons this
suite runs on. A picture whose digest differs still passes where its per-channel pixel sums lie within SUM_SLACK
levels per pixel of the pinned ones (a few pixels a level apart); a change to the generator moves them far more."""

from __future__ import annotations

import hashlib

import numpy as np

from radar_cli.fileio import read_image
from radar_cli.synth.generator import FORMAT_VERSION, SynthConfig, generate

# 64 px like `make syn-data-cpu`, the test split with the default seed: samples 0 and 1 of data/syn_cpu/test.
CONFIG = SynthConfig(size=64)
SAMPLES = 2
PINNED_VERSION = 2
PINNED = {
    "test/000000/albedo.png": "ccc67a78f9ea79b8c372fddacd85654a750827b1eba739e0c027a902679e9b78",
    "test/000000/albedo_rendered.png": "c2a8ea6d1e2b5d4e054babee44f9f720948f2b0e5b651ee4fef80448e9cfccfa",
    "test/000000/env_map.png": "fcae9a945883df31da6155b09b43669ef5570ce8b1b43dc172dfa1b22afac5e1",
    "test/000000/image.png": "f3a9b9787fe7c7951b9021ec9182ccb55649803946a1830b9578cd5ba3907fa0",
    "test/000000/mask.png": "03d1abe402ee0ffb9f6262ad7523c9bc9339a2d53b0c4129211bf525decec409",
    "test/000000/mask_front.png": "5f5ae1551b40959ccda4041135aa360f06923e0384658031220a642696030442",
    "test/000000/normal_rendered.png": "de49ed4dfbe14a81b94053f1c5ab461592c82ce68d591a17f8d2dde51b4d1dea",
    "test/000000/params.json": "39bb134f245533cede003b524f62f8c69a5a7a3db5f0106edfbca76a22972d35",
    "test/000001/albedo.png": "94a6491401dce7aebba0a2d84112317668e943291c196ef2947ed4e6e52232bc",
    "test/000001/albedo_rendered.png": "56dfa17038f9278bb4d1e0cdbc88f18a515b4ae4773d100e2726c9d082831a48",
    "test/000001/env_map.png": "12d1d4276189bead75cafcd16769d3684e37bac1afe7e253d10103c4ae0231f9",
    "test/000001/image.png": "c4d6b604c35e1bc28395a68fe0754b6a15cceb6be15745f5b3fdcf610abee67a",
    "test/000001/mask.png": "6a09f1e1bb2a349002e05f527e3febdde636364ff63e19ac4b58ff1e749df0c4",
    "test/000001/mask_front.png": "c999d072888d417007aff35ef7e4f9227c29758a175088b619047c69976db484",
    "test/000001/normal_rendered.png": "7aff4019537978222cbe057be4cc38098a988581ac87527fd2650c28da019506",
    "test/000001/params.json": "093ead37a7f3e9fdafaa91e7b206dd06094a80cfec82bacdbaa656e504c4b447",
}

PINNED_SUMS = {  # per-channel pixel sums of the same pictures
    "test/000000/albedo.png": (1436915, 790061, 2595932),
    "test/000000/albedo_rendered.png": (119845, 92820, 201897),
    "test/000000/env_map.png": (15152, 15152, 15152),
    "test/000000/image.png": (857988, 850969, 891199),
    "test/000000/mask.png": (262140, 262140, 262140),
    "test/000000/mask_front.png": (206550, 206550, 206550),
    "test/000000/normal_rendered.png": (523774, 516704, 438964),
    "test/000001/albedo.png": (2563155, 477126, 2101989),
    "test/000001/albedo_rendered.png": (229966, 50943, 190496),
    "test/000001/env_map.png": (20233, 20233, 20233),
    "test/000001/image.png": (883503, 807139, 865811),
    "test/000001/mask.png": (301920, 301920, 301920),
    "test/000001/mask_front.png": (245820, 245820, 245820),
    "test/000001/normal_rendered.png": (523696, 495292, 411654),
}
SUM_SLACK = 0.005  # levels per pixel: a float rounded a last bit apart on another CPU flips a few pixels by one


def _near_pin(path, name: str) -> bool:
    """Whether a picture whose digest differs has per-channel sums within SUM_SLACK of PINNED_SUMS."""
    if name not in PINNED_SUMS or not path.is_file():
        return False
    pixels = read_image(path, "RGB").astype(np.int64)
    sums = pixels.reshape(-1, 3).sum(0)
    slack = SUM_SLACK * pixels.shape[0] * pixels.shape[1]
    return bool((np.abs(sums - np.array(PINNED_SUMS[name])) <= slack).all())


def _digest(path) -> str:
    """sha256 of a PNG's decoded pixels (not its bytes: the encoder's zlib may differ) or of a file's bytes."""
    if path.suffix == ".png":
        pixels = read_image(path, "RGB")
        data = np.ascontiguousarray(pixels).tobytes() + repr(pixels.shape).encode()
    else:
        data = path.read_bytes()
    return hashlib.sha256(data).hexdigest()


def pinned_digests(root) -> dict[str, str]:
    """Digest of every PNG and params.json of the samples under root (npy floats are left out: their last bits
    may differ between CPUs, and every one of them also shows in a PNG)."""
    files = sorted(p for p in root.rglob("*") if p.suffix in (".png", ".json") and p.parent.name.isdigit())
    return {p.relative_to(root).as_posix(): _digest(p) for p in files}


def test_fixed_seed_output_matches_the_pin(tmp_path):
    generate(tmp_path, {"test": SAMPLES}, CONFIG, progress=False)
    got = pinned_digests(tmp_path)
    changed = sorted(name for name in got.keys() | PINNED.keys()
                     if got.get(name) != PINNED.get(name) and not _near_pin(tmp_path / name, name))
    assert not changed, (f"radar synth draws different samples ({', '.join(changed)}): if meant, raise "
                         f"FORMAT_VERSION and set PINNED to {got}")
    assert FORMAT_VERSION == PINNED_VERSION, "FORMAT_VERSION changed without the pin: update PINNED_VERSION with it"
