# pushctl — every target creates .venv first (idempotent), so each works from a clean checkout.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: install test lint bench reproduce-tables clean

NATIVE := pushctl/native/lib/libpushctl_native.so
WARM   := $(VENV)/.kernels-compiled

install: $(STAMP) $(NATIVE) $(WARM)

# torch is pinned and installed first: `torch==2.13.0` resolves to the CPU build on disk;
# a looser requirement would pull several GB of CUDA packages.
$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "torch==2.13.0"
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

# pushctl's compiled library (pushctl/native): Pinocchio's arm pass and ProxSuite's force
# QPs behind C entry points, the same bits as through their Python bindings. --optional:
# without a C++ compiler it prints a note and the bindings are used.
$(NATIVE): $(STAMP) $(wildcard pushctl/native/*.cpp)
	$(PY) -m pushctl.native.build --optional

# numba compiles the simulator's kernels at first use (about a minute of one core) and keeps
# them in its disk cache: compiled here, the first command starts at once (pushctl/cli/warm.py).
$(WARM): $(STAMP) $(NATIVE) $(shell find pushctl -name '*.py')
	$(PY) -c "from pushctl.cli.warm import warm; warm()"
	touch $(WARM)

test: install
	$(PY) -m pytest -q

lint: install
	$(PY) -m ruff check pushctl tests
	$(PY) -m ruff format --check pushctl tests
	$(PY) -m mypy pushctl

# bench.compare: this tree against 551bcac side by side (git archive, interleaved children),
# then against ac82d3c (before the step with the plant unknowns got cheaper:
# docs/reproducibility-and-speed.md); bench.evaluation: a short `pushctl evaluate` against
# 998b653, timed and compared byte for byte (docs/evaluation-speed.md); bench.training: a
# short paper-shaped `pushctl train` against aee9d1d, likewise (docs/training-speed.md).
bench: install
	$(PY) -m pushctl.bench --profile --out results/bench.csv --force
	$(PY) -m pushctl.bench.compare --against 551bcac --out results/bench_compare.csv --force
	$(PY) -m pushctl.bench.compare --against ac82d3c --out results/bench_compare_unknowns.csv --force
	$(PY) -m pushctl.bench.evaluation --against 998b653 --out results/bench_evaluation.csv --force
	$(PY) -m pushctl.bench.training --against aee9d1d --out results/bench_training.csv --force

# Train (paper preset, seeds $(SEEDS) on Ray), evaluate (50 trials x 2 objects x 3 profiles x
# 2 controllers x 2 plants), report, bench; QUICK=1: quick preset, 4 trials, into results-quick/;
# SEEDS=0: one training seed; PRESET=quick: another training preset, full evaluation
# (pushctl/cli/reproduce.py).
SEEDS ?= 0,1,2
reproduce-tables: install
	$(PY) -m pushctl.cli.reproduce $(if $(filter 1,$(QUICK)),--quick,) $(if $(filter 1,$(FORCE)),--force,) --seeds $(SEEDS) $(if $(PRESET),--preset $(PRESET),)

clean:
	rm -rf $(VENV) .pytest_cache
