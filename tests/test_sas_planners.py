"""Fast Downward's search on directly written SAS+ tasks: exact semantics, optimal lengths, honest failures.

The encoding is checked three ways: optimal plan lengths equal a breadth-first search over
apply_rules on random rule sets (no shorter plan exists in the SAS+ task than in the rules,
none longer is needed), plans validate with unified-planning's PlanValidator on the
conditional PDDL domain (an independent reading of the same rules), and predicted states are
the ToyRobot network's rollout.
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from pddl_export.pddl_writer import action_name, conditional_domain, problem_pddl
from pddl_export.rules import INF, Rule, RuleSet, apply_rules, apply_rules_batch
from pddl_export.sas_writer import SASEncoder, TermKind, context_terms, satisfying_cells
from search.sas_planners import SAS_PLANNERS, search_binary, solve_sas
from search.result import PlanStatus
from pddl_export.symbolic import N_ACTIONS, SymbolicGoal
from test_classical import NEVER, STICK_CARRIES_RIDER, UNCOVER_TWICE, rules  # noqa: F401 - fixture
from test_pddl_export import ToyRobot, random_nets  # noqa: F401 - fixture

pytestmark = pytest.mark.skipif(search_binary("up_fast_downward") is None, reason="up-fast-downward is not installed")


def _require(planner: str) -> None:
    if search_binary(SAS_PLANNERS[planner].package) is None:
        pytest.skip(f"{SAS_PLANNERS[planner].package} is not installed")


def _bfs_length(rules, init, goal: SymbolicGoal, max_depth: int = 8) -> int:
    """Shortest plan length under apply_rules (-1 if the goal is unreachable)."""
    frontier, seen = np.array([init], np.int64), {tuple(init)}
    for depth in range(max_depth + 1):
        if goal.satisfied(frontier).any():
            return depth
        k = len(frontier)
        nxt = apply_rules_batch(rules, np.repeat(frontier, N_ACTIONS, 0), np.tile(np.arange(N_ACTIONS), k))
        new = [tuple(s) for s in np.unique(nxt, axis=0).tolist() if tuple(s) not in seen]
        if not new:
            return -1
        seen.update(new)
        frontier = np.array(new, np.int64)
    raise AssertionError("goal deeper than max_depth")


@pytest.mark.parametrize("problem", [STICK_CARRIES_RIDER, UNCOVER_TWICE])
@pytest.mark.parametrize("planner", list(SAS_PLANNERS))
def test_toy_problems_follow_the_network(rules, problem, planner):  # noqa: F811
    _require(planner)
    res = solve_sas(SASEncoder(rules), problem.init, problem.goal, planner, timeout_s=20)
    assert res.status is PlanStatus.SOLVED, res.message
    net, states = ToyRobot(), [np.array(problem.init)]
    for a in res.plan:
        states.append(net(states[-1][None], np.array([a]))[0])
    assert SymbolicGoal(problem.goal).satisfied(states[-1])[0]
    assert res.predicted_states == tuple(tuple(int(c) for c in s) for s in states)
    assert res.extra["planner_time_s"] >= res.extra["fd_total_time_s"] >= res.extra["fd_search_time_s"] >= 0
    if planner.startswith("fast-downward"):
        assert res.expansions is not None and res.expansions >= 1
    if SAS_PLANNERS[planner].optimal:
        assert len(res.plan) == problem.optimal_length and res.extra["optimal"]


def test_context_terms_cover_exactly_the_satisfying_cells():
    """The DNF's terms cover every assignment of the others that meets the bounds, and no other."""
    cases = [((), 2), (((1, INF),), 2), (((0, 1),), 2), (((1, INF), (0, 1)), 2), (((2, INF),), 3),
             (((0, 2), (1, INF)), 3), (((1, 2),) * 5, 2)]
    for intervals, k in cases:
        m = len(intervals)
        want = {c for c in itertools.product(range(m + 1), repeat=k)
                if all(lo <= c.count(j) < hi for j, (lo, hi) in enumerate(intervals))}
        got = set()
        for term in context_terms(intervals, k):
            allowed = [{js[0]} if kind == "eq" else set(range(m + 1)) - set(js) for kind, js in term]
            got |= set(itertools.product(*allowed))
        assert got == want, (intervals, k)
    assert len(context_terms(((1, INF),), 2)) == 2  # "some other has X": z1 = X or z2 = X, not 3 cells
    (term,) = context_terms(((0, 1),), 2)  # "none has X": one term, forbidding X on each other object
    assert [set(range(2)) - set(js) if kind is TermKind.NOT else set(js) for kind, js in term] == [{1}, {1}]



def test_satisfying_cells_equal_every_assignment_that_meets_the_bounds():
    """The pruned enumeration gives the brute-force cells, in order, also for empty and impossible bounds."""
    rng = np.random.default_rng(0)
    for _ in range(400):
        m, k = int(rng.integers(0, 6)), int(rng.integers(0, 5))
        intervals = tuple((int(lo), int(lo + rng.integers(-1, 4))) for lo in rng.integers(0, 3, m))
        want = sorted(c for c in itertools.product(range(m + 1), repeat=k)
                      if all(lo <= c.count(j) < hi for j, (lo, hi) in enumerate(intervals)))
        assert satisfying_cells(intervals, k) == want, (intervals, k)
    # a rule that forbids 40 codes and asks for one more: each other object is "none" or that code, never a forbidden one
    forbids = ((0, 1),) * 40 + ((1, INF),)
    cells = satisfying_cells(forbids, 4)
    assert len(cells) == 2 ** 4 - 1 and all(set(c) <= {40, 41} and 40 in c for c in cells)
    assert satisfying_cells(((0, 0),), 2) == [] and satisfying_cells(((3, INF),), 2) == []

@pytest.mark.parametrize("init,goal,want", [((1, 3), (2, None), -1), ((1, 2), (2, None), 1), ((3, 1), (None, 2), -1),
                                            ((1, 1, 2), (2, 2, None), 1), ((1,), (3,), 2)])
def test_forbidding_context_plans_like_breadth_first_search(init, goal, want):
    """"Unless some other object has 3": plan lengths of the SAS+ task equal a breadth-first search over the rules."""
    _require("fast-downward-sas-opt")
    rs = RuleSet(2, (1, 2, 3), 3, (Rule(0, 1, 2, forbids=(3,)), Rule(1, 2, 3), Rule(1, 3, 1, requires=(2,))), 3)
    goal_g = SymbolicGoal(goal)
    assert _bfs_length(rs, list(init), goal_g) == want
    res = solve_sas(SASEncoder(rs), init, goal_g, "fast-downward-sas-opt", timeout_s=20)
    if want < 0:
        assert res.status is PlanStatus.UNSOLVABLE, res.message
    else:
        assert res.status is PlanStatus.SOLVED and len(res.plan) == want, res.message
        assert goal_g.satisfied(np.array(res.predicted_states[-1]))[0]


@pytest.mark.parametrize("planner", [p for p, spec in SAS_PLANNERS.items() if spec.optimal])
def test_optimal_lengths_match_breadth_first_search_on_random_rules(random_nets, planner):  # noqa: F811
    _require(planner)
    rng = np.random.default_rng(0)
    checked = {"solved": 0, "unsolvable": 0}
    for _, _, rs in random_nets:
        enc = SASEncoder(rs)
        for n in (1, 2, 3):
            for _ in range(4 if planner.startswith("fast-downward") else 2):
                init = [int(c) for c in rng.choice(rs.vocabulary, n)]
                goal = SymbolicGoal(tuple(int(c) if i == 0 or rng.random() < 0.5 else None
                                          for i, c in enumerate(rng.choice(rs.vocabulary, n))))
                want = _bfs_length(rs, init, goal)
                res = solve_sas(enc, init, goal, planner, timeout_s=20)
                if want < 0:
                    assert res.status is PlanStatus.UNSOLVABLE, (init, goal, res.message)
                    checked["unsolvable"] += 1
                else:
                    assert res.status is PlanStatus.SOLVED, (init, goal, res.message)
                    assert len(res.plan) == want, (init, goal.codes, res.plan)
                    checked["solved"] += 1
    assert checked["solved"] >= 5 and checked["unsolvable"] >= 1, checked


def test_plans_validate_on_the_conditional_pddl(rules):  # noqa: F811
    from unified_planning.io import PDDLReader
    from unified_planning.plans import ActionInstance, SequentialPlan
    from unified_planning.shortcuts import PlanValidator

    p = UNCOVER_TWICE
    res = solve_sas(SASEncoder(rules), p.init, p.goal, "fast-downward-sas", timeout_s=20)
    assert res.status is PlanStatus.SOLVED, res.message
    problem = PDDLReader().parse_problem_string(conditional_domain(rules, "t"), problem_pddl(rules, p.init, p.goal, "t"))
    plan = SequentialPlan([ActionInstance(problem.action(action_name(a))) for a in res.plan])
    with PlanValidator(problem_kind=problem.kind) as validator:
        assert validator.validate(problem, plan).status.name == "VALID"
    bad = SequentialPlan([ActionInstance(problem.action(action_name(a))) for a in res.plan[:-1]])
    with PlanValidator(problem_kind=problem.kind) as validator:
        assert validator.validate(problem, bad).status.name == "INVALID"


def test_unsolvable_and_failures_are_statuses(rules, monkeypatch, tmp_path):  # noqa: F811
    enc = SASEncoder(rules)
    for planner in SAS_PLANNERS:
        if search_binary(SAS_PLANNERS[planner].package) is not None:
            res = solve_sas(enc, NEVER.init, NEVER.goal, planner, timeout_s=20)
            assert res.status is PlanStatus.UNSOLVABLE and res.plan == (), (planner, res.message)
    # a code outside the vocabulary is inert under the rules: its object keeps it, so it can be neither left nor reached
    new = min(set(range(1 << rules.bits)) - set(rules.codes))
    res = solve_sas(enc, [new], [1], "fast-downward-sas", timeout_s=20)
    assert res.status is PlanStatus.UNSOLVABLE and res.plan == (), res.message
    res = solve_sas(enc, [new], [new], "fast-downward-sas", timeout_s=20)
    assert res.status is PlanStatus.SOLVED and res.plan == () and res.predicted_states == ((new,),)
    assert new not in enc.codes and new in rules.with_codes([new]).codes and rules.with_codes([1]) is rules
    assert solve_sas(enc, [99], [1], "fast-downward-sas", timeout_s=20).message == "every code must fit in 3 bits"
    res = solve_sas(enc, [1], [1, 2], "fast-downward-sas", timeout_s=20)
    assert res.status is PlanStatus.ERROR and "objects" in res.message
    assert solve_sas(enc, [1], [2], "no-such", timeout_s=20).message.startswith("unknown planner")
    big = UNCOVER_TWICE
    res = solve_sas(SASEncoder(rules, max_effects=3), big.init, big.goal, "fast-downward-sas", timeout_s=20)
    assert res.status is PlanStatus.ERROR and "conditional effects" in res.message
    res = solve_sas(enc, big.init, big.goal, "fast-downward-sas", timeout_s=1e-4)
    assert res.status is PlanStatus.TIMEOUT and "time limit" in res.message
    with pytest.raises(ValueError):
        solve_sas(enc, big.init, big.goal, "fast-downward-sas", timeout_s=float("nan"))
    saved = tmp_path / "task.sas"
    assert solve_sas(enc, big.init, big.goal, "fast-downward-sas", 20, write_to=saved).found
    assert saved.read_text().startswith("begin_version\n3\nend_version")
    monkeypatch.setattr("search.sas_planners.search_binary", lambda package: None)
    res = solve_sas(enc, big.init, big.goal, "fast-downward-sas", timeout_s=20)
    assert res.status is PlanStatus.ERROR and "binary of up_fast_downward was not found" in res.message


def test_effects_reproduce_the_rules_on_every_joint_state(rules):  # noqa: F811
    """In every joint state of 3 objects, the effects that fire give apply_rules' successor, never two values."""
    enc = SASEncoder(rules)
    codes = list(rules.codes)
    task = enc.task([codes[0]] * 3, [codes[1], None, None])
    body = task.text.split("end_goal\n", 1)[1]
    n_ops = int(body.split("\n", 1)[0])
    ops = body.split("begin_operator\n")[1:n_ops + 1]
    derived = {}  # derived variable -> (object, value) it tests
    for rule_text in task.text.split("begin_rule\n")[1:]:
        _, cond, eff = rule_text.split("\n")[:3]
        z, x = map(int, cond.split())
        derived[int(eff.split()[0])] = (z, x)
    for state in itertools.product(range(len(codes)), repeat=3):
        for op in ops:
            lines = op.split("\n")
            a = int(lines[0].split("-")[1]) * 6 + int(lines[0].split("-")[3])
            fired = {}
            for eff in lines[3:3 + int(lines[2])]:
                nums = list(map(int, eff.split()))
                conds = list(zip(nums[1:1 + 2 * nums[0]:2], nums[2:2 + 2 * nums[0]:2]))
                holds = all(state[v] == x if v < 3 else (state[derived[v][0]] == derived[v][1]) == bool(x)
                            for v, x in conds)
                if holds:
                    var, post = nums[-3], nums[-1]
                    assert fired.setdefault(var, post) == post, (state, lines[0], "conflicting effects fired")
            want = apply_rules_batch(rules, np.array([[codes[s] for s in state]]), np.array([a]))[0]
            got = [codes[fired.get(o, state[o])] for o in range(3)]
            assert got == want.tolist(), (state, lines[0])


def test_effects_negation_has_no_axioms_and_same_optimal_lengths(random_nets):  # noqa: F811
    """Negation.EFFECTS: no axioms, has-X(z) state variables set from the start codes; blind A* finds the same lengths."""
    from pddl_export.sas_writer import Negation
    rng = np.random.default_rng(1)
    compared = 0
    for _, _, rs in random_nets:
        ax, ef = SASEncoder(rs), SASEncoder(rs, negation=Negation.EFFECTS)
        assert ax.with_negation("effects") is ax.with_negation(Negation.EFFECTS)  # one cached sibling
        for n in (2, 3):
            init = [int(c) for c in rng.choice(rs.vocabulary, n)]
            goal = [int(c) for c in rng.choice(rs.vocabulary, n)]
            ta, te = ax.task(init, goal), ef.task(init, goal)
            assert te.n_axioms == 0 and te.n_derived == 0 and "begin_rule" not in te.text
            assert te.n_variables == ta.n_variables and te.n_effects >= ta.n_effects
            state = te.text.split("begin_state\n", 1)[1].split("\nend_state", 1)[0].split("\n")
            for (z, x), value in zip(ef._bodies[n].tracked, state[n:]):
                assert int(value) == int(init[z] == x)
            want = _bfs_length(rs, init, SymbolicGoal(tuple(goal)))
            if search_binary("up_fast_downward") is None:
                continue
            res = solve_sas(ef, init, goal, "fast-downward-sas-opt", timeout_s=20)
            assert (len(res.plan) if res.status is PlanStatus.SOLVED else -1) == want, (init, goal, res.message)
            compared += 1
    assert compared >= 4 or search_binary("up_fast_downward") is None


def _loopless_plan_lengths(rs, init, goal: SymbolicGoal, max_depth: int) -> list[int]:
    """The length of every plan under apply_rules that visits no state twice, up to max_depth, sorted."""

    lengths, stack = [], [((tuple(init),), 0)]
    while stack:
        path, depth = stack.pop()
        if goal.satisfied(np.array(path[-1]))[0]:
            lengths.append(depth)
            continue  # a loopless plan ends at its first goal state
        if depth == max_depth:
            continue
        for a in range(N_ACTIONS):
            nxt = tuple(int(c) for c in apply_rules(rs, np.array(path[-1]), a))
            if nxt not in path:
                stack.append((path + (nxt,), depth + 1))
    return sorted(lengths)


def test_top_k_returns_the_k_shortest_loopless_plans_each_valid_under_the_rules():
    """Start (1, 3), goal (2, 2): three plans of length 2 ([0, 1], [1, 0], [3, 0]) and longer detours.

    symk-sas-topk returns TOP_K distinct plans, each reaching the goal when replayed with the rules,
    shortest first, whose lengths are the TOP_K smallest over every loopless plan at most TOP_K_SLACK longer.
    """
    from search.sas_planners import TOP_K, TOP_K_SLACK

    _require("symk-sas-topk")
    rs = RuleSet(2, (1, 2, 3), 2, (Rule(0, 1, 2), Rule(1, 3, 2), Rule(3, 3, 1), Rule(4, 2, 3)), 4)
    init, goal = (1, 3), SymbolicGoal((2, 2))
    want = _loopless_plan_lengths(rs, init, goal, max_depth=2 + TOP_K_SLACK)[:TOP_K]
    assert want[:3] == [2, 2, 2] and len(want) == TOP_K and want[-1] > 2  # the case has ties and longer plans
    res = solve_sas(SASEncoder(rs), init, goal, "symk-sas-topk", timeout_s=20)
    assert res.status is PlanStatus.SOLVED, res.message
    plans = [(res.plan, res.predicted_states)] + list(res.alternatives)
    assert len(plans) == TOP_K and len({p for p, _ in plans}) == TOP_K
    assert [len(p) for p, _ in plans] == want
    for plan, states in plans:
        replay = [np.array(init)]
        for a in plan:
            replay.append(apply_rules(rs, replay[-1], a))
        assert states == tuple(tuple(int(c) for c in s) for s in replay)
        assert goal.satisfied(replay[-1])[0] and len(set(states)) == len(states)  # valid and loopless
    assert res.extra["top_k_plans"] == TOP_K and res.extra["top_k_dropped"] == 0
    assert solve_sas(SASEncoder(rs), init, goal, "symk-sas", timeout_s=20).alternatives == ()


def test_plan_files_cut_short_by_a_kill_are_left_out(tmp_path):
    """A top-k plan file without its closing cost line (the binary was killed while writing it) is not read."""
    from search.sas_planners import _read_plans

    (tmp_path / "plan.1").write_text("(pick-0-release-1)\n(pick-1-release-2)\n; cost = 2 (unit cost)\n")
    (tmp_path / "plan.10").write_text("(pick-0-release-3)\n; cost = 1 (unit cost)\n")
    (tmp_path / "plan.2").write_text("(pick-0-release-1)\n(pick-2-rel")
    assert _read_plans(tmp_path) == [["pick-0-release-1", "pick-1-release-2"], ["pick-0-release-3"]]
    (tmp_path / "plan").write_text("(pick-5-release-0)\n; cost = 1 (unit cost)\n")
    assert _read_plans(tmp_path) == [["pick-5-release-0"]]


def test_writing_a_task_past_its_deadline_is_a_timeout(rules):  # noqa: F811
    import time

    from pddl_export.sas_writer import TaskTimeoutError

    enc = SASEncoder(rules)
    with pytest.raises(TaskTimeoutError, match="time limit"):
        enc.task([1, 2], [2, None], deadline=time.perf_counter() - 1.0)
    task = enc.task([1, 2], [2, None])  # no deadline: built, then cached for two objects
    assert enc.task([2, 1], [None, 2], deadline=time.perf_counter() - 1.0).n_effects == task.n_effects
    # through solve_sas: a limit shorter than writing the operators of a new object count is a TIMEOUT, not an error
    slow = SASEncoder(rules)
    slow._body = lambda n, deadline=None: (_ for _ in ()).throw(TaskTimeoutError("passed the time limit"))
    res = solve_sas(slow, [1, 2], [2, None], "fast-downward-sas", timeout_s=5)
    assert res.status is PlanStatus.TIMEOUT and "time limit" in res.message
