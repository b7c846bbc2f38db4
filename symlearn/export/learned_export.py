"""Export the learned relational domain: operators found from data over the relational model's symbols.

    symlearn export-learned --run RUN --data data/paper_a data/k15     # RUN/learned/domain.pddl, operators.json

The training split of every data set is turned into transitions between learned symbolic states
(symlearn.symbolic.learned_state), grouped into operators (pddl_export.learned_domain), and written as a typed
STRIPS domain. report.json says how many transitions changed the learned state and how many fall in a kept
operator's group, with the settings, the model's hash and the data's fingerprints.
"""
from __future__ import annotations

import dataclasses
import json
import math
import random
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from pddl_export.files import atomic_write_files, sha256_file
from pddl_export.bounded_json import read_json_file
from pddl_export.learned_domain import (Operator, Transition, carried, coverage, domain_pddl, generalize,
                                        learn_operators, location_binding, operators_from_json, operators_to_json,
                                        precision)
from symlearn.config_file import Bound, check_bounds, preset
from symlearn.data.dataset import data_fingerprint
from symlearn.learning.relational_training import CHECKPOINT, load_relational
from symlearn.provenance import versions
from symlearn.symbolic.learned_state import data_transitions

LEARNED_DIR = "learned"
OPERATORS = "operators.json"  # RUN/learned/operators.json: what the closed loop plans with
# a lifted effect seen fewer times is dropped as noise of the learned symbols. Chosen on problems/rel_dev(68) with the
# `at`-only model: 5 keeps 131 operators, whose grounding makes every 6-8-object call time out; 20 keeps 35
MIN_COUNT = 20


@dataclass(frozen=True)
class LearnedExportConfig:
    """How operators are found from the learned transitions (pddl_export.learned_domain), in this order:
    group by lifted effect (`min_count`, `max_objects`), precondition = atoms shared by `share` of a group,
    drop operators whose precision on `sample` training transitions is below `min_precision`, then drop the
    precondition atoms the data do not need (`slack`). min_precision 0 and slack -1 turn the last two off.

    `confidence_z` judges precision by its Wilson lower bound at that many standard errors (0: the plain ratio):
    a rare operator whose precision rests on a handful of groundings (4 of 16) is dropped unless the data show it
    is above `min_precision`, while a common one loses almost nothing to the bound.

    `by_place` judges an operator for one place (`placed`) on up to `sample` transitions at that place instead
    of the shared sample: an operator that carries a far-row stick from l1 applies in about 1 transition of 6
    there and in few of a sample drawn from every place, where the bound drops it for want of evidence."""

    min_count: int = MIN_COUNT
    share: float = 1.0
    max_objects: int = 4
    min_precision: float = 0.0
    slack: float = -1.0
    confidence_z: float = 0.0
    sample: int = 4000
    seed: int = 0
    placed: bool = False  # an effect naming a location besides the action's two gets an operator per place (lift)
    by_place: bool = False
    # a group that moves three or more items at once (a stick and two riders) needs this many transitions (0:
    # min_count): far-stick data show 16 for the largest, under 20 (pretrained/relations_carry)
    multi_min_count: int = 0
    # the last step never drops a precondition atom the operator deletes (pddl_export.learned_domain.generalize): a
    # STRIPS operator then deletes only what it requires, as a person would write it
    keep_deleted: bool = False

    def __post_init__(self) -> None:
        check_bounds(self, {"min_count": Bound(1, 2**62, integer=True), "share": Bound(0.0, 1.0, lo_open=True),
                            "max_objects": Bound(1, 8, integer=True), "min_precision": Bound(0.0, 1.0),
                            "slack": Bound(-1.0, 1.0), "confidence_z": Bound(0.0, 10.0),
                            "sample": Bound(1, 2**31, integer=True), "seed": Bound(0, 2**63 - 1, integer=True),
                            "multi_min_count": Bound(0, 2**62, integer=True)})

    @staticmethod
    def from_preset(name: str, **overrides) -> "LearnedExportConfig":
        """A named preset (EXPORT_PRESETS) with optional field overrides."""
        return preset(EXPORT_PRESETS, name, "learned-export preset", **overrides)


EXPORT_PRESETS = {
    "intersection": LearnedExportConfig(),  # the follow-up's grouping: preconditions shared by every member
    # for noisy relations: shared by 90%, operators that mispredict (at 95% confidence) dropped, unneeded preconditions
    # dropped. On dev the confidence bound kept the success (0.825 / 0.85) and dropped 7 rare operators of 17,
    # a quarter of the ground operators at 8 objects
    "precise": LearnedExportConfig(share=0.9, min_precision=0.25, slack=0.05, confidence_z=1.96),
}
# as precise, and an operator per place for an effect that names other locations: a stick let go at l1 covers l0 and l2
EXPORT_PRESETS["placed"] = dataclasses.replace(EXPORT_PRESETS["precise"], placed=True)
# as placed, each operator for one place judged on the transitions at that place (LearnedExportConfig.by_place), and
# no deleted atom dropped from a precondition (keep_deleted: 10 of 54 operators dropped one, as "put a stick on ?o2"
# without (clear ?o2); dev 123 -> 125 of 142, bench/results/relations_dev_deletes.json)
EXPORT_PRESETS["carry"] = dataclasses.replace(EXPORT_PRESETS["placed"], by_place=True, keep_deleted=True)
# as carry, a stick carrying two riders from 10 transitions (LearnedExportConfig.multi_min_count); not shipped
EXPORT_PRESETS["carry-two"] = dataclasses.replace(EXPORT_PRESETS["carry"], multi_min_count=10)


def wilson_lower(hits: int, n: int, z: float) -> float:
    """The Wilson score interval's lower end for `hits` successes in `n` trials at z standard errors (0 if n is 0)."""
    if n == 0:
        return 0.0
    p = hits / n
    centre = p + z * z / (2 * n)
    spread = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return (centre - spread) / (1 + z * z / n)


def prune_dead_relations(transitions: list[Transition]) -> list[Transition]:
    """The transitions without the `nothing-rK` atoms (`clear`, `on-table` for `on`) of every head K that holds for no
    pair in any state: such a head learned nothing (training switched it off), and its negation, true of every
    object, only clutters the domain."""
    alive = {a[0] for t in transitions for a in t.pre | t.post}
    dead = {p for p in alive if p.startswith("nothing-") and p[len("nothing-"):] not in alive}
    if "on" not in alive:  # a rests-on head that never fired: clear and on-table are true of every object
        dead |= {"clear", "on-table"} & alive
    if not dead:
        return transitions
    keep = lambda atoms: frozenset(a for a in atoms if a[0] not in dead)  # noqa: E731
    return [Transition(keep(t.pre), keep(t.post), t.pick, t.release) for t in transitions]


def judged_on(op: Operator, placed: Sequence[tuple[dict[str, str], Transition]], shared: list[Transition],
              cfg: LearnedExportConfig) -> list[Transition]:
    """The transitions an operator's precision is judged on: with cfg.by_place and an operator for one place, up
    to cfg.sample of those at that place (`placed`: each transition with its location_binding); else the shared
    sample."""
    pins = {var: loc for _, var, loc in (a for a in op.precondition if a[0] == "=")}
    if not (cfg.by_place and pins):
        return shared
    here = [t for where, t in placed if all(where.get(v) == loc for v, loc in pins.items())]
    return here if len(here) <= cfg.sample else random.Random(cfg.seed).sample(here, cfg.sample)


def find_operators(transitions: Sequence[Transition], cfg: LearnedExportConfig) -> tuple[list[Operator], list[dict]]:
    """The operators of `transitions` (see LearnedExportConfig) and, per operator found, what became of it."""
    ops = learn_operators(transitions, cfg.min_count, cfg.share, cfg.max_objects, cfg.placed, cfg.multi_min_count)
    shared = list(transitions)
    if len(shared) > cfg.sample:
        shared = random.Random(cfg.seed).sample(shared, cfg.sample)
    placed = [(location_binding(t), t) for t in transitions] if cfg.by_place else []
    judge = cfg.min_precision or cfg.slack >= 0
    kept, notes = [], []
    for op in ops:
        sample = judged_on(op, placed, shared, cfg)
        applies, hits = precision([op], sample)[0] if judge else (0, 0)
        p = hits / applies if applies else 0.0
        low = wilson_lower(hits, applies, cfg.confidence_z)
        note = {"name": op.name, "count": op.count, "applies": applies, "predicts": hits, "precision": round(p, 3),
                "precision_low": round(low, 3)}
        if cfg.min_precision and low < cfg.min_precision:
            notes.append(note | {"kept": False})
            continue
        if cfg.slack >= 0:
            general = generalize(op, sample, cfg.slack, cfg.keep_deleted)
            note["dropped_preconditions"] = [list(a) for a in op.precondition if a not in general.precondition]
            op = general
        kept.append(op)
        moved = carried(op)
        notes.append(note | {"kept": True} | ({"carries": moved} if len(moved) > 1 else {}))
    return kept, notes


def export_learned(run_dir: Path, roots: Sequence[Path], cfg: LearnedExportConfig = LearnedExportConfig(),
                   comments: dict[str, str] | None = None) -> dict:
    """Write RUN/learned/{domain.pddl, operators.json, report.json}; returns the report."""
    run_dir = Path(run_dir)
    model, blob = load_relational(run_dir)
    transitions = prune_dead_relations(data_transitions(model, blob, roots, "train"))
    ops, notes = find_operators(transitions, cfg)
    report = {"operators": len(ops), "config": dataclasses.asdict(cfg), "min_count": cfg.min_count,
              "transitions": coverage(ops, transitions), "found": notes,
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


def run_hashes(run_dir: Path) -> dict[str, str]:
    """The sha256 of a run's relational model and of its learned operators: what a result read from them names."""
    return {"model_sha256": sha256_file(Path(run_dir) / CHECKPOINT),
            "operators_sha256": sha256_file(operators_path(run_dir))}


def load_operators(run_dir: Path) -> list[Operator]:
    """A run's learned operators, read by the bounded JSON reader; a missing or malformed file is refused in one
    line naming it."""
    path = operators_path(run_dir)
    if not path.is_file():
        raise ValueError(f"{path} is missing: run symlearn export-learned --run {run_dir} first")
    return operators_from_json(read_json_file(path, what="learned operators"), str(path))
