# tvoronoi: `make run` starts the terminal UI, `make test` runs every test.
# Each target does its own set-up: a .venv, the package installed editable
# with its extras, and the Cython kernels rebuilt when their sources change.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
KERNEL_SRC := $(wildcard tvoronoi/kernels/*.pyx tvoronoi/kernels/*.pxd)
INSTALLED  := $(VENV)/.installed
BUILT      := $(VENV)/.kernels-built

.PHONY: run test setup bench bench-quick clean

setup: $(BUILT)

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(INSTALLED): pyproject.toml setup.py | $(BIN)/python
	$(BIN)/python -m pip install -q "setuptools>=64" wheel "Cython>=3.0" "numpy>=1.24"
	$(BIN)/python -m pip install -q --no-build-isolation -e ".[test,bench]"
	touch $@

$(BUILT): $(INSTALLED) $(KERNEL_SRC)
	$(BIN)/python setup.py -q build_ext --inplace
	touch $@

run: setup
	$(BIN)/tvoronoi

test: setup
	$(BIN)/python -m pytest -q

bench-quick: setup
	$(BIN)/python benchmarks/run.py --quick

bench: setup
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf build tvoronoi/kernels/*.c tvoronoi/kernels/*.so $(BUILT)
