"""Pair projections of the rules (search.rule_abstraction): sound proofs that a goal is out of reach."""
from __future__ import annotations

import numpy as np
import pytest

from pddl_export.rules import Rule, RuleSet
from pddl_export.symbolic import SymbolicGoal
from search.rule_abstraction import pair_unreachable, reachable_codes
from search.rules_search import UNREACHABLE, code_distances, plan_rules
from search.result import PlanStatus
from tests.test_overrides import VOCAB, random_rules
from tests.test_rules_search import _exhaustive


def test_pair_proofs_are_sound_and_beat_the_code_graph():
    proved = stronger = 0
    for seed in range(10):
        rng = np.random.default_rng(300 + seed)
        rules = random_rules(rng, n=int(rng.integers(8, 20)))
        proved_s, stronger_s = _proofs(rng, rules)
        proved, stronger = proved + proved_s, stronger + stronger_s
    # pairs prove goals out of reach that the context-free code graph calls reachable
    assert stronger >= 3 and proved > stronger, (proved, stronger)


def _proofs(rng, rules) -> tuple[int, int]:
    """Random starts and goals: every pair proof checked by enumeration; (proofs, proofs the code graph misses)."""
    proved = stronger = 0
    for _ in range(12):
        k = int(rng.integers(2, 5))
        init = [int(c) for c in rng.choice(VOCAB, k)]
        codes = [int(c) if rng.random() < 0.7 else None for c in rng.choice(VOCAB, k)]
        codes[0] = int(rng.choice(VOCAB))  # a goal fixes at least one object
        goal = SymbolicGoal(tuple(codes))
        proof = pair_unreachable(rules, init, goal)
        if proof is not None:  # a proof must be right: no goal state among the states the rules reach
            assert _exhaustive(rules, init, goal) is None
            assert goal.codes[proof[0]] is not None or goal.codes[proof[1]] is not None
            proved += 1
            table = code_distances(rules, goal)
            stronger += not (table[np.arange(k), init] >= UNREACHABLE).any()
    return proved, stronger


def test_pairs_keep_what_contexts_forbid():
    # code 1 -> 2 under action 5 unless another object has code 3; code 3 never changes
    rs = RuleSet(bits=2, vocabulary=(1, 2, 3), max_objects=3, n_rules_before_generalization=1,
                 rules=(Rule(action=5, code_from=1, code_to=2, forbids=(3,)), Rule(action=7, code_from=2, code_to=1)))
    goal = SymbolicGoal((2, None, None))
    assert pair_unreachable(rs, [1, 3, 1], goal) == (0, 1)  # object 1 stays 3 and always forbids the rule
    assert code_distances(rs, goal)[0, 1] == 1  # the code graph alone calls it one step away
    assert pair_unreachable(rs, [1, 1, 1], goal) is None
    r = plan_rules(rs, [1, 3, 1], goal, "bfs", timeout_s=5, pair_proof=True)
    assert r.status is PlanStatus.UNSOLVABLE and "pair projection" in r.message and r.extra["generated"] == 0
    plain = plan_rules(rs, [1, 3, 1], goal, "bfs", timeout_s=5)  # without it: by exhausting the states
    assert plain.status is PlanStatus.UNSOLVABLE and plain.extra["generated"] > 0
    assert reachable_codes(rs, [1, 3]) == [{1, 2}, {3}]
    with pytest.raises(ValueError, match="do not match"):
        pair_unreachable(rs, [1, 3], goal)


def test_at_least_and_fewer_than_counts_use_what_the_others_may_and_must_hold():
    # 1 -> 2 needs at least two others with code 3; 1 -> 3 needs fewer than two others with code 2
    rs = RuleSet(bits=2, vocabulary=(1, 2, 3), max_objects=4, n_rules_before_generalization=1,
                 rules=(Rule(action=1, code_from=1, code_to=2, at_least=((3, 2),)),
                        Rule(action=2, code_from=1, code_to=3, fewer_than=((2, 2),))))
    assert pair_unreachable(rs, [1, 3, 3], SymbolicGoal((2, None, None))) is None  # two others hold 3
    assert pair_unreachable(rs, [1, 3, 2], SymbolicGoal((2, None, None))) is not None  # only one may hold 3
    assert _exhaustive(rs, [1, 3, 2], SymbolicGoal((2, None, None))) is None
    assert pair_unreachable(rs, [1, 2, 2, 2], SymbolicGoal((3, None, None, None))) is not None  # three must hold 2
    assert pair_unreachable(rs, [1, 2, 3, 3], SymbolicGoal((3, None, None, None))) is None
