"""How every planner of the registry is built: its builder, from a PlannerContext, as a planner function
(transition, start_codes, goal, timeout_s) -> PlanResult.

The registry itself (name, family, purpose, why it is kept, what it reads, its builder) is
symlearn.planning.planner_catalogue.PLANNERS, re-exported here; `make_planner(name, context)` is the one way to
get a planner function. A PlannerContext holds what the planners read from a run and their PlannerConfig.

The learned-net searches run search.learned_astar on the transition network. The PDDL planners write the problem
for the start and goal codes (and, for pyperplan, the grounded STRIPS form of the domain for this problem) and call
the planner through unified-planning (search.classical); `rules-bfs` and `rules-outcomes` search the rules in this
process (search.rules_search, search.rules_outcomes), without writing a task or starting a process. Plans on the
rules are checked against the network: if rolling it along the plan gives other states than the rules predicted,
the result is marked `rules_vs_net`. The lifted planners are symlearn.planning.lifted_planner.

    >>> context = PlannerContext.for_run(Path("runs/paper"), ["astar", "fast-downward"])  # doctest: +SKIP
    >>> plan = make_planner("fast-downward", context)                                      # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from pddl_export.files import atomic_write_text
from pddl_export.pddl_writer import conditional_domain, problem_pddl, strips_pddl
from pddl_export.lifted_rules import LiftedRules
from pddl_export.outcome_rules import MIN_OUTCOME_RATIO, OutcomeRules
from pddl_export.overrides import override_rules
from pddl_export.rules import RuleSet, apply_rules_batch
from pddl_export.rule_successors import RuleSuccessors
from pddl_export.symbolic import SymbolicGoal, TransitionFn
from search.classical import solve_pddl
from search.learned_astar import plan_symbolic
from search.processes import DeadlineExceeded, within
from search.result import PlanResult, PlanStatus, failed
from search.rules_outcomes import plan_rules_outcomes
from search.rules_search import plan_rules
from search.up_problem import strips_problem
from symlearn.planning.execution import PlannerFn
from symlearn.problems.paths import path_under
from symlearn.planning.planner_catalogue import OUTCOMES, PLANNERS, RISK_PLANNERS, PlannerConfig, planner_entry
from symlearn.planning.recovery import roll
from symlearn.planning.run_folder import Run


@dataclass(frozen=True)
class PlannerContext:
    """What building a planner may need: the planners' settings, the exported rules (for rule-based planners), and
    where to save tasks."""

    rules: RuleSet | None = None  # RUN/pddl/rules.json, needed by every spec with needs_rules
    model_hash: str = ""  # the transition model's hash recorded with the rules
    write_dir: Path | None = None  # save every problem/task a planner writes here (None: keep nothing)
    config: PlannerConfig = PlannerConfig()  # the planners' settings (risk_weight)
    outcomes: OutcomeRules | None = None  # RUN/pddl/outcomes.json, needed by rules-outcomes
    lifted: LiftedRules | None = None  # RUN/pddl/lifted.json, needed by the planners on the lifted domain

    @staticmethod
    def for_run(run_dir: Path, names: list[str], write_dir: Path | None = None,
                config: PlannerConfig = PlannerConfig()) -> "PlannerContext":
        """A context for the named planners of a run: loads RUN/pddl/rules.json (and outcomes.json) only when needed."""
        specs = [planner_entry(n) for n in names]  # refuse unknown names before reading anything
        run = Run(run_dir)  # read only: loaded and checked against its transition.pt
        lifted = run.lifted() if any(s.needs_lifted for s in specs) else None
        if not any(s.needs_rules for s in specs):
            return PlannerContext(write_dir=write_dir, config=config, lifted=lifted)
        rules, model_hash = run.rules()
        outcomes = run.outcomes(model_hash) if any(OUTCOMES in s.needs for s in specs) else None
        return PlannerContext(rules=rules, model_hash=model_hash, write_dir=write_dir, config=config,
                              outcomes=outcomes, lifted=lifted)


# ------------------------------------------------------------------------------- learned-net A*


OUTCOMES_PLANNER = "astar-outcomes"
OUTCOME_RULES_PLANNER = "rules-outcomes"
OUTCOMES_PER_ACTION = 4  # astar-outcomes: an action's likeliest next state and up to 3 other outcomes, each at
# least MIN_OUTCOME_RATIO as likely as the likeliest (the ratio export-pddl keeps second outcomes at, too)


def _astar(uniform_cost: bool, name: str, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal,
           timeout_s: float) -> PlanResult:
    return plan_symbolic(transition, start, goal, timeout_s=timeout_s, uniform_cost=uniform_cost, planner_name=name)


def _astar_outcomes(risk_weight: float, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal,
                    timeout_s: float) -> PlanResult:
    return plan_symbolic(transition, start, goal, timeout_s=timeout_s, risk_weight=risk_weight,
                         max_outcomes=OUTCOMES_PER_ACTION, min_outcome_ratio=MIN_OUTCOME_RATIO,
                         planner_name=OUTCOMES_PLANNER)


def build_astar(context: PlannerContext) -> PlannerFn:
    """`astar`: A* on the network's likeliest predictions (mismatch heuristic)."""
    return partial(_astar, False, "astar")


def build_astar_ucs(context: PlannerContext) -> PlannerFn:
    """`astar-ucs`: uniform-cost search on the network's likeliest predictions (shortest plans)."""
    return partial(_astar, True, "astar-ucs")


def build_astar_outcomes(context: PlannerContext) -> PlannerFn:
    """`astar-outcomes`: A* over each action's likely outcomes, weighted by context.config.risk_weight."""
    return partial(_astar_outcomes, context.config.risk_weight)


# ------------------------------------------------------------------------------- planners on the exported rules


def network_agrees(transition: TransitionFn, plan: PlanResult) -> bool:
    """Whether the network, run along the plan, predicts the same states as the planner did."""
    if not plan.predicted_states:
        return True
    return roll(transition, plan.predicted_states[0], list(plan.plan)) == list(plan.predicted_states)


class RulesTransition:
    """The rules as a transition function (apply_rules_batch): what a rule planner predicts a step does."""

    def __init__(self, rules: RuleSet) -> None:
        self.rules, self.bits = rules, rules.bits

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        return apply_rules_batch(self.rules, np.asarray(codes, np.int64), np.asarray(actions, np.int64))


def _observation_key(transition: TransitionFn) -> tuple:
    """The observed steps a transition carries (ObservedTransitions.seen), as a hashable key; () if none."""
    seen = getattr(transition, "seen", None) or {}
    return tuple(sorted((s, a, n) for s, steps in seen.items() for a, n in steps.items()))


class _RulesPlanner:
    """A planner function over the exported rules through unified-planning: conditional PDDL or grounded STRIPS.

    Given a transition that carries observed steps (execution's ObservedTransitions, its `seen`),
    it plans on the rules overridden by them (pddl_export.overrides), so a replan does not count
    on a step execution has disproven. With `write_dir`, every problem it writes is also saved
    there (problem.pddl, then problem_2.pddl for a replan, ...; STRIPS planners save their
    grounded domain beside it, and a replan on overridden rules the conditional domain_<n>.pddl it used).
    """

    def __init__(self, rules: RuleSet, model_hash: str, name: str, engine: str, form: str,
                 write_dir: Path | None) -> None:
        self.rules, self.model_hash, self.name, self.engine, self.form = rules, model_hash, name, engine, form
        self.write_dir = None if write_dir is None else Path(write_dir)
        self.calls = 0
        self._cache: tuple = ()
        self._tools = self._build(rules)

    def _build(self, rules: RuleSet) -> tuple[RuleSet, str | None]:
        return rules, conditional_domain(rules, self.model_hash) if self.form == "conditional" else None

    def _tools_for(self, transition: TransitionFn) -> tuple:
        """(rules, conditional domain) for this call: overridden by the transition's observations."""
        key = _observation_key(transition)
        if not key:
            return self._tools
        if not self._cache or self._cache[0] != key:
            self._cache = (key, self._build(override_rules(self.rules, transition.seen)))  # type: ignore[attr-defined]
        return self._cache[1]

    def planning_model(self, transition: TransitionFn) -> TransitionFn:
        """What this planner predicts a step does (its rules), for execution's check of a plan's remainder."""
        return RulesTransition(self.rules)

    def __call__(self, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
        init = [int(c) for c in start]
        rules, domain = self._tools_for(transition)
        return self._solve_pddl(rules, domain, transition, init, goal, timeout_s)

    def _texts(self, rules: RuleSet, domain: str | None, init: list[int], goal: SymbolicGoal) -> tuple:
        """(domain text, problem text, prebuilt unified-planning problem or None) of this call."""
        if self.form == "strips":  # built directly: unified-planning's reader is too slow for its size
            task = strips_pddl(rules, init, goal, self.model_hash)
            return task.domain, task.problem, strips_problem(task)
        return domain, problem_pddl(rules, init, goal, self.model_hash), None

    def _solve_pddl(self, rules: RuleSet, domain: str | None, transition: TransitionFn, init: list[int],
                    goal: SymbolicGoal, timeout_s: float) -> PlanResult:
        t0 = time.perf_counter()
        try:  # grounding (STRIPS) can take longer than the whole limit: it is part of the call
            dom, prob, prebuilt = within(lambda: self._texts(rules, domain, init, goal), timeout_s)
        except DeadlineExceeded:
            return failed(self.name, PlanStatus.TIMEOUT, t0, f"time limit of {timeout_s:g} s reached while writing "
                          f"the {self.form} task", pddl_write_time_s=round(time.perf_counter() - t0, 5))
        except (ValueError, RuntimeError) as e:  # codes outside the vocabulary, too many states
            return failed(self.name, PlanStatus.ERROR, t0, str(e))
        prob_path = self._next_path("problem", ".pddl")
        if prob_path is not None:
            atomic_write_text(prob_path, prob)
            if self.form == "strips":
                atomic_write_text(prob_path.with_name(prob_path.name.replace("problem", "domain_strips")), dom)
            elif rules is not self.rules:
                atomic_write_text(prob_path.with_name(prob_path.name.replace("problem", "domain")), dom)
        write_s = time.perf_counter() - t0
        if write_s >= timeout_s:
            return failed(self.name, PlanStatus.TIMEOUT, t0, f"time limit of {timeout_s:g} s reached while writing "
                          f"the {self.form} task", pddl_write_time_s=round(write_s, 5))
        res = solve_pddl(dom, prob, self.engine, timeout_s - write_s,
                         cache_domain=self.form == "conditional", problem=prebuilt)
        res = dataclasses.replace(res, planning_time_s=write_s + res.planning_time_s,
                                  extra=dict(res.extra, pddl_write_time_s=round(write_s, 5)))
        return self._checked(transition, res)

    def _next_path(self, stem: str, suffix: str) -> Path | None:
        """write_dir/problem.pddl, then problem_2.pddl for a replan, ... (None without write_dir)."""
        if self.write_dir is None:
            return None
        self.calls += 1
        self.write_dir.mkdir(parents=True, exist_ok=True)
        return path_under(self.write_dir, f"{stem}{suffix}" if self.calls == 1 else f"{stem}_{self.calls}{suffix}")

    def _checked(self, transition: TransitionFn, res: PlanResult) -> PlanResult:
        extra = dict(res.extra)
        if res.found:
            extra["rules_vs_net"] = not network_agrees(transition, res)
        return dataclasses.replace(res, planner=self.name, extra=extra)


class _InProcessRulesPlanner(_RulesPlanner):
    """A search over the exported rules in this process (search.rules_search), compiled once per rule set.

    Closed loop works as for the other rule planners: observed steps override the rules.
    Nothing is written: there is no task file.
    """

    def _build(self, rules: RuleSet) -> tuple[RuleSet, RuleSuccessors]:  # type: ignore[override]
        return rules, RuleSuccessors(rules)

    def __call__(self, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
        _, successors = self._tools_for(transition)
        return self._checked(transition, plan_rules(successors, [int(c) for c in start], goal, self.engine,
                                                    timeout_s=timeout_s, planner_name=self.name))


class _RulesOutcomesPlanner(_InProcessRulesPlanner):
    """rules-outcomes: A* over the rules and their second outcomes (search.rules_outcomes), compiled once.

    Closed loop: a step execution has seen has its observed successor only (no override needed).
    """

    def __init__(self, rules: RuleSet, outcomes: OutcomeRules, model_hash: str, risk_weight: float) -> None:
        super().__init__(rules, model_hash, OUTCOME_RULES_PLANNER, "outcomes", "in-process", None)
        self.outcomes, self.risk_weight = outcomes, risk_weight
        self._alternates, self._costs = RuleSuccessors(outcomes.rules), outcomes.alternative_costs()

    def __call__(self, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
        return self._checked(transition, plan_rules_outcomes(
            self._tools[1], self._alternates, self._costs, [int(c) for c in start], goal,
            risk_weight=self.risk_weight, timeout_s=timeout_s, seen=getattr(transition, "seen", None),
            planner_name=self.name))


def build_rules_outcomes(context: PlannerContext) -> PlannerFn:
    """`rules-outcomes`: A* over the rules and their second outcomes, weighted by context.config.risk_weight."""
    if context.rules is None or context.outcomes is None:
        raise ValueError(f"planner {OUTCOME_RULES_PLANNER!r} plans on the exported rules and their second outcomes "
                         f"(RUN/pddl/rules.json and outcomes.json); run 'symlearn export-pddl --rules' first")
    return _RulesOutcomesPlanner(context.rules, context.outcomes, context.model_hash, context.config.risk_weight)


# registry name -> (engine name in search.classical / search.rules_search, task form)
_RULES_PLANNERS = {
    "fast-downward": ("fast-downward", "conditional"),
    "pyperplan": ("pyperplan", "strips"),
    "rules-bfs": ("bfs", "in-process"),
}


def make_pddl_planner(rules: RuleSet, model_hash: str, name: str, write_dir: Path | None = None) -> PlannerFn:
    """The planner function of rule-based planner `name` over the exported rules (saving its tasks in write_dir)."""
    if name not in _RULES_PLANNERS:
        raise ValueError(f"{name!r} is not a planner on the exported rules; known: {', '.join(_RULES_PLANNERS)}")
    engine, form = _RULES_PLANNERS[name]
    kind = _InProcessRulesPlanner if form == "in-process" else _RulesPlanner
    return kind(rules, model_hash, name, engine, form, write_dir)


def _build_rules_planner(name: str, context: PlannerContext) -> PlannerFn:
    if context.rules is None:
        raise ValueError(f"planner {name!r} plans on the exported rules, and none were given; "
                         f"run 'symlearn export-pddl --rules' first")
    return make_pddl_planner(context.rules, context.model_hash, name, context.write_dir)


def build_rules_bfs(context: PlannerContext) -> PlannerFn:
    """`rules-bfs`: breadth-first search over the rules in this process."""
    return _build_rules_planner("rules-bfs", context)


def build_up_fast_downward(context: PlannerContext) -> PlannerFn:
    """`fast-downward`: Fast Downward through unified-planning on the rules' conditional-effects domain."""
    return _build_rules_planner("fast-downward", context)


def build_up_pyperplan(context: PlannerContext) -> PlannerFn:
    """`pyperplan`: pyperplan through unified-planning on the rules' grounded STRIPS form."""
    return _build_rules_planner("pyperplan", context)


# ------------------------------------------------------------------------------- stock planners, lifted domain

def _build_lifted_planner(name: str, engine: str, costs: bool, context: PlannerContext) -> PlannerFn:
    """A stock planner (search.stock_planners configuration `engine`) on the lifted domain, or its cost form."""
    if context.lifted is None:
        raise ValueError(f"planner {name!r} plans on the lifted domain (RUN/pddl/lifted.json); "
                         f"run 'symlearn export-pddl' first")
    from symlearn.planning.lifted_planner import LiftedPlanner
    return LiftedPlanner(context.lifted, name, engine, context.write_dir, costs=costs)


def build_lifted_lama(context: PlannerContext) -> PlannerFn:
    """`fast-downward-lifted`: stock Fast Downward, LAMA's first iteration, on the lifted domain."""
    return _build_lifted_planner("fast-downward-lifted", "fd-lama-first", False, context)


def build_lifted_opt(context: PlannerContext) -> PlannerFn:
    """`fast-downward-lifted-opt`: stock Fast Downward, A* with LM-cut, on the lifted domain."""
    return _build_lifted_planner("fast-downward-lifted-opt", "fd-lmcut", False, context)


def build_lifted_outcomes(context: PlannerContext) -> PlannerFn:
    """`fast-downward-lifted-outcomes`: A* with LM-cut on the lifted domain's all-outcomes cost form."""
    return _build_lifted_planner("fast-downward-lifted-outcomes", "fd-lmcut", True, context)


# ------------------------------------------------------------------------------- the registry

class WithinLimit:
    """A registry planner whose time limit covers all of its call: an answer that comes after timeout_s (a plan,
    a proof or an error) is reported as TIMEOUT, as search.classical does for its route, so no planner's
    results count work outside the limit. A planner killed by a signal keeps its result (the benchmark
    refuses it). Attributes (a rule planner's `rules`, `planning_model`) are the wrapped function's.
    """

    def __init__(self, fn: PlannerFn, name: str) -> None:
        self.fn, self.name = fn, name

    def __call__(self, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
        t0 = time.perf_counter()
        res = self.fn(transition, start, goal, timeout_s)
        total = time.perf_counter() - t0
        if total <= timeout_s or res.status is PlanStatus.TIMEOUT or res.extra.get("killed_by_signal"):
            return res
        return failed(self.name, PlanStatus.TIMEOUT, t0, f"{self.name} hit the {timeout_s:g} s time limit (answered "
                      f"{res.status.value} after {total:.3f} s)", **{k: v for k, v in res.extra.items()
                                                                      if k.endswith("_s")})

    def __getattr__(self, name: str):
        return getattr(self.fn, name)


def make_planner(name: str, context: PlannerContext = PlannerContext()) -> PlannerFn:
    """Build planner `name`'s function (its time limit covering the whole call, WithinLimit); unknown names and
    rule-based planners without rules are refused."""
    return WithinLimit(planner_entry(name).builder()(context), name)


def make_planners(names: list[str], run_dir: Path, write_dir: Path | None = None,
                  config: PlannerConfig = PlannerConfig()) -> dict[str, PlannerFn]:
    """name -> planner function for a run (its rules loaded once, only if needed), each built with the planners'
    settings `config`; every name is checked first."""
    context = PlannerContext.for_run(run_dir, names, write_dir, config)
    return {name: make_planner(name, context) for name in names}
