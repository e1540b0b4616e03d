# Two commands from a fresh clone: `make demo` and `make test`. Each creates .venv, installs,
# builds the FMUs (only what changed) and does its job.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test bench fmus clean

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
# its module fixtures (the conformance runs, the long co-simulations) are built once.
test: fmus
	$(PY) -m pytest -q -n 2 --dist loadfile

bench: fmus
	$(VENV)/bin/marinefmu bench --out bench

clean:
	rm -rf $(VENV) fmus/*.fmu fmus/.build-stamps results bench
