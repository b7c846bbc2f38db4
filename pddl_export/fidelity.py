"""Fidelity computed through the PDDL itself: unified-planning's simulator against the network.

For enumerated (scene, action) cases, the scene becomes a PDDL state, the action named
`pick-P-release-R` is applied by unified-planning's SequentialSimulator, and the successor's
codes are compared with the network's prediction (an action the domain lacks must be a no-op
of the network). This checks the written file, not the Python rules, so an encoding mistake
(such as two schemas of one real action that could both apply) shows up here.

    >>> fid = pddl_fidelity(domain_text, ruleset, enumeration, max_cases=500, seed=0)  # doctest: +SKIP
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pddl_export.enumeration import Enumeration
from pddl_export.pddl_writer import action_name, code_predicate, object_name, problem_pddl
from pddl_export.rules import RuleSet


@dataclass(frozen=True)
class PddlFidelity:
    """Agreement of the PDDL's successors with the network over the cases checked."""

    n_cases: int  # (scene, action) cases simulated
    n_agree: int
    n_enumerated: int  # all enumerated cases (the sample's population)
    disagreements: tuple[tuple[tuple[int, ...], int, tuple[int, ...], tuple[int, ...]], ...]  # first few

    @property
    def fraction(self) -> float:
        return self.n_agree / self.n_cases if self.n_cases else 1.0


def parse_pddl(domain: str, problem: str):
    """unified-planning's reading of a domain and problem, with the credits banner silenced."""
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import get_environment

    get_environment().credits_stream = None
    return PDDLReader().parse_problem_string(domain, problem)


def pddl_fidelity(domain: str, rules: RuleSet, enumeration: Enumeration, max_cases: int | None = None,
                  seed: int = 0, keep: int = 10) -> PddlFidelity:
    """Simulate enumerated cases through the PDDL domain; all of them, or a seeded sample of max_cases."""
    from unified_planning.model.state import UPState
    from unified_planning.shortcuts import SequentialSimulator

    total = enumeration.n_queries
    rng = np.random.default_rng(seed)
    take = None if max_cases is None or max_cases >= total else set(rng.choice(total, max_cases, replace=False).tolist())
    n = agree = offset = 0
    bad = []
    for b in enumeration.blocks:
        k = b.n_objects
        rows = range(len(b.actions)) if take is None else [i - offset for i in take if offset <= i < offset + len(b.actions)]
        offset += len(b.actions)
        if not rows:
            continue
        first = b.states[0].tolist()
        prob = parse_pddl(domain, problem_pddl(rules, first, [first[0]] + [None] * (k - 1), "fidelity"))
        em = prob.environment.expression_manager
        objs = [prob.object(object_name(i)) for i in range(k)]
        fluents = {c: prob.fluent(code_predicate(c, rules.bits)) for c in rules.codes}
        acts = {a.name: a for a in prob.actions}
        with SequentialSimulator(prob) as sim:
            for i in sorted(rows):
                scene, a, want = b.states[i].tolist(), int(b.actions[i]), b.next_codes[i].tolist()
                n += 1
                act = acts.get(action_name(a))
                if act is None:
                    got = scene
                else:
                    state = UPState({fluents[c](o): em.Bool(scene[j] == c) for j, o in enumerate(objs) for c in fluents},
                                    prob)
                    nxt = sim.apply(state, act, ())
                    held = [[c for c in fluents if nxt.get_value(fluents[c](o)).bool_constant_value()] for o in objs]
                    got = [h[0] if len(h) == 1 else -1 for h in held]  # -1: no code or several codes
                if got == want:
                    agree += 1
                elif len(bad) < keep:
                    bad.append((tuple(scene), a, tuple(want), tuple(got)))
    return PddlFidelity(n, agree, total, tuple(bad))
