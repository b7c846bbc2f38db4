"""In-process search over the exported rules: compiled successors, batched A*, layered BFS, dead ends.

RuleSuccessors is checked against apply_rules_batch and apply_rules on random rule sets
and on the pretrained run's rules; the searches against exhaustive enumeration of the reachable
states (reachable_transitions + networkx shortest paths): same reachability, optimal lengths for
BFS, valid plans for A*, and the code-distance dead-end test never cuts off a reachable goal.
"""
from __future__ import annotations

import itertools
import math
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

from pddl_export.pddl_writer import reachable_transitions
from pddl_export.rule_successors import RuleSuccessors, pack_states
from pddl_export.rules import apply_rules, apply_rules_batch
from pddl_export.rules_io import load_rules
from pddl_export.symbolic import SymbolicGoal
from search.astar import astar
from search.batched_bfs import breadth_first
from search.result import PlanStatus
from search.rules_search import UNREACHABLE, code_distances, plan_rules
from symlearn.planning.execution import ObservedTransitions
from symlearn.planning.planners import PlannerContext, RulesTransition, make_planner
from tests.test_overrides import DETOUR, DISPROVEN, VOCAB, random_rules

PRETRAINED = Path(__file__).resolve().parents[1] / "pretrained" / "quick-authors12k"


def _reference(rules, states: np.ndarray, actions: np.ndarray) -> np.ndarray:
    k = states.shape[1]
    return apply_rules_batch(rules, np.repeat(states, len(actions), 0), np.tile(actions, len(states))).reshape(
        len(states), len(actions), k)


@pytest.mark.parametrize("seed", range(10))
def test_compiled_successors_equal_the_reference_semantics(seed):
    rng = np.random.default_rng(seed)
    rules = random_rules(rng, n=20)
    succ = RuleSuccessors(rules, chunk=7)  # several chunks per call
    for k in (1, 2, 3, 4):
        states = np.array(list(itertools.product(VOCAB, repeat=k)), np.int64)
        assert np.array_equal(succ(states), _reference(rules, states, succ.actions)), k
        if k <= 2:  # and the row-by-row semantics, independent of both batched forms
            rows = [[apply_rules(rules, s, int(a)) for a in succ.actions] for s in states]
            assert np.array_equal(succ(states), np.array(rows).reshape(len(states), len(succ.actions), k)), k


def test_remembered_contexts_answer_as_fresh_ones_also_after_the_memo_starts_afresh(monkeypatch):
    import pddl_export.rule_successors as rs_module

    rng = np.random.default_rng(3)
    rules = random_rules(rng, n=30)
    states = np.array(list(itertools.product(VOCAB, repeat=3)), np.int64)
    want = _reference(rules, states, RuleSuccessors(rules).actions)
    succ = RuleSuccessors(rules)
    first = succ(states)
    assert len(succ._memo) > 0 and np.array_equal(first, want)
    assert np.array_equal(succ(states[::-1]), want[::-1])  # every context now from the memo
    monkeypatch.setattr(rs_module, "MEMO_SIZE", 3)  # a tiny memo: cleared over and over within one call
    small = RuleSuccessors(rules)
    for part in (slice(0, 40), slice(20, 90), slice(None)):  # overlapping batches: some contexts known, some new
        assert np.array_equal(small(states[part]), want[part])
    assert len(small._memo) <= 3 + len(states) * 3
    monkeypatch.setattr(rs_module, "MEMO_SIZE", 1)  # one context known, one new: the memo is cleared between them
    c = next(c for c, group in small._groups.items() if len(group[0]))  # a code whose rules count others
    contexts = np.unique(np.random.default_rng(0).integers(0, 3, (40, len(small._groups[c][0]))).astype(np.int16), axis=0)
    fresh = [RuleSuccessors(rules)._fired(c, contexts[i:i + 1]) for i in range(2)]
    small._fired(c, contexts[:1])
    acts, tos, starts, sizes = small._fired(c, contexts[:2])
    for i, (a, t, _, _) in enumerate(fresh):
        got = slice(starts[i], starts[i] + sizes[i])
        assert np.array_equal(acts[got], a) and np.array_equal(tos[got], t)


def test_compiled_successors_on_the_pretrained_rules():
    rules, _ = load_rules(PRETRAINED)
    succ = RuleSuccessors(rules)
    rng = np.random.default_rng(0)
    vocab = np.array(rules.vocabulary + (5,))  # 5: a code no rule names, inert
    for k in (1, 3, 5):
        states = vocab[rng.integers(0, len(vocab), (400, k))]
        out = succ(states)
        assert out.shape == (400, len(rules.actions), k)
        assert np.array_equal(out, _reference(rules, states, succ.actions))
        assert (out != states[:, None, :]).any(), "some rule must fire on 400 random states"


def test_packed_keys_are_unique_per_state_and_refuse_overflow():
    states = np.array(list(itertools.product(range(4), repeat=3)), np.int64)
    assert len(np.unique(pack_states(states, 2))) == len(states)
    with pytest.raises(ValueError, match="at most 7 objects"):
        pack_states(np.zeros((1, 8), np.int64), 8)


def _exhaustive(rules, init, goal):
    """Shortest plan length to goal under the rules by enumeration (None if unreachable)."""
    states, edges = reachable_transitions(rules, init)
    g = nx.DiGraph()
    g.add_nodes_from(range(len(states)))
    g.add_edges_from((i, j) for i, _, j in edges)
    hits = [i for i, s in enumerate(states) if all(c is None or s[k] == c for k, c in enumerate(goal.codes))]
    lengths = nx.single_source_shortest_path_length(g, 0)
    reachable = [lengths[i] for i in hits if i in lengths]
    return min(reachable) if reachable else None


def _replays_to_goal(rules, init, plan, states, goal) -> bool:
    cur = tuple(init)
    walked = [cur]
    for a in plan:
        cur = tuple(apply_rules(rules, cur, a).tolist())
        walked.append(cur)
    return walked == list(states) and all(c is None or cur[k] == c for k, c in enumerate(goal.codes))


@pytest.mark.parametrize("seed", range(12))
def test_bfs_is_optimal_and_astar_valid_against_enumeration(seed):
    rng = np.random.default_rng(100 + seed)
    rules = random_rules(rng, n=24)
    k = int(rng.integers(2, 4))
    for _ in range(6):
        init = [int(c) for c in rng.choice(VOCAB, k)]
        codes = [int(c) if rng.random() < 0.7 else None for c in rng.choice(VOCAB, k)]
        codes[0] = int(rng.choice(VOCAB))  # a goal fixes at least one object
        goal = SymbolicGoal(tuple(codes))
        best = _exhaustive(rules, init, goal)
        bfs = plan_rules(rules, init, goal, "bfs", timeout_s=10)
        if best is None:
            assert bfs.status is PlanStatus.UNSOLVABLE
        else:
            assert bfs.status is PlanStatus.SOLVED and len(bfs.plan) == best
            assert _replays_to_goal(rules, init, bfs.plan, bfs.predicted_states, goal)
        for batch, weight in ((1, 1.0), (5, 1.0), (5, 2.0)):
            a = plan_rules(rules, init, goal, "astar", timeout_s=10, batch=batch, weight=weight)
            assert a.status is (PlanStatus.UNSOLVABLE if best is None else PlanStatus.SOLVED)
            if best is not None:
                assert len(a.plan) >= best
                assert _replays_to_goal(rules, init, a.plan, a.predicted_states, goal)


@pytest.mark.parametrize("seed", range(6))
def test_code_distance_dead_ends_are_sound(seed):
    rng = np.random.default_rng(200 + seed)
    rules = random_rules(rng, n=10)
    for _ in range(10):
        init = tuple(int(c) for c in rng.choice(VOCAB, 3))
        goal = SymbolicGoal(tuple(int(c) for c in rng.choice(VOCAB, 3)))
        table = code_distances(rules, goal)
        assert table.shape == (3, 4)
        more = random_rules(rng, n=6)  # the code graph read off the rules or given, with a second rule set
        assert np.array_equal(code_distances(rules, goal, more), code_distances(
            rules, goal, more, changes=RuleSuccessors(rules).code_changes | RuleSuccessors(more).code_changes))
        assert all(table[i, c] == 0 for i, c in enumerate(goal.codes))
        states, _ = reachable_transitions(rules, init)
        for s in states:  # a state called dead must have no goal state reachable from it
            if (table[np.arange(3), list(s)] >= UNREACHABLE).any():
                assert _exhaustive(rules, list(s), goal) is None


def test_bfs_limits_and_dead_end_filter():
    succ = lambda s: np.stack([(s + 1) % 50, (s + 7) % 50], axis=1)  # noqa: E731
    goal = lambda s: s[:, 0] == 49  # noqa: E731
    solved = breadth_first(np.array([0]), succ, np.array([0, 1]), goal, bits=6, timeout_s=5, max_states=1000)
    assert solved.status is PlanStatus.SOLVED and solved.actions == (1,) * 7  # 7 x 7 = 49: the only 7-step plan
    assert breadth_first(np.array([0]), succ, np.array([0, 1]), goal, bits=6, timeout_s=5,
                         max_states=10).status is PlanStatus.NODE_LIMIT
    odd = breadth_first(np.array([0]), succ, np.array([0, 1]), goal, bits=6, timeout_s=5, max_states=1000,
                        dead_end=lambda s: s[:, 0] % 2 == 1)  # 49 is odd: never expanded, never reached
    assert odd.status is PlanStatus.UNSOLVABLE


def test_astar_batches_and_drops_dead_ends():
    graph = {"a": [("ab", "b", 1.0), ("ad", "d", 1.0)], "b": [("bc", "c", 1.0)], "c": [], "d": [("dc", "c", 1.0)]}
    many = lambda states: [graph[s] for s in states]  # noqa: E731
    out = astar("a", lambda s: s == "c", graph.__getitem__, lambda s: 0.0, max_expansions=10, timeout_s=1,
                batch=4, successors_many=many)
    assert out.status is PlanStatus.SOLVED and len(out.actions) == 2
    blocked = astar("a", lambda s: s == "c", graph.__getitem__, lambda s: math.inf if s in "bd" else 0.0,
                    max_expansions=10, timeout_s=1)
    assert blocked.status is PlanStatus.UNSOLVABLE and blocked.generated == 1
    with pytest.raises(ValueError, match="successors_many"):
        astar("a", lambda s: s == "c", graph.__getitem__, lambda s: 0.0, max_expansions=10, timeout_s=1, batch=2)


@pytest.mark.parametrize("name", ["rules-bfs"])
def test_in_process_planners_follow_observed_overrides(name):
    plan = make_planner(name, PlannerContext(rules=DETOUR, model_hash="h"))
    goal = SymbolicGoal((3, None))
    net = RulesTransition(DETOUR)
    first = plan(net, np.array([1, 0]), goal, 10.0)
    assert first.status is PlanStatus.SOLVED and first.plan == (4,) and first.planner == name
    observed = ObservedTransitions(net, {s: dict(v) for s, v in DISPROVEN.items()})
    again = plan(observed, np.array([1, 0]), goal, 10.0)
    assert again.status is PlanStatus.SOLVED and again.plan == (17, 17), again.message
    assert again.extra["rules_vs_net"] is False


def test_rules_bfs_proves_unreachable_goals_and_refuses_bad_input():
    rules, _ = load_rules(PRETRAINED)
    code = rules.vocabulary[0]
    absent = next(c for c in range(256) if c not in rules.codes)
    out = plan_rules(rules, [code, code], SymbolicGoal((absent, None)), "bfs", timeout_s=10)
    assert out.status is PlanStatus.UNSOLVABLE and "no goal state" in out.message
    with pytest.raises(ValueError, match="unknown rule search"):
        plan_rules(rules, [code], SymbolicGoal((code,)), "dfs", timeout_s=1)
    with pytest.raises(ValueError, match="do not match"):
        plan_rules(rules, [code, code], SymbolicGoal((code,)), "bfs", timeout_s=1)
