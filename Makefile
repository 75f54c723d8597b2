# Two commands do all set-up on a fresh machine:  `make lab`  and  `make test`.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
BUILD := build
NOTEBOOKS := $(sort $(wildcard notebooks/[0-9][0-9]_*.ipynb))
SANITIZE := notebooks/nbval_sanitize.cfg
PYTEST_NB := --nbval --nbval-current-env --nbval-sanitize-with $(SANITIZE) --nbval-cell-timeout=600

.PHONY: venv lab test test-fast browser notebooks course student experiments bench clean help

help:
	@echo "make lab          set up .venv and open JupyterLab on notebooks/"
	@echo "make test         set up .venv (and Chromium where possible) and run every test and notebook"
	@echo "make test-fast    unit tests only (no notebooks, no browser)"
	@echo "make notebooks    re-execute every notebook in place (refreshes the stored outputs)"
	@echo "make course       execute all notebooks and write an HTML course to $(BUILD)/course"
	@echo "make student      write student copies without solutions to $(BUILD)/student"
	@echo "make experiments  run the paper's experiments at full size into $(BUILD)/experiments"
	@echo "make bench        run the benchmarks in benchmarks/"

# The virtual environment is rebuilt whenever pyproject.toml changes.
$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e ".[dev]"
	@touch $(STAMP)

venv: $(STAMP)

# Headless Chromium for the real-browser test (Debian's package; never `playwright install`).
browser:
	@bash .ci/install-chromium.sh

# JupyterLab refuses to run as root without --allow-root (containers, cloud machines).
lab: $(STAMP)
	$(BIN)/jupyter lab notebooks/ $(if $(filter 0,$(shell id -u)),--allow-root)

test: $(STAMP) browser
	$(BIN)/python -m pytest tests notebooks $(PYTEST_NB)

test-fast: $(STAMP)
	$(BIN)/python -m pytest tests -m "not browser and not slow"

notebooks: $(STAMP)
	$(BIN)/python -m meshvae_lib.course execute $(NOTEBOOKS)

course: $(STAMP)
	$(BIN)/python -m meshvae_lib.course html --out $(BUILD)/course $(NOTEBOOKS)

student: $(STAMP)
	$(BIN)/python -m meshvae_lib.course student --out $(BUILD)/student $(NOTEBOOKS)

experiments: $(STAMP)
	$(BIN)/python benchmarks/experiments.py --out $(BUILD)/experiments

bench: $(STAMP)
	@for b in benchmarks/bench_*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(BUILD) .pytest_cache
