"""Export the learned relational domain: operators found from data over the relational model's symbols.

    symlearn export-learned --run RUN --data data/paper_a data/k15     # RUN/learned/domain.pddl, operators.json

The training split of every data set is turned into transitions between learned symbolic states
(symlearn.symbolic.learned_state), grouped into operators (pddl_export.learned_domain), and written as a typed
STRIPS domain. report.json says how many transitions changed the learned state and how many fall in a kept
operator's group, with the settings, the model's hash and the data's fingerprints.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Sequence

from pddl_export.files import atomic_write_files, sha256_file
from pddl_export.bounded_json import read_json_file
from pddl_export.learned_domain import (Operator, Transition, coverage, domain_pddl, learn_operators,
                                        operators_from_json, operators_to_json)
from symlearn.data.dataset import data_fingerprint
from symlearn.learning.relational_training import CHECKPOINT, load_relational
from symlearn.provenance import versions
from symlearn.symbolic.learned_state import data_transitions

LEARNED_DIR = "learned"
OPERATORS = "operators.json"  # RUN/learned/operators.json: what the closed loop plans with
# a lifted effect seen fewer times is dropped as noise of the learned symbols. Chosen on problems/rel_dev(68): 5 keeps
# 131 operators, whose grounding makes every 6-8-object call time out (0.85 / 0.00 at 1-5 / 6-8 objects); 20 keeps
# 35 (0.825 / 0.90)
MIN_COUNT = 20


def prune_dead_relations(transitions: list[Transition]) -> list[Transition]:
    """The transitions without the `nothing-rK` atoms of every head K that holds for no pair in any state: such a
    head learned nothing (training switched it off), and its negation, true of every object, only clutters the
    domain."""
    alive = {a[0] for t in transitions for a in t.pre | t.post}
    dead = {p for p in alive if p.startswith("nothing-") and p[len("nothing-"):] not in alive}
    if not dead:
        return transitions
    keep = lambda atoms: frozenset(a for a in atoms if a[0] not in dead)  # noqa: E731
    return [Transition(keep(t.pre), keep(t.post), t.pick, t.release) for t in transitions]


def export_learned(run_dir: Path, roots: Sequence[Path], min_count: int = MIN_COUNT,
                   comments: dict[str, str] | None = None) -> dict:
    """Write RUN/learned/{domain.pddl, operators.json, report.json}; returns the report."""
    run_dir = Path(run_dir)
    model, blob = load_relational(run_dir)
    transitions = prune_dead_relations(data_transitions(model, blob, roots, "train"))
    ops = learn_operators(transitions, min_count)
    report = {"operators": len(ops), "min_count": min_count, "transitions": coverage(ops, transitions),
              "model_sha256": sha256_file(run_dir / CHECKPOINT),
              "data": [{"data": str(r), "data_fingerprint": data_fingerprint(Path(r))} for r in roots],
              "versions": versions()}
    out = run_dir / LEARNED_DIR
    out.mkdir(exist_ok=True)
    atomic_write_files({out / "domain.pddl": domain_pddl(ops, comments=comments),
                        out / OPERATORS: json.dumps(operators_to_json(ops), indent=1),
                        out / "report.json": json.dumps(report, indent=1)})
    return report


def operators_path(run_dir: Path) -> Path:
    """RUN/learned/operators.json."""
    return Path(run_dir) / LEARNED_DIR / OPERATORS


def load_operators(run_dir: Path) -> list[Operator]:
    """A run's learned operators, read by the bounded JSON reader; a missing or malformed file is refused in one
    line naming it."""
    path = operators_path(run_dir)
    if not path.is_file():
        raise ValueError(f"{path} is missing: run symlearn export-learned --run {run_dir} first")
    return operators_from_json(read_json_file(path, what="learned operators"), str(path))
