# `make demo` and `make test` each build .venv from this project's own files,
# with the versions pinned in requirements-lock.txt (`make lock` renews
# them; `make test-latest` tries the newest versions the registry serves).
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
JOBS ?= 2
CONSTRAINTS := requirements-lock.txt
# -c pins what is installed; PIP_CONSTRAINT as well, because pip applies it to
# the isolated build environment too, so setuptools (the build backend) is pinned
PIN := PIP_CONSTRAINT=$(CURDIR)/$(CONSTRAINTS)
LATEST := .venv-latest

.PHONY: demo test test-fast test-latest lock lint bench reproduce evaluate clean bytecode

$(STAMP): pyproject.toml setup.py minvar/_lqg_kernel.c $(CONSTRAINTS)
	$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "hammer-mv needs Python >= 3.11"'
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(PIN) $(BIN)/python -m pip install --quiet -c $(CONSTRAINTS) --upgrade pip setuptools wheel
	$(PIN) $(BIN)/python -m pip install --quiet -c $(CONSTRAINTS) -e '.[dev,pose,mocap]'
	$(MAKE) --no-print-directory bytecode
	touch $(STAMP)

# Resolve every dependency afresh (newest versions) in a scratch venv and pin
# what it got. Run it, then `make test`, and commit the new constraints.
lock:
	rm -rf .venv-lock
	$(PYTHON) -m venv .venv-lock
	.venv-lock/bin/python -m pip install --quiet --upgrade pip setuptools wheel
	.venv-lock/bin/python -m pip install --quiet '.[dev,pose,mocap]'
	{ echo "# Versions make demo, make test and CI install (make lock renews them)."; \
	  echo "# Resolved $$(date -u +%Y-%m-%d) for Python $$(.venv-lock/bin/python -c 'import platform; print(platform.python_version())')."; \
	  .venv-lock/bin/python -m pip freeze --all --exclude hammer-mv; } > $(CONSTRAINTS).part
	mv $(CONSTRAINTS).part $(CONSTRAINTS)
	rm -rf .venv-lock

# The suite against the newest versions the registry serves, unpinned: it
# reports (never fails) and lists which versions differ from the lock, so a
# coming break is seen before `make lock` takes it in.
test-latest:
	rm -rf $(LATEST)
	$(PYTHON) -m venv $(LATEST)
	$(LATEST)/bin/python -m pip install --quiet --upgrade pip setuptools wheel
	$(LATEST)/bin/python -m pip install --quiet -e '.[dev,pose,mocap]'
	-$(LATEST)/bin/python tools/compare_lock.py $(CONSTRAINTS)
	-MPLBACKEND=Agg $(LATEST)/bin/python -m pytest -n $(JOBS) -q -p no:cacheprovider \
	    > $(LATEST)/pytest.log 2>&1; \
	  echo "test-latest (newest versions, not the lock): $$(tail -n 1 $(LATEST)/pytest.log | tr -d '=')"; \
	  grep -E '^(FAILED|ERROR) ' $(LATEST)/pytest.log | sed 's/^/test-latest: /' || true

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

# The verdict on the held-out healthy-adult population (seeds 9000 + k), from
# video; `tools/evaluate_verdict.py --set dev` is the set to tune on.
evaluate: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python tools/evaluate_verdict.py --set heldout -o out/eval/heldout
	$(BIN)/python tools/evaluate_online.py --set heldout -o out/eval-online/heldout

clean:
	rm -rf $(VENV) $(LATEST) .venv-lock out .pytest_cache
