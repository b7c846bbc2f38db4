# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
TORCH_VERSION := 2.13.0
# Where a CPU build of torch lies on disk (as on this project's machines) pip takes it in seconds;
# elsewhere ask PyTorch's CPU index, so that pip does not pull a multi-GB CUDA build.
TORCH_LOCAL := $(wildcard /opt/wheels/torch-$(TORCH_VERSION)*)
ifeq ($(TORCH_LOCAL),)
TORCH_FLAGS := --extra-index-url https://download.pytorch.org/whl/cpu
endif

.PHONY: demo test test-all bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/pip install -q torch==$(TORCH_VERSION) $(TORCH_FLAGS)
	$(BIN)/pip install -q -e '.[dev]'
	touch $@

demo: $(VENV)/.installed
	$(BIN)/symlearn scenarios
	$(BIN)/symlearn collect --out data/demo --n 240 --workers 2 --seed 0

test: $(VENV)/.installed
	$(BIN)/python -m pytest -q

test-all: $(VENV)/.installed
	$(BIN)/python -m pytest -q -m ''

bench: $(VENV)/.installed
	$(BIN)/python bench/collect.py --out bench/results/collect.json

clean:
	rm -rf $(VENV) data/demo .pytest_cache
