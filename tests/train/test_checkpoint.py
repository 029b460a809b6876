"""Checkpoints: round trip, keep-K, export, and clear errors for corrupt or mismatched files."""

from __future__ import annotations

import dataclasses

import pytest
import torch
from safetensors.torch import save_file

from radar_cli.errors import CheckpointError
from radar_cli.model.weights import load_model, read_checkpoint
from radar_cli.train.checkpoint import export_weights, initialise, list_checkpoints, restore, save_checkpoint
from radar_cli.train.trainer import build_state

from .conftest import tiny_config


@pytest.fixture
def saved(tmp_path):
    config = tiny_config()
    state = build_state(config, torch.device("cpu"))
    for step in (1, 2, 3):
        state.step = step
        save_checkpoint(tmp_path, config, state, keep=2)
    return config, state, tmp_path


def test_keep_last_k_and_round_trip(saved):
    config, state, run = saved
    assert [p.name for p in list_checkpoints(run)] == ["step_0000002.safetensors", "step_0000003.safetensors"]
    model, stored = load_model(list_checkpoints(run)[-1])
    assert stored == config
    image = torch.rand(2, 3, 32, 32)
    state.model.eval()
    with torch.no_grad():
        for a, b in zip(model(image).tensors(), state.model(image).tensors()):
            assert torch.equal(a, b)


def test_restore_into_fresh_state(saved):
    config, state, run = saved
    fresh = build_state(dataclasses.replace(config, train=dataclasses.replace(config.train, seed=5)),
                        torch.device("cpu"))
    assert restore(list_checkpoints(run)[-1], config, fresh) == 3
    for a, b in zip(fresh.disc.state_dict().values(), state.disc.state_dict().values()):
        assert torch.equal(a, b)


def test_export_weights_is_small_and_loadable(saved, tmp_path):
    _, state, run = saved
    out = export_weights(list_checkpoints(run)[-1], tmp_path / "assets" / "model.safetensors")
    tensors, meta, config = read_checkpoint(out)
    assert all(k.startswith("model.") for k in tensors) and meta["step"] == "3"
    model, _ = load_model(out)
    assert isinstance(model.config, type(config.model))


def test_corrupt_checkpoint_is_a_clear_error(saved, tmp_path):
    _, _, run = saved
    good = list_checkpoints(run)[-1]
    truncated = tmp_path / "truncated.safetensors"
    truncated.write_bytes(good.read_bytes()[:1000])
    garbage = tmp_path / "garbage.safetensors"
    garbage.write_bytes(b"\x00" * 64)
    for path in (truncated, garbage):
        with pytest.raises(CheckpointError, match="corrupt"):
            load_model(path)
    with pytest.raises(CheckpointError, match="no such checkpoint"):
        load_model(tmp_path / "missing.safetensors")
    foreign = tmp_path / "foreign.safetensors"
    save_file({"w": torch.zeros(2)}, str(foreign))
    with pytest.raises(CheckpointError, match="not a radar checkpoint"):
        load_model(foreign)


def test_mismatched_checkpoint_is_a_clear_error(saved, tmp_path):
    config, _, run = saved
    other = dataclasses.replace(config, model=dataclasses.replace(config.model, albedo_width=16))
    state = build_state(other, torch.device("cpu"))
    with pytest.raises(CheckpointError, match=r"\[model\] config differs"):
        restore(list_checkpoints(run)[-1], other, state)
    # weights that do not fit the stored config
    tensors, meta, _ = read_checkpoint(list_checkpoints(run)[-1])
    tensors = {k: v for k, v in tensors.items() if "albedo_net" not in k}
    broken = tmp_path / "broken.safetensors"
    save_file(tensors, str(broken), metadata=meta)
    with pytest.raises(CheckpointError, match="model weights do not fit"):
        load_model(broken)


def test_init_starts_a_new_run_from_weights_with_other_loss_settings(saved, tmp_path):
    config, state, run = saved
    sharper = dataclasses.replace(
        config, loss=dataclasses.replace(config.loss, dt_margin_px=1.0),
        model=dataclasses.replace(config.model, render=dataclasses.replace(config.model.render, sil_sigma_px=0.25)),
        train=dataclasses.replace(config.train, seed=7))
    fresh = build_state(sharper, torch.device("cpu"))
    assert initialise(list_checkpoints(run)[-1], fresh)  # the discriminator came along
    assert fresh.step == 0  # a new run: step and optimizers start afresh
    assert not fresh.opt_model.state
    for a, b in zip(fresh.model.state_dict().values(), state.model.state_dict().values()):
        assert torch.equal(a, b)
    for a, b in zip(fresh.disc.state_dict().values(), state.disc.state_dict().values()):
        assert torch.equal(a, b)
    # an exported model file (no discriminator) also initialises the networks
    exported = export_weights(list_checkpoints(run)[-1], tmp_path / "model.safetensors")
    assert not initialise(exported, build_state(sharper, torch.device("cpu")))  # networks only
    wider = dataclasses.replace(config, model=dataclasses.replace(config.model, albedo_width=16))
    with pytest.raises(CheckpointError, match="model weights do not fit"):
        initialise(exported, build_state(wider, torch.device("cpu")))
