# `make demo` and `make test` each build .venv from this project's own files.
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
JOBS ?= 2

.PHONY: demo test test-fast lint bench reproduce clean bytecode

$(STAMP): pyproject.toml setup.py minvar/_lqg_kernel.c
	$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "hammer-mv needs Python >= 3.11"'
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev,pose]'
	$(MAKE) --no-print-directory bytecode
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

bench: $(STAMP) bytecode
	$(BIN)/python tools/bench.py

# An editable install compiles nothing, and where PYTHONDONTWRITEBYTECODE is
# set (as on CI machines) Python then compiles every module of ours anew in
# every process: 0.3 s of each command's start-up. Python still reads .pyc
# files that exist, and recompiles in memory any that are out of date.
bytecode:
	$(BIN)/python -m compileall -q minvar perception hammer_mv > /dev/null

reproduce: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python tools/reproduce_thesis.py -o out/thesis

clean:
	rm -rf $(VENV) out .pytest_cache
