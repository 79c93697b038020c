# tvoronoi: `make run` starts the terminal UI, `make test` lints (ruff), type-checks (mypy) and runs every test.
# Each target does its own set-up: a .venv, the package installed editable
# with its extras, and the Cython kernels rebuilt when their sources change.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
KERNEL_SRC := $(wildcard tvoronoi/kernels/*.pyx tvoronoi/kernels/*.pxd)
INSTALLED  := $(VENV)/.installed
BUILT      := $(VENV)/.kernels-built
# The kernels with Cython's bounds checks and AddressSanitizer, built apart (tests/test_checked_build.py
# runs the degenerate inputs against them); bounds checks alone (CHECKED_MODE=1) where the compiler has no ASan.
CHECKED_MODE ?= $(if $(wildcard $(shell $(CC) -print-file-name=libasan.so)),asan,1)
CHECKED_DIR  := build/checked
CHECKED      := $(CHECKED_DIR)/.built-$(CHECKED_MODE)

.PHONY: run test setup checked bench bench-quick clean

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

checked: $(CHECKED)

$(CHECKED): $(INSTALLED) $(KERNEL_SRC) setup.py
	mkdir -p $(CHECKED_DIR) && rm -f $(CHECKED_DIR)/.built-*
	TVORONOI_CHECKED=$(CHECKED_MODE) $(BIN)/python setup.py -q build_ext --force \
		--build-lib $(CHECKED_DIR) --build-temp build/checked-tmp > build/checked.log 2>&1 \
		|| (cat build/checked.log; exit 1)
	touch $@

run: setup
	$(BIN)/tvoronoi

test: setup checked
	$(BIN)/ruff check tvoronoi tests benchmarks
	$(BIN)/ruff format --check tvoronoi tests benchmarks
	$(BIN)/mypy
	$(BIN)/python -m pytest -q

bench-quick: setup
	$(BIN)/python benchmarks/run.py --quick

bench: setup
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf build tvoronoi/kernels/*.c tvoronoi/kernels/*.so $(BUILT)
