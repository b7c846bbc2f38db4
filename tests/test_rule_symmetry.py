"""The rules' symmetry in objects: equal codes stay equal, permutations commute with actions, and the
searches that use both (coincidence dead ends, one state per orbit) keep reachability and optimal lengths.

Checked on random rule sets against exhaustive enumeration of the reachable states, and on the two
pretrained runs' rules (5-object states) for the two facts the searches rely on.
"""
from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from pddl_export.rule_successors import RuleSuccessors
from pddl_export.rules import apply_rules
from pddl_export.rules_io import load_rules
from pddl_export.symbolic import SymbolicGoal
from search.result import PlanStatus
from search.rule_symmetry import canonical, coincident, goal_classes, replay, split_pairs
from search.rules_search import plan_rules
from tests.test_overrides import VOCAB, random_rules
from tests.test_rules_search import _exhaustive, _replays_to_goal

ROOT = Path(__file__).resolve().parents[1] / "pretrained"


@pytest.mark.parametrize("run", ["quick-authors12k"])
def test_equal_codes_stay_equal_and_permutations_commute_on_pretrained_rules(run):
    rules, _ = load_rules(ROOT / run)
    succ = RuleSuccessors(rules)
    rng = np.random.default_rng(0)
    vocab = np.array(rules.vocabulary)
    states = vocab[rng.integers(0, len(vocab), (3000, 5))]
    states[:1500, 3] = states[:1500, 1]  # half the states hold a coincident pair
    nxt = succ(states)
    moved = (nxt != states[:, None, :]).any(axis=2)
    assert moved[:1500].any(), "some coincident pair must move, or the check says nothing"
    assert np.array_equal(nxt[:1500, :, 1], nxt[:1500, :, 3])
    perm = rng.permutation(5)
    assert np.array_equal(succ(states[:, perm]), nxt[:, :, perm])


@pytest.mark.parametrize("seed", range(8))
def test_coincidence_dead_ends_are_sound(seed):
    rng = np.random.default_rng(300 + seed)
    rules = random_rules(rng, n=16)
    checked = 0
    for _ in range(30):
        init = [int(c) for c in rng.choice(VOCAB, 3)]
        init[2] = init[0]
        goal = SymbolicGoal(tuple(int(c) for c in rng.choice(VOCAB, 3)))
        if coincident(np.array([init]), split_pairs(goal.codes))[0]:
            assert _exhaustive(rules, init, goal) is None
            res = plan_rules(rules, init, goal, "bfs", timeout_s=5)
            assert res.status is PlanStatus.UNSOLVABLE and res.extra["proof"] == "coincidence"
            assert "hold the same code" in res.message
            checked += 1
    assert checked >= 3


@pytest.mark.parametrize("seed", range(10))
def test_orbit_search_keeps_status_and_optimal_length(seed):
    rng = np.random.default_rng(400 + seed)
    rules = random_rules(rng, n=24)
    for _ in range(8):
        k = int(rng.integers(3, 5))
        init = [int(c) for c in rng.choice(VOCAB, k)]
        codes = [int(c) if rng.random() < 0.6 else None for c in rng.choice(VOCAB[:2], k)]  # repeats and free objects
        codes[0] = int(rng.choice(VOCAB))
        goal = SymbolicGoal(tuple(codes))
        best = _exhaustive(rules, init, goal)
        for method in ("bfs", "astar"):
            on = plan_rules(rules, init, goal, method, timeout_s=10)
            off = plan_rules(rules, init, goal, method, timeout_s=10, symmetry=False)
            assert on.status is off.status is (PlanStatus.UNSOLVABLE if best is None else PlanStatus.SOLVED)
            if best is not None:
                assert _replays_to_goal(rules, init, on.plan, on.predicted_states, goal)
                if method == "bfs":
                    assert len(on.plan) == len(off.plan) == best


def test_canonical_sorts_within_goal_classes_and_replay_walks_the_real_objects():
    goal = (2, None, 2, 1, None)
    assert [c.tolist() for c in goal_classes(goal)] == [[0, 2], [1, 4]]
    states = np.array(list(itertools.product(VOCAB, repeat=5)))
    canon = canonical(states, goal_classes(goal))
    assert (canon[:, 0] <= canon[:, 2]).all() and (canon[:, 1] <= canon[:, 4]).all()
    assert np.array_equal(canon[:, 3], states[:, 3])
    assert len(np.unique(canon, axis=0)) == 10 * 10 * 4  # 10 multisets of 2 codes per class, 4 codes for object 3
    rules = random_rules(np.random.default_rng(5), n=20)
    succ = RuleSuccessors(rules)
    start, plan = [0, 3, 1, 2, 0], [int(a) for a in succ.actions[:3]]
    walked = [tuple(start)]
    for a in plan:
        walked.append(tuple(apply_rules(rules, walked[-1], a).tolist()))
    assert list(replay(succ, succ.actions, start, plan)) == walked
