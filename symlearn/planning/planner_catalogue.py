"""The planner registry: one entry per planner, saying what it is, why it is kept, what it reads from a run and how
it is built, without importing any planner.

Every place that names planners reads this table: `symlearn.planning.planners` builds them from it
(`make_planner`), the CLI writes the epilog of `symlearn plan --help` and `benchmark --help` from it (so that
building the parser does not import torch or the planners), README's planner table is written from it
(`planners_markdown`; tests/test_planner_registry.py checks it), and the examples list planners by its families.
Adding a planner is one PlannerEntry here and its builder in symlearn.planning.planners.

The planners' own settings are a PlannerConfig (`[planner]` in a settings file), which the registry builds every
planner from; execution settings (symlearn.planning.execution.ExecutionConfig) say how plans are run.
"""
from __future__ import annotations

import importlib
import textwrap
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Callable, Mapping

from symlearn.config_file import Bound, check_bounds

DEFAULT_PLANNER = "astar-outcomes"  # the recommended recipe's planner (docs/RESULTS.md, "Ablations")

# run files a planner reads beyond the effect model (best.pt), and the command that writes each
TRANSITION = "transition.pt"
RULES = "pddl/rules.json"
OUTCOMES = "pddl/outcomes.json"
LIFTED = "pddl/lifted.json"
MADE_BY: Mapping[str, str] = MappingProxyType({
    TRANSITION: "symlearn train-transition", RULES: "symlearn export-pddl --rules",
    OUTCOMES: "symlearn export-pddl --rules", LIFTED: "symlearn export-pddl (m(z) with 9 location bits)"})


@dataclass(frozen=True)
class PlannerConfig:
    """The planners' own settings, the same for every planner of a call (`[planner]` in a settings file).

    risk_weight is the weight W of the planners that weigh how likely an outcome is (RISK_PLANNERS): astar-outcomes
    charges each outcome 1 + W * (-log P(that outcome)), rules-outcomes a second outcome W times its extra -log P.
    """

    risk_weight: float = 1.0

    def __post_init__(self) -> None:
        """Refuse a weight no planner can use (the check of [planner] risk_weight in a settings file too)."""
        check_bounds(self, PLANNER_BOUNDS)


PLANNER_BOUNDS = {"risk_weight": Bound(0.0, 1e6, lo_open=True)}


@dataclass(frozen=True)
class PlannerEntry:
    """One planner: its family, what it does (purpose), the distinct reason it is kept, the run files it reads
    (`needs`, beyond best.pt) and its builder ("module:function", (PlannerContext) -> planner function)."""

    name: str
    family: str
    purpose: str
    reason: str
    needs: tuple[str, ...]
    build: str

    @property
    def needs_rules(self) -> bool:
        """Whether it plans on the exported whole-code rules (RUN/pddl/rules.json)."""
        return RULES in self.needs

    @property
    def needs_lifted(self) -> bool:
        """Whether it plans on the lifted domain (RUN/pddl/lifted.json)."""
        return LIFTED in self.needs

    def builder(self) -> Callable[[Any], Any]:
        """The function that builds this planner from a PlannerContext (its module imported only now)."""
        module, _, name = self.build.partition(":")
        return getattr(importlib.import_module(module), name)


_BUILD = "symlearn.planning.planners:"
_NET, _LIFTED_PDDL, _RULES_IN_PROCESS, _UP = ("learned net", "lifted PDDL", "rules in process",
                                              "PDDL via unified-planning")

# (family, what it searches and when to use it), in the order --help and README list them
FAMILIES: tuple[tuple[str, str], ...] = (
    (_NET, "m(z) itself, on any run"),
    (_LIFTED_PDDL, "the lifted domain through the stock fast-downward.py, as a user outside the project would run it"),
    (_RULES_IN_PROCESS, "the exported whole-code rules, searched in this process (no location bits needed)"),
    (_UP, "the rules' PDDL through unified-planning: comparing planners on one encoding"),
)

_ENTRIES = (
    PlannerEntry("astar-outcomes", _NET,
                 "A* on m(z) over each action's likely outcomes (all-outcomes determinization), an outcome costing "
                 "1 + W (-log P)", "the recipe's planner and the learned-net A* baseline the exported domain is "
                 "checked against; plans best", (TRANSITION,), _BUILD + "build_astar_outcomes"),
    PlannerEntry("astar", _NET, "A* on m(z)'s likeliest prediction with the code-mismatch heuristic",
                 "the plain learned-net search of the paper (the paper preset's first planner): the fastest",
                 (TRANSITION,), _BUILD + "build_astar"),
    PlannerEntry("astar-ucs", _NET, "uniform-cost search on m(z)'s likeliest prediction",
                 "the shortest plan m(z) predicts: the plan-length reference on the network", (TRANSITION,),
                 _BUILD + "build_astar_ucs"),
    PlannerEntry("fast-downward-lifted", _LIFTED_PDDL,
                 "stock Fast Downward (its translator, LAMA's first iteration) on the lifted domain",
                 "the recipe's classical planner on what was learned", (TRANSITION, LIFTED),
                 _BUILD + "build_lifted_lama"),
    PlannerEntry("fast-downward-lifted-opt", _LIFTED_PDDL, "stock Fast Downward, A* with LM-cut, on the lifted domain",
                 "optimal plans on the exported domain: the length reference for fast-downward-lifted",
                 (TRANSITION, LIFTED), _BUILD + "build_lifted_opt"),
    PlannerEntry("fast-downward-lifted-outcomes", _LIFTED_PDDL,
                 "stock Fast Downward, A* with LM-cut, on the lifted domain's all-outcomes cost form",
                 "astar-outcomes' counterpart on the exported domain: each outcome of a rule an action costing by "
                 "how often m(z) answered it", (TRANSITION, LIFTED), _BUILD + "build_lifted_outcomes"),
    PlannerEntry("rules-outcomes", _RULES_IN_PROCESS,
                 "A* over the rules and each object's second likeliest outcome, a deviation costing W times its "
                 "extra -log P", "the paper's whole-code rules route, the exported form of astar-outcomes; needs no "
                 "location bits", (TRANSITION, RULES, OUTCOMES), _BUILD + "build_rules_outcomes"),
    PlannerEntry("rules-bfs", _RULES_IN_PROCESS, "breadth-first search over the rules, a whole layer per step",
                 "shortest plans on the rules, and proofs that a goal is out of their reach", (TRANSITION, RULES),
                 _BUILD + "build_rules_bfs"),
    PlannerEntry("fast-downward", _UP,
                 "Fast Downward through unified-planning on the rules' conditional-effects PDDL domain",
                 "the unified-planning route (OneshotPlanner), which runs any PDDL planner it knows on the learned "
                 "rules; checks their PDDL encoding", (TRANSITION, RULES), _BUILD + "build_up_fast_downward"),
    PlannerEntry("pyperplan", _UP, "pyperplan through unified-planning on the rules' grounded STRIPS form",
                 "a second, independent planner (pure Python) for comparing planners on the same task",
                 (TRANSITION, RULES), _BUILD + "build_up_pyperplan"),
)

PLANNERS: Mapping[str, PlannerEntry] = MappingProxyType({e.name: e for e in _ENTRIES})
# the planners whose plans depend on PlannerConfig.risk_weight
RISK_PLANNERS = ("astar-outcomes", "rules-outcomes")


def planner_entry(name: str) -> PlannerEntry:
    """The registry entry of `name`, or a one-line ValueError listing every planner."""
    if name not in PLANNERS:
        raise ValueError(f"unknown planner {name!r}; known: {', '.join(PLANNERS)}")
    return PLANNERS[name]


def by_family() -> list[tuple[str, str, list[PlannerEntry]]]:
    """(family, what it searches, its entries) in the registry's order."""
    return [(family, use, [e for e in _ENTRIES if e.family == family]) for family, use in FAMILIES]


def planners_help() -> str:
    """Every planner by family, its purpose and why it is kept: the epilog of `symlearn plan --help` and
    `benchmark --help`."""
    lines = ["planners, by family:"]
    for family, use, entries in by_family():
        lines.append(f"  {family}: {use}")
        for e in entries:
            text = textwrap.wrap(f"{e.purpose}. Why: {e.reason}. Reads {', '.join(e.needs)}.", 84)
            lines += [f"    {e.name:<30} {text[0]}"] + [f"{'':<35}{t}" for t in text[1:]]
    return "\n".join(lines)


def planners_markdown() -> str:
    """README's planner table: one row per planner, written from the registry (tests check README holds it)."""
    rows = ["| planner | family | what it does | why it is kept | reads from the run (made by) |",
            "| --- | --- | --- | --- | --- |"]
    for family, _, entries in by_family():
        rows += [f"| `{e.name}` | {family} | {e.purpose} | {e.reason} | "
                 f"{'; '.join(f'`{n}` ({MADE_BY[n]})' for n in e.needs)} |" for e in entries]
    return "\n".join(rows)
