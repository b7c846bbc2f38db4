"""How well the rules, and the PDDL written from them, reproduce the network on enumerated cases.

rule_fidelity applies the Python rules (pddl_export.rules) to every enumerated case.
pddl_fidelity goes through the PDDL itself: for enumerated (scene, action) cases, the scene
becomes a PDDL state, the action named `pick-P-release-R` is applied by unified-planning's
SequentialSimulator, and the successor's codes are compared with the network's prediction
(an action the domain lacks must be a no-op of the network). This checks the written file, not the Python rules, so an encoding mistake
(such as two schemas of one real action that could both apply) shows up here.

    >>> fid = pddl_fidelity(domain_text, ruleset, enumeration, max_cases=500, seed=0)  # doctest: +SKIP
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pddl_export.enumeration import Enumeration
from pddl_export.pddl_writer import action_name, code_predicate, object_name, problem_pddl
from pddl_export.rules import RuleSet, apply_rules, apply_rules_batch


@dataclass(frozen=True)
class Mismatch:
    """One enumerated transition where the rules (or the PDDL written from them) and the network disagree."""

    codes: tuple[int, ...]
    action: int
    network: tuple[int, ...]
    rules: tuple[int, ...]

    def __post_init__(self) -> None:
        if not len(self.codes) == len(self.network) == len(self.rules):
            raise ValueError("codes, network and rules must describe the same objects")

    def as_row(self) -> list:
        """[codes, action, network's codes, rules' codes] as JSON lists (the report's row form)."""
        return [list(self.codes), self.action, list(self.network), list(self.rules)]


@dataclass(frozen=True)
class Fidelity:
    """Agreement of rules with the network over every enumerated (scene, action) pair."""

    n_transitions: int
    n_exact: int  # transitions where every object's next code agrees
    n_object_codes: int
    n_object_codes_exact: int
    mismatches: tuple[Mismatch, ...]  # the first few disagreements

    def __post_init__(self) -> None:
        if not (0 <= self.n_exact <= self.n_transitions and 0 <= self.n_object_codes_exact <= self.n_object_codes):
            raise ValueError("exact counts must lie between 0 and the totals")

    @property
    def fraction(self) -> float:
        """Share of transitions reproduced exactly (1.0 when there are none)."""
        return self.n_exact / self.n_transitions if self.n_transitions else 1.0



def rule_fidelity(rules: RuleSet, enumeration: Enumeration, reference: bool = False, max_mismatches: int = 10) -> Fidelity:
    """Compare the rules with the network on every enumerated case.

    reference=True applies the pure-Python apply_rules row by row (slow, for cross-checks).
    """
    n_tr = n_ex = n_obj = n_obj_ex = 0
    mismatches: list[Mismatch] = []
    for b in enumeration.blocks:
        states = b.states
        if reference:
            pred = np.stack([apply_rules(rules, s, int(a)) for s, a in zip(states, b.actions)])
        else:
            pred = apply_rules_batch(rules, states, b.actions)
        eq = pred == b.next_codes  # (S*36, k)
        n_tr += len(eq)
        n_ex += int(eq.all(1).sum())
        n_obj += eq.size
        n_obj_ex += int(eq.sum())
        for r in np.flatnonzero(~eq.all(1))[: max_mismatches - len(mismatches)]:
            mismatches.append(Mismatch(tuple(states[r].tolist()), int(b.actions[r]),
                                       tuple(b.next_codes[r].tolist()), tuple(pred[r].tolist())))
    return Fidelity(n_tr, n_ex, n_obj, n_obj_ex, tuple(mismatches))


@dataclass(frozen=True)
class PddlFidelity:
    """Agreement of the PDDL's successors with the network over the cases checked."""

    n_cases: int  # (scene, action) cases simulated
    n_agree: int
    n_enumerated: int  # all enumerated cases (the sample's population)
    disagreements: tuple[Mismatch, ...]  # the first few; `rules` holds the PDDL's successor

    @property
    def fraction(self) -> float:
        """Share of simulated cases whose PDDL successor equals the network's (1.0 when none)."""
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
                    bad.append(Mismatch(tuple(scene), a, tuple(want), tuple(got)))
    return PddlFidelity(n, agree, total, tuple(bad))
