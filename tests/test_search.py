"""Generic A*, the batched symbolic planner and PlanResult, on tiny hand-made domains.

PROBLEMS is a registry of named problems with known optimal plan lengths (checked against an
independent breadth-first search below), for reuse by planner and PDDL tests.
"""
from __future__ import annotations

import json
import multiprocessing
import math
import time
from collections import deque
from dataclasses import dataclass

import numpy as np
import pytest

from search.astar import astar
from search.learned_astar import likely_outcomes, plan_symbolic, symbolic_successors
from search.result import PlanResult, PlanStatus
from pddl_export.symbolic import N_ACTIONS, SymbolicGoal, TransitionFn, codes_from_bits


# ---------------------------------------------------------------------------------------------
# Hand-made transition functions (the TransitionFn protocol: bits + batched __call__)


@dataclass(frozen=True)
class Counter:
    """Action a increments object a % k modulo 2**bits, if that object is movable; else no-op."""

    k: int
    bits: int = 2
    movable: int | None = None  # objects 0..movable-1 can change; None: all of them

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = codes.copy()
        obj = actions % self.k
        rows = np.flatnonzero(obj < (self.k if self.movable is None else self.movable))
        out[rows, obj[rows]] = (out[rows, obj[rows]] + 1) % (1 << self.bits)
        return out


@dataclass(frozen=True)
class StickRider:
    """Objects (stick, rider) at positions 0..3; pushing the stick carries a rider on it (r == s).

    a % 3 == 0: push stick one step (capped at 3), rider follows if riding;
    a % 3 == 1: rider one step forward; a % 3 == 2: rider one step back.
    """

    bits: int = 2

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = codes.copy()
        s, r, kind = codes[:, 0], codes[:, 1], actions % 3
        push = kind == 0
        riding = push & (r == s)
        out[push, 0] = np.minimum(s[push] + 1, 3)
        out[riding, 1] = out[riding, 0]
        out[kind == 1, 1] = np.minimum(r[kind == 1] + 1, 3)
        out[kind == 2, 1] = np.maximum(r[kind == 2] - 1, 0)
        return out


@dataclass(frozen=True)
class Sweep:
    """Objects (cube0, cube1, cube2, stick), 1 bit each: place cubes one by one, or sweep all.

    a in 0..2 places cube a (code 1); a == 3 aligns the stick; a == 4 with the stick aligned
    places all three cubes at once. Other actions are no-ops.
    """

    bits: int = 1

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = codes.copy()
        one = np.flatnonzero(actions < 3)
        out[one, actions[one]] = 1
        out[actions == 3, 3] = 1
        sweep = (actions == 4) & (codes[:, 3] == 1)
        out[sweep, :3] = 1
        return out


@dataclass(frozen=True)
class Problem:
    """A start, a (partial) goal and the optimal plan length (None: goal unreachable)."""

    transition: TransitionFn
    start: tuple[int, ...]
    goal: SymbolicGoal
    optimal_length: int | None


PROBLEMS: dict[str, Problem] = {
    "counter": Problem(Counter(k=3), (0, 0, 0), SymbolicGoal((2, 1, 3)), 6),
    "counter_wraparound": Problem(Counter(k=2), (3, 0), SymbolicGoal((1, 0)), 2),
    "counter_partial_goal": Problem(Counter(k=3), (0, 0, 0), SymbolicGoal((None, 2, None)), 2),
    "already_at_goal": Problem(Counter(k=2), (1, 2), SymbolicGoal((1, None)), 0),
    "stick_carries_rider": Problem(StickRider(), (0, 0), SymbolicGoal((1, 1)), 1),
    "stick_then_rider_back": Problem(StickRider(), (0, 0), SymbolicGoal((3, 2)), 4),
    "sweep": Problem(Sweep(), (0, 0, 0, 0), SymbolicGoal((1, 1, 1, None)), 2),
    "unreachable": Problem(Counter(k=2, movable=1), (0, 0), SymbolicGoal((None, 1)), None),
}
SOLVABLE = [name for name, p in PROBLEMS.items() if p.optimal_length is not None]


def bfs(transition: TransitionFn, start: tuple[int, ...], goal: SymbolicGoal | None = None):
    """Reference breadth-first search, one action per call: (goal distance or None, #reachable)."""
    dist = {start: 0}
    queue = deque([start])
    found = None
    while queue:
        s = queue.popleft()
        if goal is not None and found is None and goal.satisfied(np.array(s))[0]:
            found = dist[s]
        for a in range(N_ACTIONS):
            n = tuple(transition(np.array([s], np.int64), np.array([a], np.int64))[0].tolist())
            if n not in dist:
                dist[n] = dist[s] + 1
                queue.append(n)
    return found, len(dist)


def mismatch_h(p: Problem, state: tuple[int, ...]) -> int:
    """The planner's heuristic, recomputed: fixed objects off their goal code."""
    return int(p.goal.mismatches(np.array(state))[0])


def assert_valid_plan(p: Problem, result: PlanResult) -> None:
    """Replaying the plan action by action reproduces predicted_states and ends in the goal."""
    assert result.status is PlanStatus.SOLVED and result.found
    assert result.predicted_states[0] == p.start
    state = np.array([p.start], np.int64)
    for a, predicted in zip(result.plan, result.predicted_states[1:]):
        state = p.transition(state, np.array([a], np.int64))
        assert tuple(state[0].tolist()) == predicted
    assert p.goal.satisfied(state)[0]
    # self-loops are never part of a plan
    assert all(x != y for x, y in zip(result.predicted_states, result.predicted_states[1:]))


class CallCounter:
    """Wraps a TransitionFn and records the shape of every batch it is called with."""

    def __init__(self, inner: TransitionFn, sleep_s: float = 0.0):
        self.inner, self.bits, self.sleep_s = inner, inner.bits, sleep_s
        self.calls: list[tuple[tuple[int, ...], np.ndarray]] = []

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        self.calls.append((codes.shape, actions.copy()))
        if self.sleep_s:
            time.sleep(self.sleep_s)
        return self.inner(codes, actions)


# ---------------------------------------------------------------------------------------------
# The registry itself


@pytest.mark.parametrize("name", list(PROBLEMS))
def test_registry_optimal_lengths_match_bfs(name):
    p = PROBLEMS[name]
    assert bfs(p.transition, p.start, p.goal)[0] == p.optimal_length


# ---------------------------------------------------------------------------------------------
# plan_symbolic


@pytest.mark.parametrize("name", SOLVABLE)
def test_uniform_cost_finds_optimal_plan(name):
    p = PROBLEMS[name]
    result = plan_symbolic(p.transition, np.array(p.start), p.goal, uniform_cost=True)
    assert_valid_plan(p, result)
    assert len(result.plan) == p.optimal_length
    assert len(result.predicted_states) == p.optimal_length + 1


@pytest.mark.parametrize("name", SOLVABLE)
def test_heuristic_search_finds_valid_plan(name):
    p = PROBLEMS[name]
    result = plan_symbolic(p.transition, np.array(p.start), p.goal)
    assert_valid_plan(p, result)
    assert len(result.plan) >= p.optimal_length


def test_heuristic_is_exact_where_each_action_moves_one_object():
    p = PROBLEMS["counter"]
    result = plan_symbolic(p.transition, np.array(p.start), p.goal)
    assert len(result.plan) == p.optimal_length == 6


@pytest.mark.parametrize("name", ["stick_carries_rider", "sweep"])
def test_heuristic_overestimates_when_one_action_moves_several_objects(name):
    p = PROBLEMS[name]
    assert mismatch_h(p, p.start) > p.optimal_length


def test_inadmissible_heuristic_gives_longer_plan_uniform_cost_gives_optimum():
    p = PROBLEMS["sweep"]
    greedy = plan_symbolic(p.transition, np.array(p.start), p.goal)
    optimal = plan_symbolic(p.transition, np.array(p.start), p.goal, uniform_cost=True)
    assert len(greedy.plan) == 3  # places the cubes one by one: f stays 3, the sweep path has f 4
    assert optimal.plan == (3, 4)  # align the stick, then sweep


def test_unreachable_goal_is_unsolvable_after_exhausting_reachable_states():
    p = PROBLEMS["unreachable"]
    n_reachable = bfs(p.transition, p.start)[1]
    assert n_reachable == 4
    for uniform in (False, True):
        result = plan_symbolic(p.transition, np.array(p.start), p.goal, uniform_cost=uniform)
        assert result.status is PlanStatus.UNSOLVABLE and not result.found
        assert result.expansions == n_reachable
        assert result.plan == () and result.predicted_states == ()


@pytest.mark.parametrize("uniform", [False, True])
def test_duplicate_states_are_expanded_once(uniform):
    # 12 actions per object and many orders reach each state; object 3 never moves.
    transition = Counter(k=4, movable=3)
    start, goal = (0, 0, 0, 0), SymbolicGoal((None, None, None, 1))
    n_reachable = bfs(transition, start)[1]
    assert n_reachable == 4 ** 3
    result = plan_symbolic(transition, np.array(start), goal, uniform_cost=uniform)
    assert result.status is PlanStatus.UNSOLVABLE
    assert result.expansions == n_reachable
    assert result.extra["generated"] == n_reachable


@pytest.mark.parametrize("name", ["counter", "unreachable"])
def test_one_batched_call_of_36_rows_per_expansion(name):
    p = PROBLEMS[name]
    counted = CallCounter(p.transition)
    result = plan_symbolic(counted, np.array(p.start), p.goal)
    assert result.expansions > 0
    assert len(counted.calls) == result.expansions
    for shape, actions in counted.calls:
        assert shape == (N_ACTIONS, len(p.start))
        np.testing.assert_array_equal(actions, np.arange(N_ACTIONS))


def test_start_at_goal_needs_no_transition_call():
    p = PROBLEMS["already_at_goal"]
    counted = CallCounter(p.transition)
    result = plan_symbolic(counted, np.array(p.start), p.goal)
    assert result.found and result.plan == () and result.predicted_states == (p.start,)
    assert result.expansions == 0 and counted.calls == []


def test_symbolic_successors_drop_self_loops():
    moves = symbolic_successors(Counter(k=2, movable=1), (0, 3))
    assert [a for a, _ in moves] == list(range(0, N_ACTIONS, 2))  # odd actions touch object 1
    assert {n for _, n in moves} == {(1, 3)}


def test_all_self_loops_leave_nothing_to_search():
    # Counter with no movable object: every action is a self-loop.
    result = plan_symbolic(Counter(k=2, movable=0), np.array([0, 0]), SymbolicGoal((1, None)))
    assert result.status is PlanStatus.UNSOLVABLE
    assert result.expansions == 1 and result.extra["generated"] == 1


def test_node_limit_is_not_unsolvable():
    transition = Counter(k=3, bits=4)
    result = plan_symbolic(transition, np.array([0, 0, 0]), SymbolicGoal((15, 15, 15)),
                           max_expansions=5)
    assert result.status is PlanStatus.NODE_LIMIT and not result.found
    assert result.expansions == 5 and result.plan == ()
    assert "max_expansions=5" in result.message


def test_timeout_stops_a_slow_transition():
    slow = CallCounter(Counter(k=3, bits=4), sleep_s=0.02)
    t0 = time.perf_counter()
    result = plan_symbolic(slow, np.array([0, 0, 0]), SymbolicGoal((15, 15, 15)), timeout_s=0.1)
    elapsed = time.perf_counter() - t0
    assert result.status is PlanStatus.TIMEOUT and result.plan == ()
    assert 1 <= result.expansions <= 10  # stopped at the limit: 0.02 s a call, not the 4,096-state search
    assert 0.1 <= result.planning_time_s <= elapsed


def _drop_row(codes, actions):
    return codes[1:]


def _extra_column(codes, actions):
    return np.concatenate([codes, codes[:, :1]], axis=1)


def _flat(codes, actions):
    return codes.reshape(-1)


@pytest.mark.parametrize("bad_fn", [_drop_row, _extra_column, _flat])
def test_transition_with_wrong_output_shape_raises(bad_fn):
    bad_fn.bits = 2
    with pytest.raises(ValueError, match=r"shape \(.*\), expected \(36, 3\)"):
        plan_symbolic(bad_fn, np.array([0, 0, 0]), SymbolicGoal((1, None, None)))


@pytest.mark.parametrize("out_fn, match", [
    (lambda c, a: c + 4, "outside 0..3"),
    (lambda c, a: c.astype(np.float32), "integer codes"),
])
def test_transition_with_bad_codes_raises(out_fn, match):
    out_fn.bits = 2
    with pytest.raises(ValueError, match=match):
        plan_symbolic(out_fn, np.array([0, 0]), SymbolicGoal((1, None)))


@pytest.mark.parametrize("start, goal, match", [
    (np.array([0, 0, 0]), SymbolicGoal((1, None)), "goal has 2 objects, start_codes has 3"),
    (np.array([[0, 0]]), SymbolicGoal((1, None)), "shape"),
    (np.array([0, 7]), SymbolicGoal((1, None)), "outside"),
    (np.array([0, 0]), SymbolicGoal((9, None)), "outside"),
])
def test_bad_start_or_goal_raises(start, goal, match):
    with pytest.raises(ValueError, match=match):
        plan_symbolic(Counter(k=2), start, goal)


def test_plan_symbolic_result_survives_json():
    p = PROBLEMS["counter"]
    result = plan_symbolic(p.transition, np.array(p.start), p.goal, planner_name="astar-h")
    assert result.planner == "astar-h"
    assert PlanResult.from_json(json.loads(json.dumps(result.to_json()))) == result


@dataclass(frozen=True)
class Shortcut:
    """One object; from code 0, action 0 jumps to 3 (a prediction the model doubts, -log P = 3) and
    actions 1 then 2 reach 3 through 1, each step nearly certain (-log P = 0.1); all else stays put."""

    bits: int = 2
    jump_nll: float = 3.0

    def scored(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out, nll = codes.copy(), np.full(len(codes), 0.1)
        c = codes[:, 0]
        jump, via, land = (c == 0) & (actions == 0), (c == 0) & (actions == 1), (c == 1) & (actions == 2)
        out[jump, 0], out[via, 0], out[land, 0] = 3, 1, 3
        nll[jump] = self.jump_nll
        return out, nll

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        return self.scored(codes, actions)[0]


@pytest.mark.parametrize("uniform", [False, True])
def test_risk_weight_trades_a_doubtful_step_for_two_sure_ones(uniform):
    start, goal = np.array([0]), SymbolicGoal((3,))
    plain = plan_symbolic(Shortcut(), start, goal, uniform_cost=uniform)
    assert plain.plan == (0,) and "log_p" not in plain.extra
    likely = plan_symbolic(Shortcut(), start, goal, uniform_cost=uniform, risk_weight=1.0)
    assert likely.plan == (1, 2) and likely.predicted_states == ((0,), (1,), (3,))
    assert likely.extra["log_p"] == pytest.approx(-0.2) and likely.extra["risk_weight"] == 1.0
    # a weight too small to pay for the extra step keeps the short plan: 1 + 0.1 * 3 < 2 + 0.1 * 0.2
    small = plan_symbolic(Shortcut(), start, goal, uniform_cost=uniform, risk_weight=0.1)
    assert small.plan == (0,) and small.extra["log_p"] == pytest.approx(-3.0)


@pytest.mark.parametrize("transition, weight, match", [
    (Shortcut(), -1.0, "risk_weight must be"),
    (Shortcut(), float("nan"), "risk_weight must be"),
    (Counter(k=1), 1.0, "scores its predictions"),
    (Shortcut(jump_nll=-1.0), 1.0, "scores must be"),
    (Shortcut(jump_nll=float("inf")), 1.0, "scores must be"),
])
def test_risk_weight_refuses_bad_weights_and_unscored_models(transition, weight, match):
    with pytest.raises(ValueError, match=match):
        plan_symbolic(transition, np.array([0]), SymbolicGoal((3,)), risk_weight=weight)


@pytest.mark.parametrize("seed", range(6))
def test_likely_outcomes_are_the_most_likely_states_by_enumeration(seed):
    """Against every one of the 2**(K*bits) next states, scored as a product of independent bits."""
    import itertools

    rng = np.random.default_rng(seed)
    k, bits = int(rng.integers(1, 3)), int(rng.integers(1, 4))
    probs = rng.uniform(0, 1, (5, k, bits))
    probs[rng.uniform(size=probs.shape) < 0.3] = 1.0  # some certain bits: their flips are impossible
    probs[rng.uniform(size=probs.shape) < 0.1] = 0.0
    n, ratio = int(rng.integers(1, 6)), float(rng.uniform(0.02, 0.9))
    got = likely_outcomes(probs, n, ratio)
    assert len(got) == 5
    for row, p in zip(got, probs):
        every = sorted(((float(np.prod(np.where(b, p, 1 - p))), int(i)) for i, b in
                        enumerate(np.array(list(itertools.product([0, 1], repeat=k * bits))).reshape(-1, k, bits))),
                       key=lambda t: -t[0])
        prob_of = {tuple(codes_from_bits(b).tolist()): pr for pr, b in
                   ((float(np.prod(np.where(b, p, 1 - p))), b)
                    for b in np.array(list(itertools.product([0, 1], repeat=k * bits))).reshape(-1, k, bits))}
        want = [pr for pr, _ in every if pr >= ratio * every[0][0] * (1 + 1e-9)][:n]
        assert len(want) <= len(row) <= n  # ties at the ratio may add one
        assert [np.exp(-nll) for _, nll in row][:len(want)] == pytest.approx(want, abs=1e-9)
        assert all(prob_of[state] == pytest.approx(np.exp(-nll), abs=1e-9) for state, nll in row)
        assert len({state for state, _ in row}) == len(row)  # distinct states, the likeliest first
        assert row[0][0] == tuple(codes_from_bits(p >= 0.5).tolist())


@dataclass(frozen=True)
class Sticky:
    """One object, 2 bits. From code 0, action 0 most likely does nothing (P 0.7) but may set the low bit
    (P 0.3, code 1); action 1 surely sets the high bit (code 2); from 2 action 2 surely gives 3; all else stays."""

    bits: int = 2
    p_low: float = 0.3

    def bit_probabilities(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = ((codes[..., None] >> np.array([1, 0])) & 1).astype(float)
        c = codes[:, 0]
        out[(c == 0) & (actions == 0), 0, 1] = self.p_low
        out[(c == 0) & (actions == 1), 0, 0] = 1.0
        out[(c == 2) & (actions == 2), 0, 1] = 1.0
        return out

    def scored(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = self.bit_probabilities(codes, actions)
        return codes_from_bits(p >= 0.5), -np.log(np.where(p >= 0.5, p, 1 - p)).sum((1, 2))

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        return self.scored(codes, actions)[0]


def test_outcomes_plan_for_a_goal_only_a_less_likely_outcome_reaches():
    start = np.array([0])
    likely = plan_symbolic(Sticky(), start, SymbolicGoal((1,)), risk_weight=1.0)
    assert likely.status is PlanStatus.UNSOLVABLE  # the likeliest predictions never reach code 1
    out = plan_symbolic(Sticky(), start, SymbolicGoal((1,)), risk_weight=1.0, max_outcomes=2)
    assert out.found and out.plan == (0,) and out.predicted_states == ((0,), (1,))
    assert out.extra["log_p"] == pytest.approx(np.log(0.3)) and out.extra["max_outcomes"] == 2
    # an outcome less likely than min_outcome_ratio times the likeliest is not followed: 0.3 / 0.7 < 0.5
    assert plan_symbolic(Sticky(), start, SymbolicGoal((1,)), risk_weight=1.0, max_outcomes=2,
                         min_outcome_ratio=0.5).status is PlanStatus.UNSOLVABLE
    # where the likeliest predictions reach the goal, the sure route is kept: 2 sure steps cost 2, and the
    # doubtful outcome 1 leads nowhere
    sure = plan_symbolic(Sticky(), start, SymbolicGoal((3,)), risk_weight=1.0, max_outcomes=2)
    assert sure.plan == (1, 2) and sure.extra["log_p"] == pytest.approx(0.0)


@pytest.mark.parametrize("transition, kwargs, match", [
    (Sticky(), dict(max_outcomes=0), "max_outcomes must be"),
    (Sticky(), dict(max_outcomes=2.0), "max_outcomes must be"),
    (Sticky(), dict(max_outcomes=10), "max_outcomes must be an integer in 1..9"),
    (Sticky(), dict(max_outcomes=2, min_outcome_ratio=0.0), "min_outcome_ratio"),
    (Sticky(), dict(max_outcomes=2, min_outcome_ratio=1.5), "min_outcome_ratio"),
    (Sticky(), dict(max_outcomes=2, risk_weight=0.0), "needs risk_weight > 0"),
    (Shortcut(), dict(max_outcomes=2), "bit probabilities"),
    (Sticky(p_low=1.5), dict(max_outcomes=2), "must be \\(36, 1, 2\\) in \\[0, 1\\]"),
])
def test_outcomes_refuse_bad_settings_and_models(transition, kwargs, match):
    kwargs = {"risk_weight": 1.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        plan_symbolic(transition, np.array([0]), SymbolicGoal((1,)), **kwargs)


# ---------------------------------------------------------------------------------------------
# Generic astar


WEIGHTED = {
    "S": [("sa", "A", 1.0), ("sb", "B", 4.0)],
    "A": [("ab", "B", 1.0), ("ag", "G", 10.0)],
    "B": [("bg", "G", 2.0)],
    "G": [],
}


def test_astar_weighted_graph_optimal_with_admissible_heuristic():
    h = {"S": 3.0, "A": 2.0, "B": 2.0, "G": 0.0}
    out = astar("S", lambda s: s == "G", lambda s: WEIGHTED[s], h.__getitem__,
                max_expansions=100, timeout_s=1.0)
    assert out.status is PlanStatus.SOLVED
    assert out.actions == ("sa", "ab", "bg") and out.states == ("S", "A", "B", "G")
    assert out.cost == 4.0


def test_astar_uniform_cost_ignores_misleading_heuristic():
    h = {"S": 0.0, "A": 100.0, "B": 0.0, "G": 0.0}
    misled = astar("S", lambda s: s == "G", lambda s: WEIGHTED[s], h.__getitem__,
                   max_expansions=100, timeout_s=1.0)
    optimal = astar("S", lambda s: s == "G", lambda s: WEIGHTED[s], h.__getitem__,
                    max_expansions=100, timeout_s=1.0, uniform_cost=True)
    assert misled.cost == 6.0 and misled.actions == ("sb", "bg")
    assert optimal.cost == 4.0 and optimal.actions == ("sa", "ab", "bg")
    assert optimal.expansions == 3  # S, A, B at g=2; the stale B entry (g=4) is skipped


def test_astar_breaks_f_ties_towards_lower_h():
    graph = {"S": [("sb", "B", 0.0), ("sa", "A", 2.0)], "A": [], "B": []}
    h = {"S": 0.0, "A": 0.0, "B": 2.0}  # A and B both have f = 2; A is the goal
    out = astar("S", lambda s: s == "A", lambda s: graph[s], h.__getitem__,
                max_expansions=100, timeout_s=1.0)
    assert out.actions == ("sa",) and out.expansions == 1  # B (pushed first) never expanded


def test_astar_reopens_state_reached_more_cheaply_and_skips_stale_entries():
    # C is first expanded via B (g=6); A, delayed by its inconsistent h, then reaches C at g=2.
    graph = {"S": [("sa", "A", 1.0), ("sb", "B", 1.0)], "A": [("ac", "C", 1.0)],
             "B": [("bc", "C", 5.0)], "C": [("cg", "G", 10.0)], "G": []}
    h = {"S": 0.0, "A": 8.0, "B": 0.0, "C": 0.0, "G": 0.0}
    out = astar("S", lambda s: s == "G", lambda s: graph[s], h.__getitem__,
                max_expansions=100, timeout_s=1.0)
    assert out.status is PlanStatus.SOLVED
    assert out.actions == ("sa", "ac", "cg") and out.cost == 12.0
    assert out.expansions == 5  # S, B, C (g=6), A, C (g=2); the stale G (g=16) is never popped


def test_astar_goal_at_start_with_zero_budget():
    out = astar(0, lambda s: s == 0, lambda s: [], lambda s: 0.0, max_expansions=0, timeout_s=1.0)
    assert out.status is PlanStatus.SOLVED and out.states == (0,) and out.expansions == 0


@pytest.mark.parametrize("kwargs, match", [
    ({"max_expansions": -1, "timeout_s": 1.0}, "max_expansions"),
    ({"max_expansions": 10, "timeout_s": 0.0}, "timeout_s"),
])
def test_astar_rejects_bad_limits(kwargs, match):
    with pytest.raises(ValueError, match=match):
        astar(0, lambda s: False, lambda s: [], lambda s: 0.0, **kwargs)


def test_astar_rejects_negative_cost():
    with pytest.raises(ValueError, match="non-negative"):
        astar(0, lambda s: s == 2, lambda s: [("x", s + 1, -1.0)], lambda s: 0.0,
              max_expansions=10, timeout_s=1.0)


# ---------------------------------------------------------------------------------------------
# PlanResult


def _result(**overrides) -> PlanResult:
    kwargs = dict(planner="astar", status=PlanStatus.SOLVED, plan=(3, 17),
                  predicted_states=((0, 5), (1, 5), (1, 6)), expansions=4,
                  planning_time_s=0.01, message="", extra={"generated": 9, "engine": "x"})
    kwargs.update(overrides)
    return PlanResult(**kwargs)


@pytest.mark.parametrize("overrides", [
    {"status": PlanStatus.TIMEOUT, "predicted_states": ()},  # a plan without SOLVED
    {"status": PlanStatus.UNSOLVABLE, "plan": ()},  # predicted states without SOLVED
    {"plan": (3, 36)},
    {"plan": (-1, 3)},
    {"plan": (3.0, 17)},
    {"plan": (True, 17)},
    {"predicted_states": ((0, 5), (1, 5))},
    {"predicted_states": ((0, 5), (1, 5), (1,))},
    {"predicted_states": ((0, 5), (1, 5), (1, -6))},
    {"expansions": -1},
    {"planning_time_s": -0.5},
    {"planning_time_s": math.nan},
    {"planner": ""},
    {"status": "bogus"},
    {"message": "two\nlines"},
    {"extra": {"times": [1.0, 2.0]}},
    {"extra": {1: 2.0}},
])
def test_plan_result_validation_refuses(overrides):
    with pytest.raises((ValueError, TypeError)):
        _result(**overrides)


def test_plan_result_json_and_process_round_trip():
    r = _result(extra={"pddl_write_time_s": np.float64(0.25), "planner_time_s": 1.5,
                       "search_nodes": np.int64(12), "engine": "fast-downward"})
    d = json.loads(json.dumps(r.to_json()))
    assert d["status"] == "solved" and d["plan"] == [3, 17]
    assert PlanResult.from_json(d) == r
    send, recv = multiprocessing.Pipe()  # how a planner's child process hands its result back
    send.send(r)
    assert recv.recv() == r
    assert type(r.extra["search_nodes"]) is int


def test_plan_result_is_immutable_and_coerces():
    r = _result(status="solved", plan=(np.int64(3), 17), expansions=None)
    assert r.status is PlanStatus.SOLVED and r.found and type(r.plan[0]) is int
    with pytest.raises(TypeError):
        r.extra["generated"] = 10
    with pytest.raises(AttributeError):
        r.plan = ()
    failed = PlanResult(planner="fd", status=PlanStatus.ERROR, plan=(), predicted_states=(),
                        expansions=None, planning_time_s=0.0, message="translator crashed")
    assert not failed.found and PlanResult.from_json(failed.to_json()) == failed
