"""Executing plans in the simulator, failure stages, closed-loop replanning, the benchmark and its registry.

The encoder and transition here are untrained (seeded) networks: these tests check the plumbing,
not the quality of learned symbols.
"""
from __future__ import annotations

import argparse
import dataclasses
import json

import numpy as np
import pytest
import torch

from search.result import PlanResult, PlanStatus
from symlearn.planning import benchmark as bench
from symlearn.planning import benchmark_rows, benchmark_summary
from symlearn.learning.checkpoint import save_checkpoint
from symlearn.cli.planning import add_planning_commands
from symlearn.planning.execution import (FAILURE_CAUSES, ExecutionConfig, FailureStage, ObservedTransitions, ProblemRun,
                                        execute_plan, failure_cause, failure_causes, run_problem)
from symlearn.planning.planners import PLANNERS, PlannerConfig, PlannerContext, make_planner
from pddl_export.rules import Rule, RuleSet
from pddl_export.pddl_writer import conditional_domain, problem_pddl
from pddl_export.symbolic import SymbolicGoal
from symlearn.learning.models import AttentiveDeepSym, ModelConfig
from symlearn.problems.problem import GOAL_TOLERANCE_M, load_problem, load_problems
from symlearn.problems.problem_generation import generate_problems
from symlearn.symbolic.scenes import goal_codes, scene_codes
from pddl_export.files import sha256_file
from symlearn.symbolic.learned_transition import LearnedTransition
from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE, save_transition
from symlearn.symbolic.transition_model import TransitionConfig, TransitionNet
from symlearn.world import action_id

OPEN_LOOP = ExecutionConfig(closed_loop=False)  # each plan run as planned (ExecutionConfig() is closed loop)


def _seeded(make, seed: int):
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(seed)
        return make().eval()


@pytest.fixture(scope="module")
def encoder():
    return _seeded(lambda: AttentiveDeepSym(ModelConfig.from_preset("quick")), 0)


@pytest.fixture(scope="module")
def problems(tmp_path_factory, sim):
    out = tmp_path_factory.mktemp("exec_problems")
    return [load_problem(p) for p in generate_problems(out, 2, objects=(2, 3), length=(1, 3), seed=7, sim=sim)]


@pytest.fixture(scope="module")
def walks(tmp_path_factory, sim):
    """Problems of 2-3 reference steps whose position codes differ at every reference state."""
    out = tmp_path_factory.mktemp("exec_walks")
    enc = _PositionEncoder(sim)
    keep = []
    for path in generate_problems(out, 8, objects=(2, 3), length=(2, 3), seed=5, sim=sim):
        pr = load_problem(path)
        states = _truth(sim, enc, pr, pr.actions)[1]
        if len(set(states)) == len(states) and 7 not in states[-1]:
            keep.append(pr)
    assert len(keep) >= 2, "too few usable walks"
    return keep


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory, encoder):
    """A run directory holding an (untrained) effect model and a transition model tied to it."""
    d = tmp_path_factory.mktemp("exec_run")
    save_checkpoint(d / "best.pt", model=encoder)
    net = _seeded(lambda: TransitionNet(TransitionConfig.from_preset("quick", code_bits=encoder.cfg.bits)), 1)
    save_transition(d / TRANSITION_FILE, net, {"effect_model_sha256": sha256_file(d / "best.pt")[:16]})
    return d


def _plan(actions, states, planner="test") -> PlanResult:
    return PlanResult(planner=planner, status=PlanStatus.SOLVED, plan=tuple(actions),
                      predicted_states=tuple(tuple(int(c) for c in s) for s in states), expansions=0,
                      planning_time_s=0.0)


def _wrong(codes) -> tuple[int, ...]:
    """A state the real scene will not be in: every code with its lowest bit flipped."""
    return tuple(int(c) ^ 1 for c in codes)


def _empty_pick(problem) -> int:
    """An action that moves nothing: pick at a location no object covers."""
    from symlearn.world import LOCATIONS

    pos = problem.initial.positions()[:, :2]
    free = [i for i, (x, y) in enumerate(LOCATIONS) if np.min(np.abs(pos - (x, y)).max(1)) > 0.25]
    assert free, "test scene covers every location"
    return action_id(free[0], free[0])


class _PositionEncoder(torch.nn.Module):
    """Hand-made effect model: an object's code is the index of the table location under it (7: none).

    It reads the simulator's poses instead of the crops, so codes mean something the tests can
    reason about: a pick-and-release moves an object's code, a stack shares its location's code.
    With constant=True every object has code 0 (every scene aliases every goal).
    """

    def __init__(self, sim, constant: bool = False) -> None:
        super().__init__()
        self.sim, self.constant = sim, constant
        self.cfg = argparse.Namespace(bits=3)
        self.dummy = torch.nn.Parameter(torch.zeros(1))

    def encode(self, crops, mask):
        from symlearn.world import LOCATIONS

        pos = self.sim.get_scene().positions()[:, :2]
        dist = np.linalg.norm(pos[:, None] - np.array(LOCATIONS)[None], axis=2)  # (k, 6)
        codes = np.where(dist.min(1) < 0.1, dist.argmin(1), 7) * (not self.constant)
        bits = (codes[:, None] >> np.arange(2, -1, -1)) & 1
        return torch.tensor(bits[None], dtype=torch.float32), None


class _Still:
    """Toy network: no action changes anything."""

    bits = 3

    def __call__(self, codes, actions):
        return np.array(codes, np.int64)


def _truth(sim, enc, pr, actions) -> tuple[dict, list]:
    """The observed steps of running `actions` open loop: (state -> {action: next} as ObservedTransitions.seen, states)."""
    start = scene_codes(sim, enc, pr.initial)
    ex = execute_plan(sim, pr, _plan(actions, []), enc, start)
    seen: dict = {}
    for s, a, n in zip(ex.observed_states, ex.executed, ex.observed_states[1:]):
        seen.setdefault(s, {})[a] = n
    return seen, list(ex.observed_states)


def _refuse(codes):
    raise AssertionError(f"replanned from {codes}")


# ------------------------------------------------------------------------------- execute_plan


def test_empty_plan_is_not_a_success(sim, encoder, problems):
    pr = problems[0]
    goal = goal_codes(sim, encoder, pr)
    start = scene_codes(sim, encoder, pr.initial)
    ex = execute_plan(sim, pr, _plan([], [start]), encoder, goal)
    assert pr.generator_length >= 1
    assert not ex.success and ex.max_distance_m > GOAL_TOLERANCE_M
    assert ex.executed == () and ex.replans == 0


def test_generator_plan_succeeds(sim, encoder, problems):
    for pr in problems:
        goal = goal_codes(sim, encoder, pr)
        plan = PlanResult(planner="generator", status=PlanStatus.SOLVED, plan=pr.actions, predicted_states=(),
                          expansions=None, planning_time_s=0.0)
        ex = execute_plan(sim, pr, plan, encoder, goal)
        assert ex.success and ex.max_distance_m <= GOAL_TOLERANCE_M, pr.name
        assert ex.symbolic_match  # the same poses render the same crops and codes
        assert ex.executed == pr.actions and len(ex.observed_states) == pr.generator_length + 1


@pytest.mark.parametrize("max_replans", [0, 1, 3])
def test_closed_loop_replans_are_bounded(sim, encoder, problems, max_replans):
    pr = problems[0]
    goal = goal_codes(sim, encoder, pr)
    start = scene_codes(sim, encoder, pr.initial)
    a = _empty_pick(pr)
    calls = []

    def liar(codes):  # always predicts a state the scene never reaches
        calls.append(tuple(codes))
        return _plan([a], [codes, _wrong(codes)])

    cfg = ExecutionConfig(closed_loop=True, max_replans=max_replans)
    ex = execute_plan(sim, pr, _plan([a], [start, _wrong(start)]), encoder, goal, cfg, replan=liar)
    assert ex.replans == len(calls) == max_replans
    assert len(ex.executed) == max_replans + 1
    assert ex.diverged and not ex.on_prediction and not ex.success


class _Shift:
    """Toy network: action 0 adds 1 to object 0's code, action 1 adds 2, others change nothing."""

    bits = 4

    def __call__(self, codes, actions):
        out = np.array(codes, np.int64)
        out[:, 0] = np.where(actions == 0, out[:, 0] + 1, np.where(actions == 1, out[:, 0] + 2, out[:, 0])) % 16
        return out

    def scored(self, codes, actions):
        """Every prediction with -log P = 0.5 (enough for ObservedTransitions to show which it answers itself)."""
        return self(codes, actions), np.full(len(codes), 0.5)

    def bit_probabilities(self, codes, actions):
        """Every bit of object 0 a coin flip, 0.25 to be set; object 1's bits as they are (certain)."""
        out = ((np.asarray(codes)[..., None] >> np.arange(3, -1, -1)) & 1).astype(float)
        out[:, 0] = 0.25
        return out


def test_observed_transitions_override_only_what_was_seen():
    from search.learned_astar import plan_symbolic
    from pddl_export.symbolic import SymbolicGoal

    memory = ObservedTransitions(_Shift())
    codes = np.array([[3, 5], [3, 5], [4, 5], [3, 5]])
    actions = np.array([0, 1, 0, 2])
    assert memory(codes, actions).tolist() == [[4, 5], [5, 5], [5, 5], [3, 5]]
    memory.record((3, 5), 0, (3, 5))  # in (3, 5) action 0 was seen to do nothing
    assert memory(codes, actions).tolist() == [[3, 5], [5, 5], [5, 5], [3, 5]]
    memory.record((4, 5), 0, (4, 5))
    nxt, nll = memory.scored(codes, actions)  # observed steps: their outcome, with certainty
    assert nxt.tolist() == [[3, 5], [5, 5], [4, 5], [3, 5]] and nll.tolist() == [0.0, 0.5, 0.0, 0.5]
    with pytest.raises(ValueError, match="does not score"):
        ObservedTransitions(_Still()).scored(codes, actions)
    # bit probabilities: an observed step's are its observed bits, certain; the rest are the network's
    p = memory.bit_probabilities(codes, actions)
    assert p.shape == (4, 2, 4)
    assert p[0].tolist() == [[0, 0, 1, 1], [0, 1, 0, 1]] and p[2].tolist() == [[0, 1, 0, 0], [0, 1, 0, 1]]
    assert p[1, 0].tolist() == [0.25] * 4 and p[3, 0].tolist() == [0.25] * 4
    with pytest.raises(ValueError, match="no bit probabilities"):
        ObservedTransitions(_Still()).bit_probabilities(codes, actions)
    goal = SymbolicGoal((4, None))
    assert plan_symbolic(_Shift(), np.array([3, 5]), goal, uniform_cost=True).plan == (0,)
    replanned = plan_symbolic(memory, np.array([3, 5]), goal, uniform_cost=True)
    assert replanned.found and replanned.plan[0] != 0 and replanned.predicted_states[-1][0] == 4


def test_closed_loop_records_every_executed_step(sim, encoder, problems):
    pr = problems[0]
    goal = goal_codes(sim, encoder, pr)
    start = scene_codes(sim, encoder, pr.initial)
    a = _empty_pick(pr)
    seen = []
    cfg = ExecutionConfig(closed_loop=True, max_replans=1)
    ex = execute_plan(sim, pr, _plan([a], [start, _wrong(start)]), encoder, goal, cfg,
                      replan=lambda codes: _plan([a], [codes, _wrong(codes)]), record=lambda *step: seen.append(step))
    assert [(s, act, n) for s, act, n in seen] == [(ex.observed_states[i], ex.executed[i], ex.observed_states[i + 1])
                                                   for i in range(len(ex.executed))]


@pytest.mark.parametrize("keep", [True, False])
def test_a_failed_replan_keeps_the_plan_running_or_stops(sim, encoder, problems, keep):
    """The first step departs from its prediction and the replan finds nothing: by default the plan's other two
    steps still run (as open loop would); with keep_plan_on_failed_replan off, execution stops there."""
    pr = problems[0]
    goal = goal_codes(sim, encoder, pr)
    start = scene_codes(sim, encoder, pr.initial)
    a = _empty_pick(pr)
    fail = PlanResult(planner="t", status=PlanStatus.UNSOLVABLE, plan=(), predicted_states=(), expansions=3,
                      planning_time_s=0.0)
    plan = _plan([a, a, a], [start, _wrong(start), start, start])
    cfg = ExecutionConfig(closed_loop=True, keep_plan_on_failed_replan=keep)
    ex = execute_plan(sim, pr, plan, encoder, goal, cfg, replan=lambda c: fail)
    assert ex.replan_failed and ex.replans == 1 and len(ex.executed) == (3 if keep else 1)
    assert all(tuple(s) == tuple(start) for s in ex.observed_states[1:])  # an empty pick leaves the scene as it was


def test_closed_loop_needs_a_replan_function(sim, encoder, problems):
    with pytest.raises(ValueError, match="replan"):
        execute_plan(sim, problems[0], _plan([], [(0,) * problems[0].k]), encoder, [0] * problems[0].k,
                     ExecutionConfig(closed_loop=True))


# ------------------------------------------------------------------------------- run_problem and failure stages


def _fixed(result_of):
    """A planner function returning result_of(start_codes, goal)."""
    return lambda transition, start, goal, timeout_s: result_of(start, goal)


@pytest.mark.parametrize("status, stage", [(PlanStatus.UNSOLVABLE, "no_plan"), (PlanStatus.NODE_LIMIT, "no_plan"),
                                           (PlanStatus.TIMEOUT, "timeout"), (PlanStatus.ERROR, "no_plan")])
def test_no_plan_stages(sim, encoder, run_dir, problems, status, stage):
    fn = _fixed(lambda s, g: PlanResult(planner="t", status=status, plan=(), predicted_states=(), expansions=None,
                                        planning_time_s=0.0))
    row = run_problem(sim, encoder, LearnedTransition.from_run(run_dir), problems[0], "t", fn, OPEN_LOOP)
    assert not row.found and row.failure_stage == stage and row.plan_length is None
    assert row.failure_cause == stage and row.attribution["first_departure_step"] is None
    assert row.attribution["rules_net_disagree"] is None and row.attribution["replans"] == 0
    assert not row.success and row.max_distance_m is None and row.status == status.value


def test_a_proof_from_shared_start_codes_is_its_own_cause():
    proved = PlanResult(planner="rules-bfs", status=PlanStatus.UNSOLVABLE, plan=(), predicted_states=(),
                        expansions=0, planning_time_s=0.0, extra={"proof": "coincidence"})
    exhausted = dataclasses.replace(proved, extra={})
    assert failure_cause(proved, None) == "shared_code" and failure_cause(exhausted, None) == "no_plan"
    assert "shared_code" in FAILURE_CAUSES


def test_raising_planner_becomes_an_error_row(sim, encoder, run_dir, problems):
    def boom(*args):
        raise RuntimeError("engine crashed\nwith two lines")

    row = run_problem(sim, encoder, LearnedTransition.from_run(run_dir), problems[0], "boom", boom, OPEN_LOOP)
    assert row.status == "error" and row.failure_stage == "no_plan" and "engine crashed" in row.message
    assert "\n" not in row.message


def test_execution_and_goal_mismatch_stages(sim, encoder, run_dir, problems):
    pr = problems[0]
    tr = LearnedTransition.from_run(run_dir)
    a = _empty_pick(pr)
    departs = _fixed(lambda s, g: _plan([a], [s, _wrong(s)]))  # predicts a change that never happens
    row = run_problem(sim, encoder, tr, pr, "departs", departs, OPEN_LOOP)
    assert row.found and not row.success and row.failure_stage == "execution"
    stays = _fixed(lambda s, g: _plan([a], [s, s]))  # correct prediction, but the scene is far from the goal
    row = run_problem(sim, encoder, tr, pr, "stays", stays, OPEN_LOOP)
    assert row.found and not row.success and row.failure_stage == "goal_mismatch"
    generator = _fixed(lambda s, g: PlanResult(planner="gen", status=PlanStatus.SOLVED, plan=pr.actions,
                                               predicted_states=(), expansions=None, planning_time_s=0.0))
    row = run_problem(sim, encoder, tr, pr, "gen", generator, OPEN_LOOP)
    assert row.success and row.failure_stage is None and row.plan_length == pr.generator_length


def test_run_problem_closed_loop_row(sim, problems):
    pr = problems[0]
    a = _empty_pick(pr)
    liar = _fixed(lambda s, g: _plan([a], [s, _wrong(s)]))
    row = run_problem(sim, _PositionEncoder(sim), _Still(), pr, "liar", liar,
                      ExecutionConfig(closed_loop=True, max_replans=2))
    assert row.closed_loop and row.replans == 2 and row.failure_stage == "execution"
    assert row.failure_cause == "departure" and row.attribution["replans"] == 2
    assert json.loads(json.dumps(row.to_json()))["replans"] == 2


def test_problem_run_validation():
    base = dict(problem="p", planner="astar", found=True, status="solved", plan_length=1, planning_time_s=0.1,
                expansions=2, success=False, symbolic_match=False, max_distance_m=0.3, closed_loop=False,
                replans=0, generator_length=1)
    with pytest.raises(ValueError, match="unknown failure stage"):
        ProblemRun(**base, failure_stage="physics")
    with pytest.raises(ValueError, match="no failure stage or cause"):
        ProblemRun(**{**base, "success": True}, failure_stage="execution")
    with pytest.raises(ValueError, match="no failure stage or cause"):
        ProblemRun(**{**base, "success": True}, failure_stage=None, failure_cause="departure")
    with pytest.raises(ValueError, match="unknown failure cause 'gremlins'"):
        ProblemRun(**base, failure_stage="execution", failure_cause="gremlins")


# ------------------------------------------------------------------------------- benchmark and registry


def test_benchmark_writes_summary_and_rows(tmp_path, sim, run_dir, problems):
    pdir = tmp_path / "problems"
    generate_problems(pdir, 2, objects=(1, 2), length=(1, 2), seed=11, sim=sim)
    out = tmp_path / "bench.json"
    res = bench.benchmark(run_dir, pdir, ["astar", "astar-ucs"], out, closed_loop=True, timeout_s=2.0,
                          show_progress=False)
    saved = json.loads(out.read_text())
    assert saved["summary"] == res["summary"] and len(saved["rows"]) == 2 * 2 * 2
    for name in ("astar", "astar-ucs"):
        s = saved["summary"][name]
        assert {"success_rate", "found_rate", "median_time_s", "mean_plan_length", "mean_generator_length",
                "success_rate_closed_loop"} <= set(s)
        # the summary is the rows' aggregate: recompute it from the rows
        open_rows = [r for r in saved["rows"] if r["planner"] == name and not r["closed_loop"]]
        closed = [r for r in saved["rows"] if r["planner"] == name and r["closed_loop"]]
        assert len(open_rows) == len(closed) == s["n_problems"] == 2
        assert s["success_rate"] == pytest.approx(np.mean([r["success"] for r in open_rows]), abs=1e-4)
        assert s["found_rate"] == pytest.approx(np.mean([r["found"] for r in open_rows]), abs=1e-4)
        assert s["success_rate_closed_loop"] == pytest.approx(np.mean([r["success"] for r in closed]), abs=1e-4)
        stages = [r["failure_stage"] for r in open_rows if r["failure_stage"]]
        assert s["failure_stages"] == {st: stages.count(st) for st in set(stages)}
        assert all((r["failure_stage"] is None) == r["success"] for r in saved["rows"])
        assert all((r["plan_length"] is None) != r["found"] for r in saved["rows"])  # a length exactly with a plan
        lengths = [r["plan_length"] for r in open_rows if r["found"]]
        assert s["mean_plan_length"] == (pytest.approx(np.mean(lengths), abs=1e-3) if lengths else None)
    assert {r["closed_loop"] for r in saved["rows"]} == {False, True}
    assert "astar-ucs" in benchmark_summary.format_table(res)
    assert "risk_weight" not in saved  # no planner here depends on it
    # every row knows how many goal objects lie off the locations; the split adds up to the problems
    offs = {r["problem"]: r["goal_off_locations"] for r in saved["rows"]}
    assert offs == {pr.name: pr.goal_off_locations for _, pr in load_problems(pdir)}
    for name in ("astar", "astar-ucs"):
        parts = saved["goal_placement"][name]
        assert sum(c["n_problems"] for c in parts.values()) == 2
        for key, c in parts.items():
            mine = [r for r in saved["rows"] if r["planner"] == name and r["closed_loop"]
                    and (r["goal_off_locations"] > 0) == (key == "off_locations")]
            assert c["success_rate_closed_loop"] == pytest.approx(np.mean([r["success"] for r in mine]), abs=1e-4)
            assert sum(c["closed_loop_failure_causes"].values()) == sum(not r["success"] for r in mine)
    assert benchmark_summary.format_goal_placement(res).startswith("astar: success open/closed, goals o")


def test_benchmark_records_the_risk_weight_of_astar_outcomes(tmp_path, sim, run_dir):
    pdir = tmp_path / "problems"
    generate_problems(pdir, 2, objects=(1, 2), length=(1, 2), seed=12, sim=sim)
    res = bench.benchmark(run_dir, pdir, ["astar-outcomes"], tmp_path / "b.json", timeout_s=2.0, closed_loop=False,
                          show_progress=False, planner_config=PlannerConfig(risk_weight=2.5))
    assert res["risk_weight"] == 2.5 and len(res["rows"]) == 2
    assert all(r["planner"] == "astar-outcomes" for r in res["rows"])
    # an interrupted run resumes only under the same weight: the weight is part of the settings
    problems = benchmark_rows.load_sets([pdir])
    ex = ExecutionConfig(timeout_s=2.0)
    settings = [bench._settings(run_dir, [pdir], problems, ["astar-outcomes"], ex, PlannerConfig(risk_weight=w))
                for w in (1.0, 2.5)]
    assert settings[0]["risk_weight"] == 1.0 and settings[0] != settings[1]
    weighted = PlannerConfig(risk_weight=2.5)
    assert bench._settings(run_dir, [pdir], problems, ["astar", "astar-outcomes"], ex, weighted)["risk_weight"] == 2.5
    assert "risk_weight" not in bench._settings(run_dir, [pdir], problems, ["astar"], ex, weighted)


def test_unknown_planner_lists_every_planner(tmp_path, run_dir):
    with pytest.raises(ValueError, match="unknown planner 'ghost'; known: astar-outcomes, astar, astar-ucs, ") as info:
        bench.benchmark(run_dir, tmp_path, ["astar", "ghost"], tmp_path / "b.json")
    msg = str(info.value)
    assert "\n" not in msg and all(name in msg for name in PLANNERS)


def test_registry_holds_every_planner_and_is_immutable():
    assert list(PLANNERS) == ["astar-outcomes", "astar", "astar-ucs", "fast-downward-lifted",
                              "fast-downward-lifted-opt", "fast-downward-lifted-outcomes", "rules-outcomes",
                              "rules-bfs", "fast-downward", "pyperplan"]
    assert [n for n, s in PLANNERS.items() if not s.needs_rules and not s.needs_lifted] == [
        "astar-outcomes", "astar", "astar-ucs"]
    assert [n for n, s in PLANNERS.items() if s.needs_lifted] == ["fast-downward-lifted", "fast-downward-lifted-opt",
                                                                  "fast-downward-lifted-outcomes"]
    assert all(s.name == n and s.purpose and s.reason for n, s in PLANNERS.items())
    with pytest.raises(TypeError):
        PLANNERS["mine"] = PLANNERS["astar"]  # type: ignore[index]
    with pytest.raises(dataclasses.FrozenInstanceError):
        PLANNERS["astar"].needs_rules = True  # type: ignore[misc]


def test_make_planner_builds_and_refuses(tmp_path, run_dir):
    res = make_planner("astar-ucs")(LearnedTransition.from_run(run_dir), np.array([0]), SymbolicGoal((0,)), 2.0)
    assert res.planner == "astar-ucs" and res.found and res.plan == ()
    m = LearnedTransition.from_run(run_dir)
    start = np.array([0, 0])
    nxt = m(np.repeat(start[None], 36, 0), np.arange(36))
    moved = np.flatnonzero((nxt != start).any(1))
    if len(moved):  # a goal one step away: the likely plan's log_p is that step's log P under the network
        goal = tuple(int(c) for c in nxt[moved[0]])
        # every outcome the all-outcomes planner may follow from the start, the likeliest first
        res = make_planner("astar-outcomes")(m, start, SymbolicGoal(goal), 5.0)
        assert res.planner == "astar-outcomes" and res.found and res.predicted_states[-1] == goal
        assert res.extra["max_outcomes"] == 4 and res.extra["log_p"] <= 0
        p = m.bit_probabilities(np.array(res.predicted_states[:-1]), np.array(res.plan))
        step = np.array([[((c >> np.arange(m.bits - 1, -1, -1)) & 1) for c in s] for s in res.predicted_states[1:]])
        assert res.extra["log_p"] == pytest.approx(np.log(np.where(step == 1, p, 1 - p)).sum(), abs=1e-5)
    with pytest.raises(ValueError, match="plans on the exported rules, and none were given"):
        make_planner("fast-downward", PlannerContext())
    with pytest.raises(ValueError, match="no exported rules"):  # rules are read only when a planner needs them
        PlannerContext.for_run(tmp_path, ["astar", "rules-bfs"])
    assert PlannerContext.for_run(tmp_path, ["astar", "astar-ucs"]).rules is None
    config = PlannerConfig(risk_weight=3.0)
    assert PlannerContext.for_run(tmp_path, ["astar-outcomes"], config=config).config.risk_weight == 3.0
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="risk_weight="):
            PlannerConfig(risk_weight=bad)


def test_failure_stage_values_are_the_json_strings():
    assert [s.value for s in FailureStage] == ["no_plan", "timeout", "execution", "goal_mismatch", "rules_vs_net"]
    base = dict(problem="p", planner="astar", found=False, status="timeout", plan_length=None, planning_time_s=0.1,
                expansions=None, success=False, symbolic_match=False, max_distance_m=None, closed_loop=False,
                replans=0, generator_length=1)
    row = ProblemRun(**base, failure_stage="timeout")
    assert row.failure_stage is FailureStage.TIMEOUT and f"{row.failure_stage}" == "timeout"
    assert json.loads(json.dumps(row.to_json()))["failure_stage"] == "timeout"
    assert benchmark_summary.summarize_rows([row])["astar"]["failure_stages"] == {"timeout": 1}


def test_cli_parses_planning_commands(tmp_path):
    from symlearn.cli.planning import execution_config, planner_config
    from symlearn.config_file import ConfigFileError, read_config_file
    from symlearn.symbolic.transition_model import TransitionConfig

    p = argparse.ArgumentParser(prog="symlearn")
    sub = p.add_subparsers(dest="command", required=True)
    add_planning_commands(sub)
    a = p.parse_args(["problems", "--out", "x", "--n", "3", "--objects", "4-5", "--length", "2", "--seed", "1"])
    assert (a.objects, a.length, a.n, a.kind) == ((4, 5), (2, 2), 3, None) and a.func.__name__ == "cmd_problems"
    a = p.parse_args(["benchmark", "--run", "r", "--problems", "d", "--planners", "astar,astar-ucs", "--out", "o"])
    assert a.planners == ["astar", "astar-ucs"] and a.func.__name__ == "cmd_benchmark"
    assert execution_config(a) == ExecutionConfig() and ExecutionConfig().closed_loop  # the recipe's
    a = p.parse_args(["plan", "--run", "r", "--problem", "f.json", "--planner", "astar-ucs", "--timeout", "5"])
    assert a.planner == "astar-ucs" and a.func.__name__ == "cmd_plan"
    assert execution_config(a) == ExecutionConfig(timeout_s=5.0)
    config = tmp_path / "open.toml"
    config.write_text("[execution]\nclosed_loop = false\ntimeout_s = 30\n[planner]\nrisk_weight = 2\n")
    a = p.parse_args(["plan", "--run", "r", "--problem", "f.json", "--config", str(config), "--timeout", "7"])
    got = execution_config(a)  # the file over the recipe, the flag over the file
    assert (got.closed_loop, got.timeout_s, got.max_replans) == (False, 7.0, 3)
    assert planner_config(a) == PlannerConfig(risk_weight=2.0)
    for bad in ("0", "-1", "nan"):
        config.write_text(f"[planner]\nrisk_weight = {bad}\n")
        with pytest.raises((ValueError, ConfigFileError)):
            planner_config(p.parse_args(["plan", "--run", "r", "--problem", "f", "--config", str(config)]))
    a = p.parse_args(["train-transition", "--run", "r", "--data", "d", "--preset", "quick"])
    assert (a.preset, a.seed, a.config) == ("quick", 0, None) and a.func.__name__ == "cmd_train_transition"
    assert p.parse_args(["train-transition", "--run", "r", "--data", "d"]).preset == "recommended"
    assert TransitionConfig.from_preset("recommended").location_bits == 9  # what the lifted domain reads
    for n in (4, 5, 6, 7, 9):
        config.write_text(f"[transition]\nlocation_bits = {n}\nmodes = 4\n")
        assert TransitionConfig.from_preset("quick", **read_config_file(config)["transition"]).location_bits == n
    for bad in (3, 8, 10):
        config.write_text(f"[transition]\nlocation_bits = {bad}\n")
        with pytest.raises(ValueError, match="location_bits"):
            TransitionConfig.from_preset("quick", **read_config_file(config)["transition"])
    config.write_text("[transition]\nmodes = 0\n")
    with pytest.raises(ValueError, match="modes=0"):
        TransitionConfig.from_preset("quick", **read_config_file(config)["transition"])


def test_cli_problems_command(tmp_path):
    p = argparse.ArgumentParser(prog="symlearn")
    add_planning_commands(p.add_subparsers(dest="command", required=True))
    args = p.parse_args(["problems", "--kind", "walks", "--out", str(tmp_path / "pp"), "--n", "1", "--objects", "1-2",
                         "--seed", "2"])
    assert args.func(args) == 0
    assert load_problem(tmp_path / "pp" / "problem_0000.json").k in (1, 2)
    args = p.parse_args(["problems", "--out", str(tmp_path / "on"), "--n", "2", "--objects", "1-2", "--seed", "2",
                         "--length", "2-3", "--kind", "located-walks"])
    assert args.func(args) == 0
    assert [load_problem(f).goal_off_locations for f in sorted((tmp_path / "on").glob("*.json"))] == [0, 0]
    args = p.parse_args(["problems", "--out", str(tmp_path / "s"), "--kind", "structures", "--exclude", "x"])
    with pytest.raises(ValueError, match="--exclude does not apply to --kind structures"):
        args.func(args)
    args = p.parse_args(["problems", "--out", str(tmp_path / "t"), "--length", "1-2"])  # the default: stratified
    with pytest.raises(ValueError, match="--length does not apply to --kind stratified"):
        args.func(args)
    assert not (tmp_path / "s").exists() and not (tmp_path / "t").exists()


# ------------------------------------------------------------------------------- recovery and attribution


def test_departure_whose_rest_still_reaches_the_goal_is_continued(sim, walks):
    enc = _PositionEncoder(sim)
    pr = walks[0]
    seen, states = _truth(sim, enc, pr, pr.actions)
    assert states[-1] == tuple(goal_codes(sim, enc, pr))
    predicted = [states[0], _wrong(states[1]), *states[2:]]  # wrong about the first step only
    cfg = ExecutionConfig(closed_loop=True, max_replans=1)
    ignorant = ObservedTransitions(_Still())  # one model that cannot see the rest work is not enough to abandon it
    ex = execute_plan(sim, pr, _plan(pr.actions, predicted), enc, states[-1], cfg, replan=_refuse,
                      models=[ignorant, ObservedTransitions(_Still(), seen)])
    assert ex.continued == 1 and ex.replans == 0 and ex.fallbacks == 0
    assert ex.executed == pr.actions and ex.success and ex.diverged
    assert ex.first_departure_step == 0 and ex.departed_objects == tuple(range(pr.k))
    calls = []  # without a model to roll the rest, the same departure is replanned
    ex = execute_plan(sim, pr, _plan(pr.actions, predicted), enc, states[-1], cfg,
                      replan=lambda c: calls.append(tuple(c)) or _plan([], [c]))
    assert calls == [states[1]] and ex.replans == 1 and ex.executed == pr.actions[:1] and not ex.success


def test_fallback_to_an_alternative_plan(sim, walks):
    enc = _PositionEncoder(sim)
    pr = walks[1]
    seen, states = _truth(sim, enc, pr, pr.actions)
    a0 = _empty_pick(pr)  # the main plan claims this empty pick does what the first reference step does
    main = dataclasses.replace(_plan([a0, *pr.actions[1:]], states), alternatives=((pr.actions, tuple(states)),))
    cfg = ExecutionConfig(closed_loop=True, max_replans=1)
    ex = execute_plan(sim, pr, main, enc, states[-1], cfg, replan=_refuse, models=[ObservedTransitions(_Still(), seen)])
    assert ex.fallbacks == 1 and ex.replans == 0 and ex.continued == 0
    assert ex.executed == (a0, *pr.actions) and ex.success and ex.on_prediction
    ex = execute_plan(sim, pr, main, enc, states[-1], dataclasses.replace(cfg, max_fallbacks=0),
                      replan=lambda c: _plan([], [c]), models=[ObservedTransitions(_Still(), seen)])
    assert ex.fallbacks == 0 and ex.replans == 1 and not ex.success


def test_plan_ending_away_from_the_goal_is_replanned(sim, walks):
    enc = _PositionEncoder(sim)
    pr = walks[0]
    states = _truth(sim, enc, pr, pr.actions)[1]
    calls = []
    ex = execute_plan(sim, pr, _plan([], states[:1]), enc, states[-1], ExecutionConfig(closed_loop=True),
                      replan=lambda c: calls.append(tuple(c)) or _plan(pr.actions, states))
    assert calls == [states[0]] and ex.replans == 1 and ex.success and ex.executed == pr.actions
    ex = execute_plan(sim, pr, _plan([], states[:1]), enc, states[-1])  # open loop: nothing more
    assert ex.executed == () and not ex.success


def _rows(sim, pr):
    """A departure, an aliasing, a no-plan and a successful row of one problem, with hand-made encoders."""
    a = _empty_pick(pr)
    enc, blind = _PositionEncoder(sim), _PositionEncoder(sim, constant=True)
    s = tuple(scene_codes(sim, enc, pr.initial))
    rules = RuleSet(bits=3, vocabulary=tuple(range(8)), max_objects=3, n_rules_before_generalization=0,
                    rules=(Rule(action=a, code_from=s[0], code_to=s[0] ^ 1),))  # rules say a moves object 0
    departs = run_problem(sim, enc, _Still(), pr, "departs", _fixed(lambda s, g: _plan([a], [s, _wrong(s)])),
                          OPEN_LOOP, rules=rules)
    aliased = run_problem(sim, blind, _Still(), pr, "stays", _fixed(lambda s, g: _plan([a], [s, s])),
                          OPEN_LOOP)
    none = run_problem(sim, enc, _Still(), pr, "none", _fixed(lambda s, g: PlanResult(
        planner="none", status=PlanStatus.UNSOLVABLE, plan=(), predicted_states=(), expansions=0, planning_time_s=0)), OPEN_LOOP)
    gen = run_problem(sim, enc, _Still(), pr, "gen", _fixed(lambda s, g: _plan(pr.actions, [])), OPEN_LOOP)
    return departs, aliased, none, gen


def test_failure_attribution_per_cause(sim, walks):
    pr = walks[0]
    departs, aliased, none, gen = _rows(sim, pr)
    assert departs.failure_cause == "departure" and departs.failure_stage == "execution"
    assert departs.attribution == {"first_departure_step": 0, "departed_objects": list(range(pr.k)),
                                   "rules_net_disagree": True, "aliasing": False, "replans": 0,
                                   "replan_failed": False, "continued": 0, "fallbacks": 0}
    assert aliased.failure_cause == "symbol_aliasing" and aliased.symbolic_match and not aliased.success
    assert aliased.attribution["aliasing"] and aliased.attribution["first_departure_step"] is None
    assert aliased.max_distance_m > GOAL_TOLERANCE_M
    assert none.failure_cause == "no_plan" and none.attribution["departed_objects"] == []
    assert gen.success and gen.failure_cause is None and gen.attribution["first_departure_step"] is None
    a = _empty_pick(pr)
    enc = _PositionEncoder(sim)
    agree = RuleSet(bits=3, vocabulary=tuple(range(8)), max_objects=3, n_rules_before_generalization=0, rules=())
    for rules, want in ((agree, False), (None, None)):
        row = run_problem(sim, enc, _Still(), pr, "d", _fixed(lambda s, g: _plan([a], [s, _wrong(s)])), OPEN_LOOP,
                          rules=rules)
        assert row.failure_cause == "departure" and row.attribution["rules_net_disagree"] is want


def test_failure_causes_add_up_to_the_failures(sim, walks):
    rows = [r for pr in walks[:2] for r in _rows(sim, pr)]
    counts = failure_causes(rows)
    assert counts == {"departure": 2, "no_plan": 2, "symbol_aliasing": 2}
    assert sum(counts.values()) == sum(not r.success for r in rows)
    as_json = [json.loads(json.dumps(r.to_json())) for r in rows]
    assert failure_causes(as_json) == counts
    legacy = {k: v for k, v in as_json[0].items() if k != "failure_cause"}
    assert failure_causes([legacy]) == {"unattributed": 1}


def test_rules_planner_replans_on_the_overridden_rules(tmp_path):
    from pddl_export.overrides import override_rules
    from symlearn.planning.planners import RulesTransition, make_pddl_planner

    rules = RuleSet(bits=2, vocabulary=(0, 1, 2, 3), max_objects=2, n_rules_before_generalization=0,
                    rules=(Rule(action=4, code_from=1, code_to=3), Rule(action=17, code_from=1, code_to=2),
                           Rule(action=17, code_from=2, code_to=3)))
    plan = make_pddl_planner(rules, "h", "fast-downward", write_dir=tmp_path)
    goal = SymbolicGoal((3, None))
    first = plan(RulesTransition(rules), np.array([1, 0]), goal, 20.0)
    assert first.plan == (4,) and not first.extra["rules_vs_net"]
    memory = ObservedTransitions(RulesTransition(rules))
    memory.record((1, 0), 4, (1, 0))  # execution showed that action 4 does nothing here
    second = plan(memory, np.array([1, 0]), goal, 20.0)
    assert second.plan == (17, 17) and not second.extra["rules_vs_net"], second.message
    fixed = override_rules(rules, memory.seen)
    assert (tmp_path / "domain_2.pddl").read_text() == conditional_domain(fixed, "h")  # the rules it replanned on
    assert (tmp_path / "problem.pddl").read_text() == problem_pddl(rules, [1, 0], goal, "h")
    assert (tmp_path / "problem_2.pddl").read_text() == problem_pddl(fixed, [1, 0], goal, "h")
