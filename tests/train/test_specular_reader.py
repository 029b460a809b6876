"""The specular-albedo reader: it starts as f_L's reading, learns the true specular albedo of synthetic vases,
resumes a killed run, and loads only its own file format."""

from __future__ import annotations

import dataclasses
import json
import shutil

import pytest
import torch
from safetensors.torch import save_file

from radar_cli.config import to_dict
from radar_cli.errors import CheckpointError, ConfigError, InputError
from radar_cli.model.radar import RadarModel
from radar_cli.model.specular_reader import SpecularReader
from radar_cli.model.weights import FORMAT, load_specular_reader, module_tensors
from radar_cli.sor.solid import Solid
from radar_cli.synth.generator import SynthConfig, make_sample, write_sample_folder
from radar_cli.train.checkpoint import save_specular_reader
from radar_cli.train.specular_reader import LAST_FILE, READER_FILE, ReaderConfig, train_reader

from .conftest import tiny_config


@pytest.fixture(scope="module")
def synth32(tmp_path_factory):
    """12 training and 4 held-out `radar synth` vases at 32 px."""
    root = tmp_path_factory.mktemp("reader32")
    cfg = SynthConfig(size=32, seed=3)
    for split, n in (("train", 12), ("test", 4)):
        for i in range(n):
            files, params = make_sample(cfg, split, i, None)
            write_sample_folder(root, split, f"{i:06d}", files, params)
    return root


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """A tiny model's weights file, as `radar train` exports it."""
    torch.manual_seed(0)
    config = tiny_config()
    path = tmp_path_factory.mktemp("base") / "model.safetensors"
    save_file(module_tensors(RadarModel(config.model), "model"), str(path),
              metadata={"format": FORMAT, "config": json.dumps(to_dict(config)), "step": "0"})
    return path


def _shape(n: int = 2):
    return torch.full((n, 16), 0.4), torch.full((n,), 0.7), torch.tensor([[10.0, 0.0, 0.0, 0.0]] * n)


def test_reader_starts_as_f_l_reading():
    torch.manual_seed(0)
    model = RadarModel(tiny_config().model).eval()
    reader = SpecularReader.from_light_net(model.config, model.light_net).eval()
    image = torch.rand(2, 3, 32, 32)
    radius, height, pose = _shape()
    with torch.no_grad():
        solid = Solid(radius, height, pose)
        _, _, rho = model.light_net(*model.unwrap_inputs(solid, image))
        read = reader(image, solid)
    assert torch.allclose(read * 2, rho, atol=1e-6)  # f_L reads 0..2, the reader 0..1


def test_reader_learns_resumes_and_repeats(synth32, base, tmp_path):
    config = ReaderConfig(epochs=6, batch_size=4, lr=1e-3, threads=1)
    lines = []
    full = train_reader(config, synth32, tmp_path / "full", base, progress=False, say=lines.append)
    assert len(lines) == 6 and lines[-1].startswith("epoch 6: train L1")  # one line per epoch, as it ends
    first, last = full.history[0], full.history[-1]
    assert len(full.history) == 6 and full.resumed == 0
    assert last["train_l1"] < 0.8 * first["train_l1"]  # it learns the training vases' specular albedo
    assert {"held_out_l1", "held_out_constant_l1"} <= set(last)
    assert (tmp_path / "full" / "loss.png").stat().st_size > 0

    # killed after 3 epochs, then run again to 6: the same reader as the run that was not killed
    train_reader(dataclasses.replace(config, epochs=3), synth32, tmp_path / "split", base, progress=False)
    (tmp_path / "split" / READER_FILE).unlink()
    resumed = train_reader(config, synth32, tmp_path / "split", base, progress=False)
    assert resumed.resumed == 3 and len(resumed.history) == 6
    a, b = load_specular_reader(full.reader), load_specular_reader(resumed.reader)
    for (name, x), (_, y) in zip(a.state_dict().items(), b.state_dict().items()):
        assert torch.equal(x, y), name


def test_reader_files_round_trip_and_foreign_files_are_refused(base, tmp_path):
    torch.manual_seed(0)
    reader = SpecularReader(tiny_config().model).eval()
    path = save_specular_reader(reader, tmp_path / "r.safetensors")
    loaded = load_specular_reader(path)
    image, solid = torch.rand(2, 3, 32, 32), Solid(*_shape())
    with torch.no_grad():
        assert torch.equal(loaded(image, solid), reader(image, solid))
    with pytest.raises(CheckpointError, match="not a radar specular-albedo reader"):
        load_specular_reader(base)
    broken = tmp_path / "broken.safetensors"
    broken.write_bytes(path.read_bytes()[:1000])
    with pytest.raises(CheckpointError, match="broken.safetensors"):
        load_specular_reader(broken)
    assert not (tmp_path / LAST_FILE).exists()


def test_samples_without_ground_truth_are_named(synth32, base, tmp_path):
    root = tmp_path / "data"
    shutil.copytree(synth32 / "train", root / "train")
    params = root / "train" / "000003" / "params.json"
    params.write_text(json.dumps({k: v for k, v in json.loads(params.read_text()).items() if k != "rho"}))
    with pytest.raises(InputError, match="000003.*rho"):
        train_reader(ReaderConfig(epochs=1, batch_size=4, threads=1), root, tmp_path / "out", base, progress=False)


def test_unusable_settings_are_one_clear_error(synth32, base, tmp_path):
    with pytest.raises(ConfigError, match="epochs"):
        train_reader(ReaderConfig(epochs=0), synth32, tmp_path / "out", base, progress=False)
