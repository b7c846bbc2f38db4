"""Executing symbolic plans in the simulator: open loop, or closed loop with replanning.

A plan (a PlanResult from any planner) is run action by action with `sim.step` from the
problem's initial poses. After each action the real scene is rendered and encoded; the codes
are compared with the planner's predicted state. Success is geometric (every object within
2 cm of its goal position); the symbolic match (final codes == goal codes) is reported beside
it. With `closed_loop=True`, a departure from the prediction triggers replanning from the
observed codes, at most `max_replans` times; the replanning search uses the network corrected
by every transition seen so far in this execution (ObservedTransitions), so it does not repeat an
action the scene has just answered differently than predicted.

    >>> row = run_problem(sim, encoder, transition, problem, "astar", make_planner("astar"),
    ...                   ExecutionConfig(closed_loop=True))                       # doctest: +SKIP
    >>> row.found, row.plan_length, row.success, row.failure_stage               # doctest: +SKIP
    (True, 2, True, None)
"""
from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from enum import Enum
from typing import Callable

import numpy as np

from search.result import PlanResult, PlanStatus, failed
from pddl_export.symbolic import SymbolicGoal, TransitionFn
from symlearn.planning.problem import GOAL_TOLERANCE_M, Problem
from symlearn.planning.scenes import max_goal_distance, place_scene, symbolic_goal
from symlearn.symbolic.transition_data import encode_observation
from symlearn.world import decode_action

PlannerFn = Callable[[TransitionFn, np.ndarray, SymbolicGoal, float], PlanResult]


class FailureStage(str, Enum):
    """Where a benchmark run failed; the value is what the JSON rows and summaries hold."""

    def __str__(self) -> str:  # as StrEnum (Python 3.11+) does, on 3.10 too
        return self.value

    NO_PLAN = "no_plan"  # the planner found no plan (unsolvable, node limit, error)
    TIMEOUT = "timeout"  # the planner ran out of time
    EXECUTION = "execution"  # the executed scene departed from the plan's predictions
    GOAL_MISMATCH = "goal_mismatch"  # the plan ran as predicted but the scene is not within tolerance of the goal
    RULES_VS_NET = "rules_vs_net"  # the PDDL plan's states are not what the network predicts


@dataclass(frozen=True)
class ExecutionConfig:
    """How plans are executed and judged."""

    tolerance_m: float = GOAL_TOLERANCE_M  # every object within 2 cm of its goal position
    closed_loop: bool = False  # replan when the observed codes depart from the prediction
    max_replans: int = 3  # bound on replanning calls per problem
    timeout_s: float = 30.0  # per planner call

    def __post_init__(self) -> None:
        if not self.tolerance_m > 0:
            raise ValueError(f"tolerance_m={self.tolerance_m} must be positive")
        if self.max_replans < 0:
            raise ValueError(f"max_replans={self.max_replans} must be >= 0")
        if not self.timeout_s > 0:
            raise ValueError(f"timeout_s={self.timeout_s} must be positive")


@dataclass(frozen=True)
class ExecutionResult:
    """What executing a plan did: geometric and symbolic outcome, trajectory of observed codes."""

    success: bool  # every object within tolerance of its goal position
    symbolic_match: bool  # final observed codes == goal codes
    max_distance_m: float  # largest object distance to its goal position
    executed: tuple[int, ...]  # action ids actually run, across replans
    observed_states: tuple[tuple[int, ...], ...]  # codes at the start and after each executed action
    diverged: bool  # the observed codes departed from a prediction at some step
    on_prediction: bool  # the last plan's steps all matched their predictions (end state included)
    replans: int
    replan_failed: bool  # a replanning call found no plan, so execution stopped
    off_table: bool  # some object fell off the table


class ObservedTransitions:
    """The network, except where execution has shown what an action does in a symbolic state.

    Closed-loop replanning searches with this model: every executed (state, action) ->
    observed next state is recorded and answered from memory, so a replan does not choose
    an action again in the state where the network was just proven wrong about it.
    """

    def __init__(self, inner: TransitionFn) -> None:
        self.inner, self.bits = inner, inner.bits
        self.seen: dict[tuple[int, ...], dict[int, tuple[int, ...]]] = {}  # state -> {action: next}

    def record(self, state, action: int, nxt) -> None:
        self.seen.setdefault(tuple(int(c) for c in state), {})[int(action)] = tuple(int(c) for c in nxt)

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = np.array(self.inner(codes, actions), np.int64)
        if not self.seen or len(codes) == 0:
            return out
        codes, actions = np.asarray(codes), np.asarray(actions)
        states, inverse = np.unique(codes, axis=0, return_inverse=True)  # an A* expansion: one state
        for j, state in enumerate(states.tolist()):
            known = self.seen.get(tuple(state))
            if not known:
                continue
            rows = np.flatnonzero((inverse.reshape(-1) == j) & np.isin(actions, list(known)))
            for i in rows:
                out[i] = known[int(actions[i])]
        return out


def _codes(sim, encoder) -> tuple[int, ...]:
    return tuple(int(c) for c in encode_observation(encoder, sim.observe()))


def execute_plan(sim, problem: Problem, plan: PlanResult, encoder, goal: SymbolicGoal | np.ndarray,
                 config: ExecutionConfig = ExecutionConfig(),
                 replan: Callable[[np.ndarray], PlanResult] | None = None,
                 record: Callable[[tuple, int, tuple], None] | None = None, recorder=None) -> ExecutionResult:
    """Run plan.plan from the problem's initial poses; closed loop replans with `replan(observed_codes)`.

    `record(state, action, observed_next)` hears every executed step (ObservedTransitions.record);
    `recorder` (a symlearn.planning.recording.PlanRecorder) takes a camera frame at the start and after each step.
    """
    if config.closed_loop and replan is None:
        raise ValueError("closed-loop execution needs a replan function")
    goal = goal if isinstance(goal, SymbolicGoal) else SymbolicGoal(tuple(int(c) for c in goal))
    place_scene(sim, problem.initial)
    if recorder is not None:
        recorder.start(sim)
    codes = _codes(sim, encoder)
    observed, executed = [codes], []
    actions, predicted = list(plan.plan), list(plan.predicted_states)
    t, replans, diverged, segment_ok, replan_failed, off_table = 0, 0, False, True, False, False
    while t < len(actions):
        res = sim.step(decode_action(actions[t]))
        off_table |= res.off_table
        executed.append(actions[t])
        if recorder is not None:
            recorder.step(sim, actions[t])
        before, codes = codes, _codes(sim, encoder)
        observed.append(codes)
        if record is not None:
            record(before, actions[t], codes)
        if predicted and codes != predicted[t + 1]:
            diverged, segment_ok = True, False
            if config.closed_loop and replans < config.max_replans:
                replans += 1
                new = replan(np.asarray(codes, np.int64))
                if not new.found:
                    replan_failed = True
                    break
                actions, predicted, t, segment_ok = list(new.plan), list(new.predicted_states), 0, True
                continue
        t += 1
    if not predicted:  # a planner without predictions: judge the end state only
        segment_ok = bool(goal.satisfied(np.asarray(codes, np.int64))[0])
    dist = max_goal_distance(sim.get_scene(), problem.goal, problem.free)
    return ExecutionResult(success=dist <= config.tolerance_m and not off_table,
                           symbolic_match=bool(goal.satisfied(np.asarray(codes, np.int64))[0]),
                           max_distance_m=dist, executed=tuple(executed), observed_states=tuple(observed),
                           diverged=diverged, on_prediction=segment_ok and not replan_failed, replans=replans,
                           replan_failed=replan_failed, off_table=off_table)


@dataclass(frozen=True)
class ProblemRun:
    """One benchmark row: a planner on a problem, planned and executed."""

    problem: str
    planner: str
    found: bool
    status: str  # PlanStatus value of the initial planning call
    plan_length: int | None  # None when no plan was found
    planning_time_s: float
    expansions: int | None
    success: bool
    symbolic_match: bool
    max_distance_m: float | None  # None when nothing was executed
    closed_loop: bool
    replans: int
    failure_stage: FailureStage | None  # a FailureStage (or its value), None on success
    generator_length: int
    message: str = ""
    n_objects: int = 0
    timings: dict = field(default_factory=dict)  # planner-specific, e.g. pddl_write_time_s, planner_time_s
    task: str = "random-walk"  # the problem's task (Problem.task)
    failure_cause: str | None = None  # the attributed cause of a failure (see failure attribution), None on success
    attribution: dict = field(default_factory=dict)  # per-step failure attribution details

    def __post_init__(self) -> None:
        if self.failure_stage is not None:
            if self.failure_stage not in FailureStage.__members__.values():
                raise ValueError(f"unknown failure stage {self.failure_stage!r}; "
                                 f"known: {', '.join(s.value for s in FailureStage)}")
            object.__setattr__(self, "failure_stage", FailureStage(self.failure_stage))
        if self.success and self.failure_stage is not None:
            raise ValueError("a successful run has no failure stage")

    def to_json(self) -> dict:
        """The row as plain JSON values (the failure stage as its string value)."""
        d = asdict(self)
        d["failure_stage"] = None if self.failure_stage is None else self.failure_stage.value
        return d


def failure_stage(plan: PlanResult, ex: ExecutionResult | None) -> FailureStage | None:
    """Where a run failed: no plan, timeout, execution departing from predictions, or goal tolerance."""
    if not plan.found:
        return FailureStage.TIMEOUT if plan.status is PlanStatus.TIMEOUT else FailureStage.NO_PLAN
    if ex is None or ex.success:
        return None
    if plan.extra.get("rules_vs_net"):  # the network would not have predicted the PDDL plan's states
        return FailureStage.RULES_VS_NET
    return FailureStage.GOAL_MISMATCH if ex.on_prediction else FailureStage.EXECUTION


def safe_plan(planner: str, planner_fn: PlannerFn, transition: TransitionFn, start: np.ndarray,
              goal: SymbolicGoal, timeout_s: float) -> PlanResult:
    """Call a planner; an exception it raises becomes an ERROR result, so one problem cannot stop a benchmark."""
    t0 = time.perf_counter()
    try:
        return planner_fn(transition, np.asarray(start, np.int64), goal, timeout_s)
    except (ValueError, RuntimeError, OSError) as e:
        return failed(planner, PlanStatus.ERROR, t0, f"{type(e).__name__}: {e}")


def run_problem(sim, encoder, transition: TransitionFn, problem: Problem, planner: str, planner_fn: PlannerFn,
                config: ExecutionConfig = ExecutionConfig(), initial_plan: PlanResult | None = None,
                recorder=None) -> ProblemRun:
    """Encode start and goal, plan (or reuse initial_plan), execute, and report one row (frames into `recorder`)."""
    sym_goal = symbolic_goal(sim, encoder, problem)
    place_scene(sim, problem.initial)
    start = encode_observation(encoder, sim.observe())
    plan = initial_plan or safe_plan(planner, planner_fn, transition, start, sym_goal, config.timeout_s)
    ex = None
    if plan.found:
        memory = ObservedTransitions(transition)
        ex = execute_plan(sim, problem, plan, encoder, sym_goal, config,
                          replan=lambda codes: safe_plan(planner, planner_fn, memory, codes, sym_goal,
                                                         config.timeout_s),
                          record=memory.record if config.closed_loop else None, recorder=recorder)
    elif recorder is not None:  # nothing to execute: the start scene alone
        place_scene(sim, problem.initial)
        recorder.start(sim)
    return ProblemRun(
        problem=problem.name, planner=planner, found=plan.found, status=plan.status.value,
        plan_length=len(plan.plan) if plan.found else None, planning_time_s=plan.planning_time_s,
        expansions=plan.expansions, success=bool(ex and ex.success), symbolic_match=bool(ex and ex.symbolic_match),
        max_distance_m=None if ex is None else round(ex.max_distance_m, 5), closed_loop=config.closed_loop,
        replans=0 if ex is None else ex.replans, failure_stage=failure_stage(plan, ex),
        generator_length=problem.generator_length, message=plan.message, n_objects=problem.k,
        timings={k: v for k, v in plan.extra.items() if k.endswith("_s")}, task=problem.task)
