# quadimpact: one-command entry points.
#   make run    set up .venv (once) and reproduce the paper's study (report in results/paper);
#               make run DATA=DIR reads the flight logs from DIR (quadimpact reproduce --data
#               DIR), else $QUADIMPACT_DATA or the search of docs/EXPERIMENTS.md
#   make test   set up .venv (once), install headless Chromium if missing (root only), run the
#               tests but those marked slow (what CI runs), on every core (pytest-xdist,
#               at most 4 processes; JOBS=1 runs them in this process)
#   make test-avx2 the tests marked pinned again, NumPy's SIMD dispatch limited to AVX2 (CI
#               runs it after make test: what an AVX2-only CPU computes, checked on any CPU)
#   make test-all  every test, the slow ones (compiling plug-in kernels, whole studies) included
#   make lint   ruff check and ruff format --check
#   make bench  timing benchmark of the compiled core

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.quadimpact-installed

OUT := results/paper

# pytest's worker processes (pytest-xdist): one per core, at most 4; JOBS=1 runs the tests in
# one process (no xdist), JOBS=N in N.
JOBS ?= auto
ifeq ($(JOBS),1)
XDIST :=
else
XDIST := -n $(JOBS) --maxprocesses 4
endif

# The flight logs' folder for make run, given on make's command line (DATA=DIR): it
# becomes reproduce's --data. A DATA variable of the environment is not read (too
# common a name); the environment's route is QUADIMPACT_DATA, which reproduce reads.
ifeq ($(origin DATA),environment)
DATA :=
endif
DATA_FLAG := $(if $(strip $(DATA)),--data "$(strip $(DATA))")

.PHONY: setup run test test-avx2 test-all lint bench clean browser

setup: $(STAMP)

# Create the virtual environment if missing and install quadimpact (editable)
# with the development tools; redone only when pyproject.toml changes. Without
# network access for the build backend, fall back to the venv's own setuptools.
$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -e ".[dev,viz,distributed,rl]" \
	  || $(BIN)/python -m pip install --no-build-isolation --no-deps -e .
	touch $(STAMP)

# The paper's whole study (Figure 4, Table II, Figures 5-6, the seven crashes of
# Table III, the findings with computed verdicts) to $(OUT)/report.md, then a
# movie and an interactive viewer of the example impact.
run: $(STAMP)
	$(BIN)/quadimpact reproduce --out $(OUT) $(DATA_FLAG)
	$(BIN)/quadimpact animate $(OUT)/example-paper-replica
	$(BIN)/quadimpact view $(OUT)/example-paper-replica

# Headless Chromium for the viewer's browser tests (tests/viz/test_viz.py), from
# Debian's packages, only when it is missing and we are root (as in CI);
# otherwise those tests skip and say why. Idempotent.
browser:
	@if [ ! -x /usr/bin/chromium ] && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  (apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y chromium chromium-driver) \
	  || echo "make: could not install chromium; the browser tests will skip"; \
	fi

test: $(STAMP) browser
	$(BIN)/python -m pytest -m "not slow" $(XDIST)

# NumPy picks SVML loops for some ufuncs on AVX-512 CPUs and the C library on AVX2 ones:
# the pinned numbers must hold on both (quadimpact.libm, tests/test_libm.py).
test-avx2: $(STAMP)
	NPY_DISABLE_CPU_FEATURES="$$($(BIN)/python tests/cpu_dispatch.py)" \
	  $(BIN)/python -m pytest -m "pinned and not slow"

test-all: $(STAMP) browser
	$(BIN)/python -m pytest $(XDIST)

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks examples
	$(BIN)/ruff format --check src tests benchmarks examples

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_run.py

clean:
	rm -rf results build dist src/*.egg-info .pytest_cache .ruff_cache
