# pushctl — every target creates .venv first (idempotent), so each works from a clean checkout.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: install test lint bench reproduce-tables clean

install: $(STAMP)

# torch is pinned and installed first: `torch==2.13.0` resolves to the CPU build on disk;
# a looser requirement would pull several GB of CUDA packages.
$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "torch==2.13.0"
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

test: $(STAMP)
	$(PY) -m pytest -q

lint: $(STAMP)
	$(PY) -m ruff check pushctl tests
	$(PY) -m ruff format --check pushctl tests
	$(PY) -m mypy pushctl

bench: $(STAMP)
	$(PY) -m pushctl.bench --profile --out results/bench.csv

reproduce-tables: $(STAMP)
	@echo "reproduce-tables: evaluation and the report are not built yet (issue 6); training is: pushctl train --preset paper" >&2
	@exit 2

clean:
	rm -rf $(VENV) .pytest_cache
