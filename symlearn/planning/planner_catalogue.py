"""What each planner is, in words: its one-line description and its family, without importing any planner.

The registry (symlearn.planning.planners.PLANNERS) builds every planner and takes its description from here; the
CLI lists the families in `symlearn plan --help` and `benchmark --help` from here too, so that building the parser
does not import torch or the planners. `tests/test_cli.py` checks that the families cover the registry exactly.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

DEFAULT_PLANNER = "astar-outcomes"  # the recommended recipe's planner (docs/RESULTS.md, "Ablations")

DESCRIPTIONS: Mapping[str, str] = MappingProxyType({
    "astar": "learned-net A* with the mismatch heuristic",
    "astar-ucs": "learned-net uniform-cost search (shortest plans)",
    "astar-likely": "learned-net A*, each action costing 1 - w log P(its prediction): the plans most likely to "
                    "unfold as predicted",
    "astar-outcomes": "learned-net A* over each action's likely outcomes (all-outcomes determinization), each "
                      "costing 1 - w log P(that outcome)",
    "fast-downward": "Fast Downward on the conditional-effects PDDL domain",
    "symk": "SymK on the conditional-effects PDDL domain",
    "pyperplan": "pyperplan on the grounded STRIPS form of the problem",
    "fast-downward-opt": "optimal Fast Downward on the grounded STRIPS form",
    "fast-downward-blind": "Fast Downward, blind search, on the PDDL domain",
    "fast-downward-sas": "Fast Downward's search on a direct SAS+ task",
    "fast-downward-sas-opt": "optimal Fast Downward search on the SAS+ task",
    "symk-sas": "SymK's symbolic search on the same SAS+ task",
    "symk-sas-topk": "SymK top-k plans on the SAS+ task; execution falls back to the next plan when one departs",
    "fast-downward-sas-ms": "optimal A* with merge-and-shrink on the SAS+ task without axioms",
    "fast-downward-sas-lama": "LAMA's first iteration (FF and landmarks) on the SAS+ task without axioms",
    "rules-astar": "A* over the rules in process, batched expansions, code-distance heuristic",
    "rules-bfs": "breadth-first search over the rules in process: shortest plans, proves unreachable goals",
    "rules-outcomes": "A* over the rules and each object's second likeliest outcome (the exported all-outcomes "
                      "determinization), a deviation costing 1 - w log of its odds",
    "fast-downward-lifted": "stock Fast Downward (its translator, LAMA's first iteration) on the lifted domain",
    "fast-downward-lifted-opt": "stock Fast Downward, optimal A* with LM-cut, on the lifted domain",
    "fast-downward-lifted-outcomes": "stock Fast Downward, A* with LM-cut, on the lifted domain's all-outcomes cost "
                                     "form: each outcome of a rule an action costing by how often m(z) answered it",
})

# (family, its planners, what it searches and when to use it)
FAMILIES: tuple[tuple[str, tuple[str, ...], str], ...] = (
    ("learned net", ("astar-outcomes", "astar", "astar-likely", "astar-ucs"),
     "search m(z) itself; astar-outcomes (its likely outcomes) plans best, on any run"),
    ("lifted PDDL", ("fast-downward-lifted", "fast-downward-lifted-opt", "fast-downward-lifted-outcomes"),
     "the stock fast-downward.py on the lifted domain (export-pddl; m(z) with 9 location bits)"),
    ("rules in process", ("rules-outcomes", "rules-bfs", "rules-astar"),
     "search the exported rules (export-pddl --rules) in this process; rules-bfs proves unreachable goals"),
    ("SAS+ on the rules", ("fast-downward-sas", "fast-downward-sas-opt", "fast-downward-sas-ms",
                           "fast-downward-sas-lama", "symk-sas", "symk-sas-topk"),
     "Fast Downward's or SymK's search on a SAS+ task written from the rules, no translator"),
    ("PDDL via unified-planning", ("fast-downward", "fast-downward-blind", "fast-downward-opt", "symk", "pyperplan"),
     "the conditional-effects domain or its grounded STRIPS form: small runs, checks of the encoding"),
)


def planners_help() -> str:
    """Every planner by family, one line each: the epilog of `symlearn plan --help` and `benchmark --help`."""
    lines = ["planners, by family:"]
    for family, names, use in FAMILIES:
        lines.append(f"  {family}: {use}")
        lines += [f"    {name:<25} {DESCRIPTIONS[name]}" for name in names]
    return "\n".join(lines)
