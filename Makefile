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
	touch $@

# The whole pipeline at the quick preset on a small data set (about 5 minutes on 2 cores with the install: 4:45
# from a fresh clone on 2026-12-02), ending with the
# learned-net A* next to Fast Downward and SymK on the exported rules (their SAS+ route; the PDDL route through
# unified-planning takes seconds per task and runs in `make test` and examples/) and the in-process rule searches
# (rules-bfs, rules-outcomes), the same problems on the
# shipped pretrained run (copied to runs/pretrained), and RUN/report.html.
demo: $(VENV)/.installed
	$(BIN)/symlearn scenarios
	$(BIN)/symlearn collect --out data/demo --n 3000 --workers 2 --seed 0 --quiet
	$(BIN)/symlearn train --data data/demo --out runs/demo --preset quick --epochs 30 --quiet
	$(BIN)/symlearn evaluate --run runs/demo --data data/demo
	$(BIN)/symlearn table1 --run runs/demo
	$(BIN)/symlearn symbols --run runs/demo --data data/demo --min-count 20
	$(BIN)/symlearn train-transition --run runs/demo --data data/demo --preset quick --epochs 20 --quiet
	$(BIN)/symlearn export-pddl --run runs/demo --data data/demo --max-objects 2 --min-count 5 --pddl-fidelity-cases 0
	$(BIN)/symlearn problems --out problems/demo --n 10 --objects 1-3 --length 1-2 --seed 0
	$(BIN)/symlearn benchmark --run runs/demo --problems problems/demo --planners astar,astar-outcomes,fast-downward-sas-opt,symk-sas,rules-bfs,rules-outcomes --closed-loop \
		--out runs/demo/benchmark.json --quiet
	$(BIN)/symlearn plan --run runs/demo --problem problems/demo/problem_0000.json --planner astar --record runs/demo/plan.gif
	rm -rf runs/pretrained && cp -r pretrained/quick-authors12k runs/pretrained
	$(BIN)/symlearn benchmark --run runs/pretrained --problems problems/demo --planners astar,astar-outcomes,fast-downward-sas-opt,rules-bfs,rules-outcomes --closed-loop \
		--out runs/pretrained/benchmark.json --quiet
	$(BIN)/symlearn report --run runs/demo --data data/demo --benchmark runs/demo/benchmark.json --recording runs/demo/plan.gif

test: $(VENV)/.installed
	$(BIN)/python -m pytest -q

# Also the tests marked slow: the paper preset's pipeline on 12,000 samples (tests/test_paper_scale.py), hours on
# 2 CPU cores.
test-all: $(VENV)/.installed
	$(BIN)/python -m pytest -q -m ''

bench: $(VENV)/.installed
	$(BIN)/python bench/collect.py --out bench/results/collect.json

clean:
	rm -rf $(VENV) data/demo runs/demo runs/pretrained problems/demo .pytest_cache
