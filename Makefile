# Two commands from a fresh clone: `make demo` and `make test`. Each creates .venv, installs,
# builds the FMUs (only what changed) and does its job.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test bench docs fmus clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

fmus: $(STAMP)
	$(PY) build_fmus.py

demo: fmus
	$(VENV)/bin/marinefmu simulate system --out results/system

# Two test workers (pytest-xdist), one per core of the CI machine; a file's tests stay together so
# its module fixtures (the conformance runs, the long co-simulations) are built once. The files go
# out in collection order, the long ones first (tests/conftest.py, LONG_FIRST), not xdist's
# most-tests-first, which leaves the few-test long files to the end on one worker.
test: fmus
	$(PY) -m pytest -q -n 2 --dist loadfile --no-loadscope-reorder --durations=20

bench: fmus
	$(VENV)/bin/marinefmu bench --out bench

# The documentation site into docs/_build/html, warnings as errors; the FMU pages read their
# interface tables from the built FMUs, hence fmus first.
docs: fmus
	$(PY) -m sphinx -W --keep-going -b html docs docs/_build/html

clean:
	rm -rf $(VENV) fmus/*.fmu fmus/.build-stamps results bench docs/_build
