"""Executing symbolic plans in the simulator: open loop, or closed loop with recovery.

A plan (a PlanResult from any planner) is run action by action with `sim.step` from the
problem's initial poses. After each action the real scene is rendered and encoded; the codes
are compared with the planner's predicted state. Success is geometric (every object within
2 cm of its goal position); the symbolic match (final codes == goal codes) is reported beside
it. With `closed_loop=True`, a departure from the prediction is answered in this order:

1. continue: the rest of the plan, rolled from the observed codes through a corrected model
   (the planner's own model or the network, answered from memory where execution has seen a
   step), still reaches the goal codes: keep it, with the rolled states as its new predictions;
2. fall back: a further plan of a top-k planner (PlanResult.alternatives) or the current
   one passes through the observed codes, and its suffix from there reaches the goal when
   rolled the same way: run that suffix (at most `max_fallbacks` times);
3. replan from the observed codes (at most `max_replans` times) with the network corrected by
   every step seen so far (ObservedTransitions); rule planners plan on their rules overridden
   by those steps (pddl_export.overrides). A replan that finds no plan leaves the plan it had
   running (`keep_plan_on_failed_replan`). A plan that ends away from the goal codes is
   replanned too.

Every failed row gets one cause (failure_cause) and an attribution: the first step whose
observed codes departed from the prediction, which objects, whether the rules and the network
disagree on that step, aliasing, replans.

    >>> row = run_problem(sim, encoder, transition, problem, "astar", make_planner("astar"),
    ...                   ExecutionConfig(closed_loop=True))                       # doctest: +SKIP
    >>> row.found, row.plan_length, row.success, row.failure_stage               # doctest: +SKIP
    (True, 2, True, None)
"""
from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from enum import Enum
from typing import Callable, Sequence

import numpy as np

from search.result import PlanResult, PlanStatus, failed
from pddl_export.rules import RuleSet, apply_rules
from pddl_export.symbolic import SymbolicGoal, TransitionFn, bits_from_codes
from symlearn.config_file import MAX_TIMEOUT_S, TIMEOUT_S, Bound, check_bounds
from symlearn.problems.problem import GOAL_TOLERANCE_M, Problem, max_goal_distance
from symlearn.planning.recovery import Progress, Segment, recover, replanned
from symlearn.symbolic.scenes import place_scene, symbolic_goal
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
    """How plans are executed and judged. The defaults are the recipe's (docs/RESULTS.md), what `symlearn plan`,
    `symlearn benchmark`, the library calls and the recommended pipeline all run: closed loop, 10 s a planner call.
    """

    tolerance_m: float = GOAL_TOLERANCE_M  # every object within 2 cm of its goal position
    closed_loop: bool = True  # recover (keep, fall back, replan) when the observed codes depart from the prediction
    max_replans: int = 3  # bound on replanning calls per problem
    max_fallbacks: int = 3  # bound on switches to another plan's suffix (top-k fallback) per problem
    # a replan after a departure that finds no plan (none exists in the planner's model, or none in time) leaves
    # the plan it had to run on, as open loop would, instead of stopping: the world often still reaches the goal
    # where the model has no plan from the observed codes (test set, Fast Downward on the lifted domain: 7 of 8
    # such stops reached the goal open loop)
    keep_plan_on_failed_replan: bool = True
    timeout_s: float = 10.0  # per planner call

    def __post_init__(self) -> None:
        """Refuse what no execution can use (the checks of [execution] in a settings file, and of --timeout)."""
        if not TIMEOUT_S.holds(self.timeout_s):
            raise ValueError(f"timeout_s={self.timeout_s!r} must be a finite positive number of seconds, "
                             f"in (0, {MAX_TIMEOUT_S:g}]")
        check_bounds(self, EXECUTION_BOUNDS)
        for name in ("closed_loop", "keep_plan_on_failed_replan"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name}={getattr(self, name)!r} must be true or false")


EXECUTION_BOUNDS = {
    "tolerance_m": Bound(0.0, 1.0, lo_open=True),  # metres: the table is about a metre across
    "max_replans": Bound(0, 1000, integer=True),
    "max_fallbacks": Bound(0, 1000, integer=True),
}


# ExecutionConfig's named presets, the one place they are defined (the pipeline's presets name them).
# "recommended": the defaults, the recipe's; "paper": the paper's execution, each plan run open loop as planned,
# 30 s a planner call.
EXECUTION_PRESETS = {
    "recommended": ExecutionConfig(),
    "paper": ExecutionConfig(closed_loop=False, timeout_s=30.0),
}


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
    first_departure_step: int | None = None  # index into `executed` of the first step off its prediction
    departed_objects: tuple[int, ...] = ()  # objects whose codes differed from the prediction there
    continued: int = 0  # departures after which the plan's rest still reached the goal and was kept
    fallbacks: int = 0  # switches to a suffix of another (top-k) plan


class ObservedTransitions:
    """The network, except where execution has shown what an action does in a symbolic state.

    Closed-loop replanning searches with this model: every executed (state, action) ->
    observed next state is recorded and answered from memory, so a replan does not choose
    an action again in the state where the network was just proven wrong about it.
    """

    def __init__(self, inner: TransitionFn, seen: dict | None = None) -> None:
        self.inner, self.bits, self.modes = inner, inner.bits, int(getattr(inner, "modes", 1))
        # state -> {action: next}; pass another memory's `seen` to share it (one memory, two models)
        self.seen: dict[tuple[int, ...], dict[int, tuple[int, ...]]] = {} if seen is None else seen

    def record(self, state, action: int, nxt) -> None:
        self.seen.setdefault(tuple(int(c) for c in state), {})[int(action)] = tuple(int(c) for c in nxt)

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = np.array(self.inner(codes, actions), np.int64)
        for i, nxt in self._observed_rows(codes, actions):
            out[i] = nxt
        return out

    def scored(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The inner model's scored predictions; an observed step is answered from memory with -log P = 0."""
        if not callable(getattr(self.inner, "scored", None)):
            raise ValueError(f"{type(self.inner).__name__} does not score its predictions")
        out, nll = self.inner.scored(codes, actions)
        out, nll = np.array(out, np.int64), np.array(nll, np.float64)
        for i, nxt in self._observed_rows(codes, actions):
            out[i], nll[i] = nxt, 0.0
        return out, nll

    def bit_probabilities(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """The inner model's bit probabilities; an observed step's are its observed next bits (0 or 1)."""
        if not callable(getattr(self.inner, "bit_probabilities", None)):
            raise ValueError(f"{type(self.inner).__name__} gives no bit probabilities")
        p = np.array(self.inner.bit_probabilities(codes, actions), np.float64)
        for i, nxt in self._observed_rows(codes, actions):
            p[i] = bits_from_codes(np.asarray(nxt, np.int64), self.bits)
        return p

    def mode_outcomes(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The inner mixture's mode outcomes; an observed step has one outcome, the observed one, at -log P = 0."""
        states, nll = self.inner.mode_outcomes(codes, actions)
        states, nll = np.array(states, np.int64), np.array(nll, np.float64)
        for i, nxt in self._observed_rows(codes, actions):
            states[i], nll[i] = nxt, 0.0
        return states, nll

    def _observed_rows(self, codes: np.ndarray, actions: np.ndarray) -> list[tuple[int, tuple[int, ...]]]:
        """(row, observed next state) for every row whose (state, action) execution has seen."""
        if not self.seen or len(codes) == 0:
            return []
        codes, actions = np.asarray(codes), np.asarray(actions)
        states, inverse = np.unique(codes, axis=0, return_inverse=True)  # an A* expansion: one state
        rows = []
        for j, state in enumerate(states.tolist()):
            known = self.seen.get(tuple(state))
            if not known:
                continue
            hit = np.flatnonzero((inverse.reshape(-1) == j) & np.isin(actions, list(known)))
            rows += [(int(i), known[int(actions[i])]) for i in hit]
        return rows


def _codes(sim, encoder) -> tuple[int, ...]:
    return tuple(int(c) for c in encode_observation(encoder, sim.observe()))


def execute_plan(sim, problem: Problem, plan: PlanResult, encoder, goal: SymbolicGoal | np.ndarray,
                 config: ExecutionConfig = ExecutionConfig(closed_loop=False),  # without `replan`: open loop only
                 replan: Callable[[np.ndarray], PlanResult] | None = None,
                 record: Callable[[tuple, int, tuple], None] | None = None, recorder=None,
                 models: Sequence[TransitionFn] = ()) -> ExecutionResult:
    """Run plan.plan from the problem's initial poses; closed loop recovers from departures (module docstring).

    `models` are the corrected models that roll a plan's rest from observed codes (without any, a departure
    goes straight to `replan(observed_codes)`); `record(state, action, observed_next)` hears every executed
    step (ObservedTransitions.record); `recorder` (a symlearn.planning.recording.PlanRecorder) takes a
    camera frame at the start and after each step.
    """
    if config.closed_loop and replan is None:
        raise ValueError("closed-loop execution needs a replan function")
    goal = goal if isinstance(goal, SymbolicGoal) else SymbolicGoal(tuple(int(c) for c in goal))
    place_scene(sim, problem.initial)
    if recorder is not None:
        recorder.start(sim)
    prog, seg = Progress([_codes(sim, encoder)]), Segment.of(plan)
    while seg is not None:
        while seg is not None and seg.t < len(seg.actions):
            seg = _step(sim, encoder, seg, prog, goal, config, replan, record, recorder, models)
        codes = prog.observed[-1]
        if (seg is None or not config.closed_loop or prog.replans >= config.max_replans
                or goal.satisfied(np.asarray(codes, np.int64))[0]):
            break
        seg = replanned(replan, codes, prog)  # the plan ended away from the goal codes
    codes = prog.observed[-1]
    if not plan.predicted_states:  # a planner without predictions: judge the end state only
        prog.segment_ok = bool(goal.satisfied(np.asarray(codes, np.int64))[0])
    dist = max_goal_distance(sim.get_scene(), problem.goal, problem.free)
    return ExecutionResult(success=dist <= config.tolerance_m and not prog.off_table,
                           symbolic_match=bool(goal.satisfied(np.asarray(codes, np.int64))[0]),
                           max_distance_m=dist, executed=tuple(prog.executed), observed_states=tuple(prog.observed),
                           diverged=prog.diverged, on_prediction=prog.segment_ok and not prog.replan_failed,
                           replans=prog.replans, replan_failed=prog.replan_failed, off_table=prog.off_table,
                           first_departure_step=prog.first_departure, departed_objects=prog.departed,
                           continued=prog.continued, fallbacks=prog.fallbacks)


def _step(sim, encoder, seg: Segment, prog: Progress, goal: SymbolicGoal, config: ExecutionConfig,
          replan, record, recorder, models) -> Segment | None:
    """Execute seg's next action, observe, and on a departure recover; the segment to go on with (None: stop)."""
    action = seg.actions[seg.t]
    prog.off_table |= sim.step(decode_action(action)).off_table
    prog.executed.append(action)
    if recorder is not None:
        recorder.step(sim, action)
    before, codes = prog.observed[-1], _codes(sim, encoder)
    prog.observed.append(codes)
    if record is not None:
        record(before, action, codes)
    want = seg.predicted[seg.t + 1] if seg.predicted else codes
    if codes == tuple(want):
        seg.t += 1
        return seg
    prog.diverged, prog.segment_ok = True, False
    if prog.first_departure is None:
        prog.first_departure = len(prog.executed) - 1
        prog.departed = tuple(i for i, (c, w) in enumerate(zip(codes, want)) if c != w)
    if not config.closed_loop:
        seg.t += 1
        return seg
    if models:
        kept = recover(seg, codes, models, goal, prog, config.max_fallbacks)
        if kept is not None:
            return kept
    if prog.replans < config.max_replans:
        new = replanned(replan, codes, prog)
        if new is not None or not config.keep_plan_on_failed_replan:
            return new
    seg.t += 1  # no replans left, or no plan from here: go on with the plan as it is
    return seg


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
    goal_off_locations: int | None = None  # judged objects the goal puts off the table locations (Problem's)
    optimal_length: int | None = None  # the problem's shortest plan (Problem.optimal_length), None if undecided
    executed_length: int | None = None  # actions executed, across replans; None when nothing was executed

    def __post_init__(self) -> None:
        if self.failure_stage is not None:
            if self.failure_stage not in FailureStage.__members__.values():
                raise ValueError(f"unknown failure stage {self.failure_stage!r}; "
                                 f"known: {', '.join(s.value for s in FailureStage)}")
            object.__setattr__(self, "failure_stage", FailureStage(self.failure_stage))
        if self.success and (self.failure_stage is not None or self.failure_cause is not None):
            raise ValueError("a successful run has no failure stage or cause")
        if self.failure_cause is not None and self.failure_cause not in FAILURE_CAUSES:
            raise ValueError(f"unknown failure cause {self.failure_cause!r}; known: {', '.join(FAILURE_CAUSES)}")

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


FAILURE_CAUSES = ("no_plan", "shared_code", "timeout", "off_table", "symbol_aliasing", "departure")


def failure_cause(plan: PlanResult, ex: ExecutionResult | None) -> str | None:
    """The one cause of a failed run (FAILURE_CAUSES), None on success.

    No plan, split off where the planner proved it from two objects the goal tells apart sharing a
    start code (aliasing between objects: the rules move them alike, search.rule_symmetry), or a
    timeout; else an object off the table; else aliasing (the final codes meet the goal codes, the
    poses do not); else a departure: the codes left the prediction (or, for a plan without
    predictions, ended away from the goal codes it promised) and did not come back.
    """
    if not plan.found:
        if plan.status is PlanStatus.TIMEOUT:
            return "timeout"
        return "shared_code" if plan.extra.get("proof") == "coincidence" else "no_plan"
    if ex is None or ex.success:
        return None
    if ex.off_table:
        return "off_table"
    return "symbol_aliasing" if ex.symbolic_match else "departure"


def attribution(ex: ExecutionResult | None, goal: SymbolicGoal, transition: TransitionFn,
                rules: RuleSet | None, tolerance_m: float) -> dict:
    """Per-step details of a run (the attribution keys of ProblemRun); every key present, also without a run.

    The first departure is the first executed step whose observed codes differ from the prediction;
    a run without one that ended away from the goal codes departs at its end (step = number of
    executed actions), with the objects whose codes miss the goal. rules_net_disagree compares the
    rules' and the network's next codes on the first departed step (None without rules or step).
    """
    out = {"first_departure_step": None, "departed_objects": [], "rules_net_disagree": None, "aliasing": False,
           "replans": 0, "replan_failed": False, "continued": 0, "fallbacks": 0}
    if ex is None:
        return out
    final = np.asarray(ex.observed_states[-1], np.int64)
    step, objects = ex.first_departure_step, list(ex.departed_objects)
    if step is None and not ex.symbolic_match:
        step = len(ex.executed)
        objects = [i for i, c in enumerate(goal.codes) if c is not None and int(final[i]) != c]
    disagree = None
    if rules is not None and step is not None and step < len(ex.executed):
        state, action = np.asarray([ex.observed_states[step]], np.int64), np.asarray([ex.executed[step]], np.int64)
        net = np.asarray(transition(state, action), np.int64)[0]
        disagree = bool(not np.array_equal(apply_rules(rules, state[0], int(action[0])), net))
    out.update(first_departure_step=step, departed_objects=objects, rules_net_disagree=disagree,
               aliasing=bool(ex.symbolic_match and ex.max_distance_m > tolerance_m), replans=ex.replans,
               replan_failed=ex.replan_failed, continued=ex.continued, fallbacks=ex.fallbacks)
    return out


def failure_causes(rows) -> dict[str, int]:
    """cause -> number of failed rows (ProblemRun or their JSON dicts); the counts add up to the failures.

    A failed row without a cause (written before causes existed) counts as "unattributed".
    """
    out: dict[str, int] = {}
    for r in rows:
        get = r.get if isinstance(r, dict) else lambda k, r=r: getattr(r, k)
        if not get("success"):
            cause = get("failure_cause") or "unattributed"
            out[cause] = out.get(cause, 0) + 1
    return dict(sorted(out.items()))


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
                recorder=None, rules: RuleSet | None = None) -> ProblemRun:
    """Encode start and goal, plan (or reuse initial_plan), execute, attribute a failure, report one row.

    `rules` (default: the planner's own, for rule planners) let the attribution say whether the rules and
    the network disagree on the first departed step; frames go into `recorder`.
    """
    sym_goal = symbolic_goal(sim, encoder, problem)
    place_scene(sim, problem.initial)
    start = encode_observation(encoder, sim.observe())
    plan = initial_plan or safe_plan(planner, planner_fn, transition, start, sym_goal, config.timeout_s)
    ex = None
    if plan.found:
        memory = ObservedTransitions(transition)
        own = getattr(planner_fn, "planning_model", None)  # rule planners predict with their rules
        models = (memory,) if own is None else (ObservedTransitions(own(transition), memory.seen), memory)
        ex = execute_plan(sim, problem, plan, encoder, sym_goal, config,
                          replan=lambda codes: safe_plan(planner, planner_fn, memory, codes, sym_goal,
                                                         config.timeout_s),
                          record=memory.record if config.closed_loop else None, recorder=recorder, models=models)
    elif recorder is not None:  # nothing to execute: the start scene alone
        place_scene(sim, problem.initial)
        recorder.start(sim)
    rules = rules if rules is not None else getattr(planner_fn, "rules", None)
    cause, why = failure_cause(plan, ex), attribution(ex, sym_goal, transition, rules, config.tolerance_m)
    return ProblemRun(
        problem=problem.name, planner=planner, found=plan.found, status=plan.status.value,
        plan_length=len(plan.plan) if plan.found else None, planning_time_s=plan.planning_time_s,
        expansions=plan.expansions, success=bool(ex and ex.success), symbolic_match=bool(ex and ex.symbolic_match),
        max_distance_m=None if ex is None else round(ex.max_distance_m, 5), closed_loop=config.closed_loop,
        replans=0 if ex is None else ex.replans, failure_stage=failure_stage(plan, ex),
        generator_length=problem.generator_length, message=plan.message, n_objects=problem.k,
        timings={k: v for k, v in plan.extra.items() if k.endswith("_s")}, task=problem.task,
        failure_cause=cause, attribution=why, goal_off_locations=problem.goal_off_locations,
        optimal_length=problem.optimal_length, executed_length=None if ex is None else len(ex.executed))
