"""Rule overrides: observed steps replace exactly their cases, everything else keeps the rules' outcome.

Checked by enumeration: every state of K objects over a small vocabulary, every action with rules,
before and after overriding random rule sets with random observations; and by planning on the
overridden rules (conditional PDDL, blind A*: shortest plans) around a disproven step.
"""
from __future__ import annotations

import itertools
from collections import Counter

import numpy as np
import pytest

from pddl_export.overrides import box_difference, observed_cases, override_rules, override_rules_info
from pddl_export.pddl_writer import conditional_domain, problem_pddl
from pddl_export.rules import INF, Rule, RuleSet, apply_rules, apply_rules_batch
from pddl_export.symbolic import SymbolicGoal
from search.classical import solve_pddl
from search.result import PlanStatus

VOCAB = (0, 1, 2, 3)
ACTIONS = (4, 17)


def _random_bounds(rng) -> dict[int, tuple[int, int]]:
    out = {}
    for x in rng.choice(VOCAB, size=rng.integers(0, 3), replace=False):
        lo = int(rng.integers(0, 3))
        hi = int(rng.choice([lo + 1, lo + 2, INF]))
        if (lo, hi) != (0, INF):
            out[int(x)] = (lo, hi)
    return out


def random_rules(rng, n: int = 14) -> RuleSet:
    """A random mutually exclusive rule set: candidate rules that would overlap their group are dropped."""
    rules: list[Rule] = []
    for _ in range(n):
        a, c = int(rng.choice(ACTIONS)), int(rng.choice(VOCAB))
        to = int(rng.choice([x for x in VOCAB if x != c]))
        cand = Rule.from_bounds(a, c, to, _random_bounds(rng))
        try:
            RuleSet(bits=2, vocabulary=VOCAB, max_objects=3, rules=tuple(rules + [cand]),
                    n_rules_before_generalization=0)
        except ValueError:
            continue
        rules.append(cand)
    return RuleSet(bits=2, vocabulary=VOCAB, max_objects=3, rules=tuple(rules), n_rules_before_generalization=0)


def _case(state, i: int, action: int):
    others = Counter(state)
    others[state[i]] -= 1
    return action, state[i], tuple(sorted((x, n) for x, n in others.items() if n > 0))


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("k", [2, 3])
def test_overrides_are_exact_on_every_state_of_the_same_size(seed, k):
    rng = np.random.default_rng([seed, k])
    rules = random_rules(rng)
    states = list(itertools.product(VOCAB, repeat=k))
    observed: dict = {}
    for _ in range(int(rng.integers(1, 6))):
        s = states[int(rng.integers(len(states)))]
        observed.setdefault(s, {})[int(rng.choice(ACTIONS))] = tuple(int(c) for c in rng.choice(VOCAB, size=k))
    fixed, info = override_rules_info(rules, observed)
    cases, conflicts = observed_cases(observed)
    assert info.cases == len(cases) and info.conflicts == conflicts
    RuleSet(bits=fixed.bits, vocabulary=fixed.vocabulary, max_objects=fixed.max_objects, rules=fixed.rules,
            n_rules_before_generalization=0)  # the exclusivity check, once more on the bare rules
    pairs = [(s, a) for s in states for a in ACTIONS]
    batch = apply_rules_batch(fixed, np.array([s for s, _ in pairs]), np.array([a for _, a in pairs]))
    n_overridden = 0
    for (s, a), got_batch in zip(pairs, batch.tolist()):
        before = apply_rules(rules, s, a).tolist()
        want = [cases.get(_case(s, i, a), before[i]) for i in range(k)]
        if s in observed and a in observed[s] and not any(_case(s, i, a) in conflicts for i in range(k)):
            assert want == list(observed[s][a])
        n_overridden += want != before
        assert apply_rules(fixed, s, a).tolist() == want == got_batch, (s, a)
    clean = [(s, a) for s in observed for a in observed[s] if not any(_case(s, i, a) in conflicts for i in range(k))]
    if any(observed[s][a] != tuple(apply_rules(rules, s, a).tolist()) for s, a in clean):
        assert n_overridden > 0  # some observation disagreed with the rules, and it shows


def test_equal_codes_going_apart_are_reported_and_left_alone():
    rules = RuleSet(bits=2, vocabulary=VOCAB, max_objects=3, n_rules_before_generalization=0,
                    rules=(Rule(action=4, code_from=1, code_to=2),))
    fixed, info = override_rules_info(rules, {(1, 1, 0): {4: (2, 3, 0)}})
    assert info.conflicts == ((4, 1, ((0, 1), (1, 1))),)
    assert apply_rules(fixed, (1, 1, 0), 4).tolist() == [2, 2, 0]  # the conflicting case keeps its rule
    assert apply_rules(fixed, (1, 1, 3), 4).tolist() == [2, 2, 3]


def test_box_difference_covers_the_rest_disjointly():
    r, b = {0: (1, INF), 2: (0, 2)}, {0: (1, 2), 1: (0, 1)}
    pieces = box_difference(r, b)
    assert len(pieces) <= 2 * len(b)
    inside = lambda box, cnt: all(lo <= cnt.get(x, 0) < hi for x, (lo, hi) in box.items())  # noqa: E731
    for cnt in (dict(zip((0, 1, 2), c)) for c in itertools.product(range(4), repeat=3)):
        hits = sum(inside(p, cnt) for p in pieces)
        assert hits == (inside(r, cnt) and not inside(b, cnt)), cnt
    assert box_difference(r, {0: (0, 1)}) == [r]  # disjoint: unchanged


# --------------------------------------------------------------------------- planning on overridden rules

# Action 4 moves a 1 to 3 directly; action 17 moves 1 -> 2 and 2 -> 3 (two steps). Execution then showed
# that action 4 does nothing when the other object has code 0: the planners must take the long way.
DETOUR = RuleSet(bits=2, vocabulary=VOCAB, max_objects=2, n_rules_before_generalization=0,
                 rules=(Rule(action=4, code_from=1, code_to=3), Rule(action=17, code_from=1, code_to=2),
                        Rule(action=17, code_from=2, code_to=3)))
DISPROVEN = {(1, 0): {4: (1, 0)}}


def _replay(rules, init, plan):
    states = [tuple(init)]
    for a in plan:
        states.append(tuple(apply_rules(rules, states[-1], a).tolist()))
    return states


def _solve(rules: RuleSet, init: list[int], goal: SymbolicGoal):
    return solve_pddl(conditional_domain(rules, "h"), problem_pddl(rules, init, goal, "h"), "fast-downward-blind",
                      timeout_s=20)


def test_pddl_plans_follow_the_overrides():
    fixed = override_rules(DETOUR, DISPROVEN)
    goal = SymbolicGoal((3, None))
    assert apply_rules(fixed, (1, 0), 4).tolist() == [1, 0] and apply_rules(fixed, (1, 2), 4).tolist() == [3, 2]
    before = _solve(DETOUR, [1, 0], goal)
    assert before.status is PlanStatus.SOLVED and before.plan == (4,)
    pddl = _solve(fixed, [1, 0], goal)
    assert pddl.status is PlanStatus.SOLVED and pddl.plan == (17, 17), pddl.message
    states = _replay(fixed, (1, 0), pddl.plan)
    assert goal.satisfied(np.array(states[-1]))[0] and (4 not in pddl.plan)
    assert pddl.predicted_states == tuple(states)
    elsewhere = _solve(fixed, [1, 2], goal)
    assert elsewhere.plan == (4,)  # with a 2 beside it, action 4 was never disproven
