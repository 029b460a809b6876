# radar: every set-up step lives here, so a fresh clone needs only `make demo` or `make test`.
# The experiment targets below reproduce the paper's tables; each names the data, run and results folders it uses.
PY ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
RADAR := $(BIN)/radar
SHARED ?= ../shared
DEVICE ?= auto
WORKERS ?= 2
THREADS ?=
# CPU training threads: empty keeps each preset's train.threads (1, for shared machines); THREADS=2 on an idle one
TRAIN_THREADS := $(if $(THREADS),--threads $(THREADS),)
# extra `radar train` options for train-syn and train-met, e.g. TRAIN_ARGS="--max-minutes 25" and later
# TRAIN_ARGS="--max-minutes 25 --resume" to fit the 40k steps into a machine's time limit (status 3 = not finished)
TRAIN_ARGS ?=
# the albedo the evaluation targets score: the paper's Table 2 scores the albedo network's output (network);
# ALBEDO=divided scores `radar derender`'s default, the input divided by the predicted shading
ALBEDO ?= network
# PITCH=search scores `radar derender --pitch search` (the test-time pitch search) instead of f_S's pitch
PITCH ?= network

.PHONY: install demo test test-slow test-all test-gpu test-browser lint clean \
        syn-data syn-data-cpu syn-data-cpu-format1 train-syn train-syn-cpu eval-syn eval-syn-cpu table2 table2-cpu \
        met-fetch met-masks train-met real-vases bench specular-reader

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	# torch is pinned to the CPU build on disk; installing it first keeps pip from pulling CUDA wheels.
	$(BIN)/pip install -q torch==2.13.0
	$(BIN)/pip install -q -e '.[test,lint]'
	touch $(STAMP)

install: $(STAMP)

# The main job on the embedded default: the bundled model de-renders the bundled example photos.
demo: $(STAMP)
	$(RADAR) derender examples --out demo_out

# The everyday suite, CPU only; tests marked slow (torchrun, subprocesses, shards, kill/resume, long optimisations)
# are left to test-slow
test: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow and not gpu" tests

test-slow: $(STAMP)
	$(BIN)/python -m pytest -q -m "slow and not gpu" tests

# Everything: test and test-slow, and the GPU tests, which skip without CUDA
test-all: $(STAMP)
	$(BIN)/python -m pytest -q tests

# ruff on the package, the tests and experiments/; mypy on the files pyproject.toml's [tool.mypy] names
lint: $(STAMP)
	$(BIN)/ruff check radar_cli tests experiments
	$(BIN)/mypy

# CPU-vs-CUDA agreement of the renderer, the losses and the bundled model (each test skips without CUDA)
test-gpu: $(STAMP)
	$(BIN)/python -m pytest -q -m gpu tests

# The gallery in a real browser: Debian's Chromium (headless, software WebGL) driven by Playwright, which is told to
# use that Chromium and never downloads one. Installing Chromium needs root (or sudo).
test-browser: $(STAMP)
	command -v chromium >/dev/null || { apt-get update && apt-get install -y chromium; } || \
		{ sudo apt-get update && sudo apt-get install -y chromium; }
	$(BIN)/pip install -q -e '.[test,browser]'
	$(BIN)/python -m pytest -q -s -m browser tests

clean:
	rm -rf $(VENV) demo_out .pytest_cache

# --- Synthetic vases: Table 2 of the paper (GPU presets, 256 px) ------------------------------------------
syn-data: $(STAMP)
	$(RADAR) synth --out data/syn_vases --size 256 --workers $(WORKERS)

train-syn: $(STAMP)
	$(RADAR) train --config pipelines/paper/syn_vases.toml --data data/syn_vases --out runs/syn_vases --device $(DEVICE) \
		$(TRAIN_ARGS)

eval-syn: $(STAMP)
	$(RADAR) derender data/syn_vases/test --checkpoint runs/syn_vases/model.safetensors --out results/syn_vases \
		--views 0 --device $(DEVICE) --workers $(WORKERS) --albedo $(ALBEDO) --pitch $(PITCH)
	$(RADAR) eval --pred results/syn_vases --gt data/syn_vases --json results/syn_vases/eval.json

# Every row of Table 2: the full model, the ablations and the supervised upper bound.
table2: $(STAMP)
	for p in syn_vases syn_vases_no_alb syn_vases_no_sad syn_vases_no_diff syn_vases_supervised; do \
		$(RADAR) train --config pipelines/paper/$$p.toml --data data/syn_vases --out runs/$$p --device $(DEVICE) && \
		$(RADAR) derender data/syn_vases/test --checkpoint runs/$$p/model.safetensors --out results/$$p \
			--views 0 --device $(DEVICE) --workers $(WORKERS) --albedo $(ALBEDO) --pitch $(PITCH) && \
		$(RADAR) eval --pred results/$$p --gt data/syn_vases --json results/$$p/eval.json || exit 1; \
	done

# --- The same at CPU size (64 px): the bundled model's data, training and evaluation -------------------------
syn-data-cpu: $(STAMP)
	$(RADAR) synth --out data/syn_cpu --size 64 --workers $(WORKERS)

# Stages 1-8 of the bundled model were trained on synthesis format 1, the images `radar synth` drew before its edge
# pixels were blended with the background (docs/formats.md); this makes them with that commit's generator.
FORMAT1_COMMIT := 9b29213
syn-data-cpu-format1: $(STAMP)
	rm -rf build/synth_format1 && mkdir -p build/synth_format1
	git archive $(FORMAT1_COMMIT) radar_cli | tar -x -C build/synth_format1
	cd build/synth_format1 && PYTHONPATH=. $(CURDIR)/$(BIN)/python -m radar_cli synth --out $(CURDIR)/data/syn_cpu_format1 \
		--size 64 --workers $(WORKERS)

# The bundled model's ten stages (docs/training.md; pipelines/cpu/syn_vases_cpu.toml, then pipelines/bundled/):
# stages 1-8 on format-1 images, each but stage 4 starting from the one before with --init (stage 4 resumes
# stage 3 with a second learning-rate ramp); stage 8 first de-renders the training vases with --pitch search for
# its pitch labels; stage 9 fine-tunes stage 8 on format-2 images (`make syn-data-cpu`) and stage 10 repeats stage 8's
# self-training on them. --resume continues a killed fine-tune and a
# re-run `radar derender` skips the objects it has finished.
F1 := data/syn_cpu_format1
train-syn-cpu: $(STAMP)
	$(RADAR) train --config pipelines/cpu/syn_vases_cpu.toml --data $(F1) --out runs/syn_cpu --device cpu $(TRAIN_THREADS)
	$(RADAR) train --config pipelines/bundled/stage2_sharp.toml --init runs/syn_cpu/checkpoints/step_0006500.safetensors \
		--data $(F1) --out runs/syn_cpu_sharp --device cpu $(TRAIN_THREADS)
	$(RADAR) train --config pipelines/bundled/stage3_mouth.toml \
		--init runs/syn_cpu_sharp/checkpoints/step_0004500.safetensors --data $(F1) --out runs/syn_cpu_mouth \
		--device cpu $(TRAIN_THREADS)
	mkdir -p runs/syn_cpu_mouth_long/checkpoints
	test -n "$$(ls runs/syn_cpu_mouth_long/checkpoints)" || \
		cp runs/syn_cpu_mouth/checkpoints/step_0018000.safetensors runs/syn_cpu_mouth_long/checkpoints/
	$(RADAR) train --config pipelines/bundled/stage4_mouth_long.toml --resume --data $(F1) \
		--out runs/syn_cpu_mouth_long --device cpu $(TRAIN_THREADS)
	$(RADAR) train --config pipelines/bundled/stage5_cycle.toml --resume \
		--init runs/syn_cpu_mouth_long/checkpoints/step_0027000.safetensors --data $(F1) \
		--out runs/syn_cpu_cycle --device cpu $(TRAIN_THREADS)
	$(RADAR) train --config pipelines/bundled/stage6_light.toml --resume \
		--init runs/syn_cpu_cycle/checkpoints/step_0004000.safetensors --data $(F1) \
		--out runs/syn_cpu_light --device cpu $(TRAIN_THREADS)
	$(RADAR) train --config pipelines/bundled/stage7_divided.toml --resume \
		--init runs/syn_cpu_light/checkpoints/step_0004000.safetensors --data $(F1) \
		--out runs/syn_cpu_divided --device cpu $(TRAIN_THREADS)
	$(RADAR) derender $(F1)/train --checkpoint runs/syn_cpu_divided/model.safetensors \
		--out results/syn_cpu_train_search --views 0 --pitch search --workers $(WORKERS)
	$(RADAR) train --config pipelines/bundled/stage8_selftrain.toml --resume \
		--init runs/syn_cpu_divided/checkpoints/step_0002000.safetensors --pitch-labels results/syn_cpu_train_search \
		--data $(F1) --out runs/syn_cpu_selftrain --device cpu $(TRAIN_THREADS)
	$(RADAR) train --config pipelines/bundled/stage9_finetune.toml --resume \
		--init runs/syn_cpu_selftrain/model.safetensors --data data/syn_cpu --out runs/syn_cpu_finetune \
		--device cpu $(TRAIN_THREADS)
	$(RADAR) derender data/syn_cpu/train --checkpoint runs/syn_cpu_finetune/model.safetensors \
		--out results/syn_cpu_f2_train_search --views 0 --pitch search --workers $(WORKERS)
	$(RADAR) train --config pipelines/bundled/stage10_selftrain.toml --resume \
		--init runs/syn_cpu_finetune/checkpoints/step_0002000.safetensors --pitch-labels results/syn_cpu_f2_train_search \
		--data data/syn_cpu --out runs/syn_cpu_selftrain2 --device cpu $(TRAIN_THREADS)

# The bundled specular-albedo reader (radar_cli/assets/readers/specular_albedo.safetensors; docs/refinement.md):
# the bundled model's f_L taught with the true specular albedo of 4,000 synthetic vases at 64 px (447 held out)
specular-reader: $(STAMP)
	$(RADAR) synth --out data/reader_syn --n 4000 --size 64 --seed 31 --workers $(WORKERS)
	$(RADAR) train-reader --config pipelines/readers/specular_albedo.toml --data data/reader_syn --out runs/specular_reader

# The bundled model (or CPU_MODEL=runs/.../model.safetensors) on the 460 test vases of `make syn-data-cpu`
CPU_MODEL ?=
eval-syn-cpu: $(STAMP)
	$(RADAR) derender data/syn_cpu/test $(if $(CPU_MODEL),--checkpoint $(CPU_MODEL),) --out results/syn_cpu \
		--overwrite --views 0 --albedo $(ALBEDO) --pitch $(PITCH) --workers $(WORKERS)
	$(RADAR) eval --pred results/syn_cpu --gt data/syn_cpu --json results/syn_cpu/eval.json

table2-cpu: $(STAMP)
	for p in syn_vases_cpu syn_vases_cpu_no_alb syn_vases_cpu_no_sad syn_vases_cpu_no_diff syn_vases_cpu_supervised; do \
		$(RADAR) train --config pipelines/cpu/$$p.toml --data data/syn_cpu --out runs/$$p --device cpu $(TRAIN_THREADS) && \
		$(RADAR) derender data/syn_cpu/test --checkpoint runs/$$p/model.safetensors --out results/$$p --views 0 \
			--albedo $(ALBEDO) --pitch $(PITCH) && \
		$(RADAR) eval --pred results/$$p --gt data/syn_cpu --json results/$$p/eval.json || exit 1; \
	done

# --- Metropolitan Museum vases: the paper's real data (needs the Met API, i.e. internet) ------------------
met-fetch: $(STAMP)
	$(RADAR) fetch --query vase --out data/met

met-masks: $(STAMP)
	$(RADAR) masks data/met --out data/met_prepared --size 256 --workers $(WORKERS)

train-met: $(STAMP)
	$(RADAR) train --config pipelines/paper/met_vases.toml --data data/met_prepared --out runs/met_vases --device $(DEVICE) \
		$(TRAIN_ARGS)

# --- The 12 real photographs beside the repo, de-rendered by the bundled model, with a contact sheet ----------
real-vases: $(STAMP)
	$(RADAR) derender $(SHARED)/data/real_vases --out results/real_vases --overwrite \
		--contact-sheet results/real_vases/contact_sheet.png

bench: $(STAMP)
	$(RADAR) bench render --device $(DEVICE)
	$(RADAR) bench train --config pipelines/cpu/syn_vases_cpu.toml
	$(RADAR) bench masks
	$(RADAR) bench synth
	$(RADAR) bench derender
