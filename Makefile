# pushctl — every target creates .venv first (idempotent), so each works from a clean checkout.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: install test lint bench bench-learners reproduce-tables pd-sweep digests clean

NATIVE := pushctl/native/lib/libpushctl_native.so
WARM   := $(VENV)/.kernels-compiled

install: $(STAMP) $(NATIVE) $(WARM)

# torch is pinned and installed first: `torch==2.13.0` resolves to the CPU build on disk;
# a looser requirement would pull several GB of CUDA packages.
$(STAMP): pyproject.toml
	@echo "installing pushctl and its packages into $(VENV) (torch, Pinocchio, MuJoCo, Ray)"
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "torch==2.13.0"
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

# pushctl's compiled library (pushctl/native): Pinocchio's arm pass and ProxSuite's force
# QPs behind C entry points, the same bits as through their Python bindings. --optional:
# without a C++ compiler it prints a note and the bindings are used.
$(NATIVE): $(STAMP) $(wildcard pushctl/native/*.cpp)
	$(PY) -c "from pushctl.native.build import build; print(build(optional=True))"

# numba compiles the simulator's kernels at first use (5-11 min on two cores) and keeps them
# in its disk cache: compiled here, showing each step, the first command starts at once
# (pushctl/cli/warm.py).
$(WARM): $(STAMP) $(NATIVE) $(shell find pushctl -name '*.py')
	$(PY) -c "from pushctl.cli.warm import main; main()"
	touch $(WARM)

test: install
	$(PY) -m pytest -q

lint: install
	$(PY) -m ruff check pushctl tests benchmarks studies
	$(PY) -m ruff format --check pushctl tests benchmarks studies
	$(PY) -m mypy pushctl

# Timings of this tree beside MuJoCo's, one core, the engines interleaved, medians
# (benchmarks/): results/bench.csv and the table of docs/performance.md. Comparisons with
# another commit are opt-in: python -m benchmarks.compare_commits step --against REV.
bench: install
	$(PY) -m benchmarks.suite --out results/bench.csv --page docs/performance.md --force

# Our DDPG and TD3 beside stable-baselines3's DDPG, TD3 and SAC on Pendulum-v1 and
# InvertedPendulum-v5, one budget per task, seeds 0-2 (benchmarks/learners.py; 30 runs on
# one core): docs/learner-check.csv, whose figures docs/learner-check.md reports.
bench-learners: install
	$(PY) -m benchmarks.learners --out docs/learner-check.csv --force

# Train (experiments/train_paper_v1.toml, seeds 0-4 on Ray; 97 min on two cores), evaluate
# (50 trials x 2 objects x 3 profiles x every controller x the plants sim, proxy and
# mujoco), report, bench: `pushctl reproduce`.
# QUICK=1: quick preset, 4 trials, into results-quick/; SEEDS=0: one training seed;
# PRESET=quick: another training preset, full evaluation; FORCE=1: overwrite a results
# directory an earlier reproduction did not make.
reproduce-tables: install
	$(PY) -m pushctl.cli reproduce $(if $(filter 1,$(QUICK)),--quick,) $(if $(filter 1,$(FORCE)),--force,) $(if $(SEEDS),--seeds $(SEEDS),) $(if $(PRESET),--preset $(PRESET),)

# The PD baseline on drawn scenarios (studies/pd_sweep.py): results/pd_sweep_{sim,proxy}.csv.
pd-sweep: install
	$(PY) -m studies.pd_sweep --plant sim --out results/pd_sweep_sim.csv --force
	$(PY) -m studies.pd_sweep --plant proxy --out results/pd_sweep_proxy.csv --force

# After a change meant to move results and a new `make reproduce-tables`: record the shipped
# files' digests and the short runs' (tests/shipped_digests.py) that `make test` checks.
digests: install
	$(PY) tests/shipped_digests.py --record

clean:
	rm -rf $(VENV) .pytest_cache
