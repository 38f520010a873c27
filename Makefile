# `make demo` and `make test` each build .venv from this project's own files.
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
JOBS ?= 2

.PHONY: demo test test-fast lint bench reproduce clean

$(STAMP): pyproject.toml setup.py minvar/_lqg_kernel.c
	$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "hammer-mv needs Python >= 3.11"'
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev,pose]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/python tools/demo.py

test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -n $(JOBS) -q

test-fast: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -n $(JOBS) -q -m "not slow"

# ruff for style and bugs; vulture for code that can never run
lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/vulture minvar perception hammer_mv tools tests --min-confidence 100

bench: $(STAMP)
	$(BIN)/python tools/bench.py

reproduce: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python tools/reproduce_thesis.py -o out/thesis

clean:
	rm -rf $(VENV) out .pytest_cache
