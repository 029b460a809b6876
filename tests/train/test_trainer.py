"""The training loop: the loss goes down, resume reproduces an uninterrupted run, NaN stops cleanly, overfit."""

from __future__ import annotations

import json

import pytest
import torch

from radar_cli.errors import RadarError
from radar_cli.model.weights import load_model
from radar_cli.train import trainer
from radar_cli.train.checkpoint import list_checkpoints
from radar_cli.train.trainer import DivergedError, train

from .conftest import tiny_config


def test_few_steps_lower_the_loss(vases32, tmp_path):
    config = tiny_config(lr=2e-3, batch_size=8, iterations=16, checkpoint_every=100, image_every=8)
    summary = train(config, vases32, tmp_path / "run", progress=False)
    totals = [h["total"] for h in summary.history]
    assert len(totals) == 16 and all(map(torch.isfinite, torch.tensor(totals)))
    assert sum(totals[-3:]) / 3 < 0.8 * sum(totals[:3]) / 3
    assert summary.checkpoint is not None and summary.checkpoint.name == "step_0000016.safetensors"


def test_outputs_of_a_run(vases32, tmp_path):
    run = tmp_path / "run"
    train(tiny_config(iterations=4), vases32, run, progress=True)
    records = [json.loads(line) for line in (run / "metrics.jsonl").read_text().splitlines()]
    assert [r["step"] for r in records] == [0, 1, 2, 3]
    assert {"total", "sil", "im", "alb", "diff", "sad", "disc", "sec_per_step"} <= set(records[0])
    assert sorted(p.name for p in (run / "images").iterdir()) == ["step_0000002.png", "step_0000004.png"]
    assert (run / "loss_curve.png").stat().st_size > 1000
    assert [p.name for p in list_checkpoints(run)] == ["step_0000002.safetensors", "step_0000004.safetensors"]


@pytest.mark.parametrize("decay", [0, 4])  # with lr_decay_steps, the killed run stops inside the decay
def test_resume_continues_exactly(vases32, tmp_path, monkeypatch, decay):
    full = train(tiny_config(iterations=6, checkpoint_every=3, lr_decay_steps=decay), vases32, tmp_path / "a",
                 progress=False)
    real_step = trainer.train_step

    def killed_after_three(state, *args):
        if state.step == 3:
            raise KeyboardInterrupt  # as a kill after the step-3 checkpoint
        return real_step(state, *args)

    with monkeypatch.context() as patch, pytest.raises(KeyboardInterrupt):
        patch.setattr(trainer, "train_step", killed_after_three)
        train(tiny_config(iterations=6, checkpoint_every=3, lr_decay_steps=decay), vases32, tmp_path / "b",
              progress=False)
    resumed = train(tiny_config(iterations=6, checkpoint_every=3, lr_decay_steps=decay), vases32, tmp_path / "b",
                    resume=True, progress=False)
    assert resumed.start == 3 and resumed.end == 6
    for a, b in zip(full.history[3:], resumed.history):
        assert a.keys() == b.keys()
        for k in a:
            assert a[k] == pytest.approx(b[k], rel=1e-5, abs=1e-7), k
    model_a, _ = load_model(list_checkpoints(tmp_path / "a")[-1])
    model_b, _ = load_model(list_checkpoints(tmp_path / "b")[-1])
    for (name, pa), pb in zip(model_a.state_dict().items(), model_b.state_dict().values()):
        assert torch.allclose(pa, pb, atol=1e-6), name
    steps = [json.loads(line)["step"] for line in (tmp_path / "b" / "metrics.jsonl").read_text().splitlines()]
    assert steps == list(range(6))


def test_time_budget_checkpoints_and_stops_then_resume_finishes(vases32, tmp_path):
    config = tiny_config(iterations=4, checkpoint_every=100)
    full = train(config, vases32, tmp_path / "a", progress=False)
    assert not full.out_of_time
    cut = train(config, vases32, tmp_path / "b", progress=False, max_minutes=1e-9)  # spent after the first step
    assert cut.out_of_time and (cut.start, cut.end) == (0, 1)
    assert [p.name for p in list_checkpoints(tmp_path / "b")] == ["step_0000001.safetensors"]
    assert not (tmp_path / "b" / "model.safetensors").exists()  # weights are exported only at the last step
    resumed = train(config, vases32, tmp_path / "b", resume=True, progress=False, max_minutes=60)
    assert not resumed.out_of_time and (resumed.start, resumed.end) == (1, 4)
    assert [h["total"] for h in resumed.history] == pytest.approx([h["total"] for h in full.history[1:]], rel=1e-5)


def test_init_fine_tunes_from_another_run_and_resumes_its_own(vases32, tmp_path):
    first = train(tiny_config(iterations=2, checkpoint_every=2), vases32, tmp_path / "a", progress=False)
    tuned = train(tiny_config(iterations=2, checkpoint_every=1), vases32, tmp_path / "b", progress=False,
                  init=first.checkpoint, iterations=1)
    assert tuned.start == 0 and tuned.end == 1
    # the first step of the fine-tune starts from run a's weights: its loss is a's loss on that batch, not a
    # fresh network's
    fresh = train(tiny_config(iterations=1), vases32, tmp_path / "c", progress=False)
    assert tuned.history[0]["total"] != pytest.approx(fresh.history[0]["total"], rel=1e-6)
    # killed and rerun with --resume --init: continues from its own checkpoint, not from --init again
    resumed = train(tiny_config(iterations=2, checkpoint_every=1), vases32, tmp_path / "b", resume=True,
                    progress=False, init=first.checkpoint)
    assert resumed.start == 1 and resumed.end == 2


def test_init_from_a_model_file_says_the_discriminator_starts_afresh(vases32, tmp_path, capsys):
    first = train(tiny_config(iterations=1), vases32, tmp_path / "a", progress=False)
    train(tiny_config(iterations=1), vases32, tmp_path / "b", progress=False, init=first.checkpoint)
    assert "discriminator" not in capsys.readouterr().out
    model_file = tmp_path / "a" / "model.safetensors"
    train(tiny_config(iterations=1), vases32, tmp_path / "c", progress=False, init=model_file)
    assert f"{model_file}: no discriminator in it" in capsys.readouterr().out


def test_resume_without_checkpoint_is_an_error(vases32, tmp_path):
    with pytest.raises(RadarError, match="no checkpoint"):
        train(tiny_config(), vases32, tmp_path / "empty", resume=True, progress=False)


def test_nan_stops_with_step_and_keeps_last_good_checkpoint(vases32, tmp_path, monkeypatch):
    real = trainer.generator_losses
    calls = {"n": 0}

    def poisoned(pred, batch, config, disc, model=None):
        terms, rendered = real(pred, batch, config, disc, model)
        calls["n"] += 1
        if calls["n"] == 3:  # step index 2
            terms["total"] = terms["total"] * float("nan")
        return terms, rendered

    monkeypatch.setattr(trainer, "generator_losses", poisoned)
    run = tmp_path / "run"
    with pytest.raises(DivergedError, match=r"step 2: the loss is NaN or Inf.*step_0000002\.safetensors"):
        train(tiny_config(iterations=6), vases32, run, progress=False)
    model, _ = load_model(list_checkpoints(run)[-1])
    assert all(torch.isfinite(p).all() for p in model.parameters())
    assert (run / "loss_curve.png").is_file()


@pytest.mark.slow
def test_overfit_one_sample_drives_reconstruction_near_zero(vases32, tmp_path):
    config = tiny_config(lr=2e-3, iterations=300, checkpoint_every=1000, image_every=1000)
    summary = train(config, vases32, tmp_path / "run", overfit=1, progress=False)
    first, last = summary.history[0], summary.history[-1]
    assert last["im"] < 0.03 and last["im"] < 0.25 * first["im"]
    assert last["sil"] < 0.7 * first["sil"]  # the soft silhouette's blur sets a floor at 32 px


def test_nan_weights_stop_with_step(vases32, tmp_path, monkeypatch):
    real = trainer.train_step

    def poison_then_step(state, model, disc, batch, config, info, run_dir):
        if state.step == 1:
            with torch.no_grad():
                for p in state.model.shape_net.parameters():
                    p.fill_(float("nan"))
        return real(state, model, disc, batch, config, info, run_dir)

    monkeypatch.setattr(trainer, "train_step", poison_then_step)
    with pytest.raises(DivergedError, match="step 1: invalid network output"):
        train(tiny_config(iterations=3), vases32, tmp_path / "run", progress=False)


def test_command_line_overrides_replace_only_what_they_name():
    cfg = tiny_config()
    out = trainer.apply_overrides(cfg, iterations=7, overfit=None, threads=2)
    assert (out.train.iterations, out.train.threads, out.train.batch_size) == (7, 2, cfg.train.batch_size)
    assert out.model == cfg.model and out.loss == cfg.loss
    same = trainer.apply_overrides(cfg, None, None)
    assert same.train == cfg.train


def test_learning_rate_decays_linearly_over_the_last_steps(vases32, tmp_path):
    t = tiny_config(iterations=6, lr_decay_steps=4).train
    assert [trainer.learning_rate(t, s) / t.lr for s in range(6)] == [1, 1, 1, 0.75, 0.5, 0.25]
    assert trainer.learning_rate(tiny_config(iterations=6).train, 5) == t.lr  # 0 = constant, as the paper
    summary = train(tiny_config(iterations=6, lr_decay_steps=4), vases32, tmp_path / "run", progress=False)
    records = [json.loads(line) for line in (tmp_path / "run" / "metrics.jsonl").read_text().splitlines()]
    assert [r["lr"] / t.lr for r in records] == pytest.approx([1, 1, 1, 0.75, 0.5, 0.25])
    groups = summary.state.opt_model.param_groups + summary.state.opt_disc.param_groups
    assert all(g["lr"] == pytest.approx(0.25 * t.lr) for g in groups)
    assert trainer.learning_rate(tiny_config(iterations=2, lr_decay_steps=4).train, 0) == 0.5 * t.lr
    with pytest.raises(RadarError, match="lr_decay_steps"):
        tiny_config(iterations=6, lr_decay_steps=-1)
