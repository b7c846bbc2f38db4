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
	$(BIN)/pip install -q -e '.[dev,ray]'
	# pddlgym (the tests load the lifted domain with it) pins pillow<10, which the plan recordings' pillow does not
	# need; its other dependencies are in the dev extra
	$(BIN)/pip install -q --no-deps pddlgym==0.0.7 gym==0.26.2 gym-notices==0.1.0
	touch $@

# The recommended recipe at the demo preset (symlearn/pipeline.py): a paper-style data set and a 1-5-object one,
# the stability-trained effect model, m(z) on 9 location bits, the lifted PDDL domain, problems by shortest-plan
# length, and astar-outcomes next to stock Fast Downward on the lifted domain, closed loop; it ends with
# runs/demo/run/report.html. From a fresh clone after `make test` (2026-12-03 to -06, 2 cores): 2:02-3:19 (idle, or
# beside one other job); closed loop on 18 problems of 1-3 objects, astar-outcomes solved 0.33-0.50 (its search
# is timed) and fast-downward-lifted 0.61 (small models: the demo shows the system, not its results). Run again, it skips what
# is done (runs/demo/pipeline.json).
demo: $(VENV)/.installed
	$(BIN)/symlearn pipeline --preset demo --out runs/demo

test: $(VENV)/.installed
	$(BIN)/python -m pytest -q

# Also the tests marked slow: the paper preset's pipeline on 12,000 samples (tests/test_paper_scale.py), hours on
# 2 CPU cores.
test-all: $(VENV)/.installed
	$(BIN)/python -m pytest -q -m ''

bench: $(VENV)/.installed
	$(BIN)/python bench/collect.py --out bench/results/collect.json

clean:
	rm -rf $(VENV) runs/demo .pytest_cache
