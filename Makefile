# Two commands do all set-up on a fresh machine:  `make lab`  and  `make test`.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
BUILD := build
NOTEBOOKS := $(sort $(wildcard notebooks/[0-9][0-9]_*.ipynb))
SANITIZE := notebooks/nbval_sanitize.cfg
PYTEST_NB := --nbval --nbval-current-env --nbval-sanitize-with $(SANITIZE) --nbval-cell-timeout=900
LOCK := constraints.txt
# Float settings under which `make test-portable` re-runs every notebook against its stored outputs:
# one quoted string of environment assignments each. Each makes this machine compute as another
# would (measured: README, "The portability pass"): torch's generic kernels on one thread; MKL's
# "compatible" GEMM path; an AVX2 machine (the Haswell kernels of the OpenBLAS that numpy and scipy
# bundle, numpy's AVX2 loops); an AVX machine (Sandy Bridge kernels, numpy's SSE4.2 loops, torch's
# generic kernels). Add one here and a row to README's table.
PORTABLE_SETTINGS := \
	"ATEN_CPU_CAPABILITY=default MESHVAE_NUM_THREADS=1" \
	"MKL_CBWR=COMPATIBLE" \
	"OPENBLAS_CORETYPE=Haswell NPY_DISABLE_CPU_FEATURES=X86_V4,AVX512_ICL,AVX512_SPR" \
	"OPENBLAS_CORETYPE=Sandybridge NPY_DISABLE_CPU_FEATURES=X86_V3,X86_V4,AVX512_ICL,AVX512_SPR ATEN_CPU_CAPABILITY=default"

.PHONY: venv lock lab test test-fast test-portable browser models notebooks course student experiments bench clean help

help:
	@echo "make lab          set up .venv and open JupyterLab on notebooks/"
	@echo "make test         set up .venv (and Chromium where possible) and run every test and notebook"
	@echo "make test-fast    unit tests only (no notebooks, no browser)"
	@echo "make test-portable  re-run every notebook under other float settings (kernels of other CPUs) against its stored outputs"
	@echo "make lock         re-resolve the packages and rewrite $(LOCK) (then re-run make notebooks and make test)"
	@echo "make models       train the course's models that are not cached yet (~/.cache/meshvae, or \$$MESHVAE_CACHE)"
	@echo "make notebooks    re-execute every notebook in place (refreshes the stored outputs)"
	@echo "make course       execute all notebooks and write an HTML course to $(BUILD)/course"
	@echo "make student      write student copies without solutions to $(BUILD)/student"
	@echo "make experiments  run the paper's experiments at full size into docs/results (committed; notebook 09 shows them)"
	@echo "make bench        run the benchmarks in benchmarks/"

# The virtual environment is rebuilt whenever pyproject.toml or the lock changes; the lock pins
# every package to the version the notebooks were recorded with.
$(STAMP): pyproject.toml $(LOCK)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -c $(LOCK) -e ".[dev]"
	@touch $(STAMP)

venv: $(STAMP)

# Resolve pyproject.toml afresh in a throw-away venv and write every installed version to the lock.
lock:
	rm -rf $(BUILD)/lock-venv
	$(PYTHON) -m venv $(BUILD)/lock-venv
	$(BUILD)/lock-venv/bin/python -m pip install --quiet --disable-pip-version-check -e ".[dev]"
	{ sed -n '/^#/p;/^#/!q' $(LOCK); $(BUILD)/lock-venv/bin/python -m pip freeze --exclude-editable | sed 's/+cpu$$//'; } > $(LOCK).new
	mv $(LOCK).new $(LOCK)
	rm -rf $(BUILD)/lock-venv
	@echo "wrote $(LOCK); now update environment.yml's pins, then make notebooks && make test"

# Headless Chromium for the real-browser test (Debian's package; never `playwright install`).
browser:
	@bash .ci/install-chromium.sh

# JupyterLab refuses to run as root without --allow-root (containers, cloud machines).
lab: $(STAMP)
	$(BIN)/jupyter lab notebooks/ $(if $(filter 0,$(shell id -u)),--allow-root)

test: $(STAMP) browser models
	$(BIN)/python -m pytest tests notebooks $(PYTEST_NB)

# The stored outputs must hold under other kernels and summation orders, as on another machine.
# Every setting runs, also after a failure; the summary names each failed cell beside its setting
# (one log per setting in $(BUILD)/portable).
test-portable: $(STAMP) models
	$(BIN)/python -m meshvae_lib.course portable --logs $(BUILD)/portable \
	  --command "$(BIN)/python -m pytest notebooks $(PYTEST_NB) -p no:cacheprovider -q" $(PORTABLE_SETTINGS)

test-fast: $(STAMP)
	$(BIN)/python -m pytest tests -m "not browser and not slow"

# The course's trained models live in a cache outside the clone (meshvae_lib/course/models.py);
# this builds the missing ones. A notebook that needs a missing model trains it itself.
models: $(STAMP)
	$(BIN)/python -m meshvae_lib.course models

notebooks: $(STAMP) models
	$(BIN)/python -m meshvae_lib.course execute $(NOTEBOOKS)

course: $(STAMP)
	$(BIN)/python -m meshvae_lib.course html --out $(BUILD)/course $(NOTEBOOKS)

student: $(STAMP)
	$(BIN)/python -m meshvae_lib.course student --out $(BUILD)/student $(NOTEBOOKS)

experiments: $(STAMP)
	$(BIN)/python benchmarks/experiments.py --out docs/results

bench: $(STAMP)
	@for b in benchmarks/bench_*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(BUILD) .pytest_cache
