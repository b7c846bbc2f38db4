"""Every planner the benchmark, the CLI and the examples can run, in one immutable registry.

`PLANNERS` maps a name to a PlannerSpec: a description, whether it plans on the exported rules
(RUN/pddl/rules.json), and how to build its planner function (transition, start_codes, goal,
timeout_s) -> PlanResult from a PlannerContext. The registry is built once and cannot be
changed at run time; `make_planner(name, context)` is the one way to get a planner function.

The learned-net A* ("astar", greedy-ish with the mismatch heuristic) and its uniform-cost
variant ("astar-ucs", shortest plans) search with the transition network; "astar-likely" charges
each action the network's -log P of its prediction too, preferring plans it is sure of, and
"astar-outcomes" also follows each action's other likely outcomes at their -log P (all-outcomes
determinization: a goal the network's likeliest predictions miss can still be planned for). The classical
planners write the problem for the start and goal codes (and, for STRIPS-only planners, the
grounded STRIPS form of the domain for this problem) and call the planner through
unified-planning (search.classical), or, for the `-sas` planners, write the rules for this
problem as a SAS+ task and run Fast Downward's or SymK's search on it without a translator
(search.sas_planners). The `rules-` planners search the rules in this process (search.rules_search),
without writing a task or starting a process; `rules-outcomes` also follows each object's second likeliest
outcome (RUN/pddl/outcomes.json, search.rules_outcomes), the exported form of "astar-outcomes". Their plans are checked against the network: if rolling the
transition network along the plan gives other states than the PDDL predicted, the result is
marked `rules_vs_net`. PDDL writing time and the planner's own time are reported separately.

    >>> context = PlannerContext.for_run(Path("runs/paper"), ["astar", "fast-downward"])  # doctest: +SKIP
    >>> plan = make_planner("fast-downward", context)                                      # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import math
import time
import types
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from pddl_export.files import atomic_write_text, sha256_file
from pddl_export.pddl_writer import conditional_domain, problem_pddl, strips_pddl
from pddl_export.lifted_rules import LiftedRules, load_lifted
from pddl_export.outcome_rules import MIN_OUTCOME_RATIO, OutcomeRules, load_outcomes
from pddl_export.overrides import override_rules
from pddl_export.rules import RuleSet, apply_rules_batch
from pddl_export.rule_successors import RuleSuccessors
from pddl_export.rules_io import PDDL_DIR, RULES_FILE, load_rules
from pddl_export.sas_writer import SASEncoder
from pddl_export.symbolic import SymbolicGoal, TransitionFn
from search.classical import solve_pddl
from search.learned_astar import plan_symbolic
from search.processes import DeadlineExceeded, within
from search.result import PlanResult, PlanStatus, failed
from search.rules_outcomes import plan_rules_outcomes
from search.rules_search import plan_rules
from search.sas_planners import solve_sas
from search.up_problem import strips_problem
from symlearn.planning.execution import PlannerFn
from symlearn.problems.paths import path_under
from symlearn.planning.planner_catalogue import DESCRIPTIONS
from symlearn.planning.recovery import roll


@dataclass(frozen=True)
class PlannerContext:
    """What building a planner may need: the exported rules (for rule-based planners) and where to save tasks."""

    rules: RuleSet | None = None  # RUN/pddl/rules.json, needed by every spec with needs_rules
    model_hash: str = ""  # the transition model's hash recorded with the rules
    write_dir: Path | None = None  # save every problem/task a planner writes here (None: keep nothing)
    risk_weight: float = 1.0  # astar-likely/-outcomes: an action costs 1 + risk_weight * (-log P(its predicted next state))
    outcomes: OutcomeRules | None = None  # RUN/pddl/outcomes.json, needed by rules-outcomes
    lifted: LiftedRules | None = None  # RUN/pddl/lifted.json, needed by the planners on the lifted domain

    def __post_init__(self) -> None:
        if not (isinstance(self.risk_weight, (int, float)) and math.isfinite(self.risk_weight)
                and self.risk_weight > 0):
            raise ValueError(f"risk weight {self.risk_weight!r} must be a finite number > 0")

    @staticmethod
    def for_run(run_dir: Path, names: list[str], write_dir: Path | None = None,
                risk_weight: float = 1.0) -> "PlannerContext":
        """A context for the named planners of a run: loads RUN/pddl/rules.json (and outcomes.json) only when needed."""
        specs = [planner_spec(n) for n in names]  # refuse unknown names before reading anything
        lifted = load_run_lifted(Path(run_dir)) if any(s.needs_lifted for s in specs) else None
        if not any(s.needs_rules for s in specs):
            return PlannerContext(write_dir=write_dir, risk_weight=risk_weight, lifted=lifted)
        rules, model_hash = load_rules(Path(run_dir))
        check_rules_current(Path(run_dir), model_hash)
        outcomes = None
        if OUTCOME_RULES_PLANNER in names:
            outcomes, outcomes_hash = load_outcomes(Path(run_dir))
            if outcomes_hash != model_hash:
                raise ValueError(f"{Path(run_dir) / PDDL_DIR} holds rules.json and outcomes.json of different "
                                 f"transition models; re-run 'symlearn export-pddl --run {run_dir} --rules'")
        return PlannerContext(rules=rules, model_hash=model_hash, write_dir=write_dir, risk_weight=risk_weight,
                              outcomes=outcomes, lifted=lifted)


def load_run_lifted(run_dir: Path) -> LiftedRules:
    """RUN/pddl/lifted.json, refused if missing or exported from another transition.pt than the run's."""
    from symlearn.export.lifted_export import LIFTED_FILE

    path = Path(run_dir) / PDDL_DIR / LIFTED_FILE
    if not path.is_file():
        raise ValueError(f"no lifted domain at {path}; run 'symlearn export-pddl --run {run_dir}' "
                         f"(it needs an m(z) on 9 location bits)")
    lifted = load_lifted(path)
    check_rules_current(Path(run_dir), lifted.model_hash, path)
    return lifted


def check_rules_current(run_dir: Path, model_hash: str, rules_path: Path | None = None) -> None:
    """Refuse rules exported from another transition.pt than the run's (the sha256 prefix export-pddl records)."""
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    path = Path(run_dir) / TRANSITION_FILE
    if not path.is_file():
        raise ValueError(f"no transition model at {path}; run 'symlearn train-transition' first")
    current = sha256_file(path)[:16]
    if not model_hash or model_hash != current:
        raise ValueError(f"{rules_path or Path(run_dir) / PDDL_DIR / RULES_FILE} was exported from another transition.pt "
                         f"(model_hash {model_hash or 'missing'}, {path.name} is {current}); "
                         f"re-run 'symlearn export-pddl --run {run_dir} --rules'")


@dataclass(frozen=True)
class PlannerSpec:
    """One registry entry: a planner's name, what it is, and how to build its function from a context."""

    name: str
    description: str
    needs_rules: bool  # plans on the exported rules (RUN/pddl/rules.json) rather than the network alone
    build: Callable[[PlannerContext], PlannerFn]
    needs_lifted: bool = False  # plans on the lifted domain (RUN/pddl/lifted.json)


# ------------------------------------------------------------------------------- learned-net A*


def _astar(transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
    return plan_symbolic(transition, start, goal, timeout_s=timeout_s, planner_name="astar")


def _astar_ucs(transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
    return plan_symbolic(transition, start, goal, timeout_s=timeout_s, uniform_cost=True, planner_name="astar-ucs")


RISK_PLANNER = "astar-likely"
OUTCOMES_PLANNER = "astar-outcomes"
OUTCOME_RULES_PLANNER = "rules-outcomes"
# the planners whose plans depend on PlannerContext.risk_weight
RISK_PLANNERS = (RISK_PLANNER, OUTCOMES_PLANNER, OUTCOME_RULES_PLANNER)
OUTCOMES_PER_ACTION = 4  # astar-outcomes: an action's likeliest next state and up to 3 other outcomes, each at
# least MIN_OUTCOME_RATIO as likely as the likeliest (the ratio export-pddl keeps second outcomes at, too)


def _astar_likely(risk_weight: float, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal,
                  timeout_s: float) -> PlanResult:
    return plan_symbolic(transition, start, goal, timeout_s=timeout_s, risk_weight=risk_weight,
                         planner_name=RISK_PLANNER)


def _astar_outcomes(risk_weight: float, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal,
                    timeout_s: float) -> PlanResult:
    return plan_symbolic(transition, start, goal, timeout_s=timeout_s, risk_weight=risk_weight,
                         max_outcomes=OUTCOMES_PER_ACTION, min_outcome_ratio=MIN_OUTCOME_RATIO,
                         planner_name=OUTCOMES_PLANNER)


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
    """A planner function over the exported rules: PDDL (conditional or grounded STRIPS) or a SAS+ task.

    Given a transition that carries observed steps (execution's ObservedTransitions, its `seen`),
    it plans on the rules overridden by them (pddl_export.overrides), so a replan does not count
    on a step execution has disproven. With `write_dir`, every problem it writes is also saved
    there (problem.pddl, then problem_2.pddl for a replan, ...; STRIPS planners save their
    grounded domain beside it, SAS+ planners the task.sas they ran, and a replan on overridden
    rules the conditional domain_<n>.pddl it used).
    """

    def __init__(self, rules: RuleSet, model_hash: str, name: str, engine: str, form: str,
                 write_dir: Path | None) -> None:
        self.rules, self.model_hash, self.name, self.engine, self.form = rules, model_hash, name, engine, form
        self.write_dir = None if write_dir is None else Path(write_dir)
        self.calls = 0
        self._cache: tuple = ()
        self._tools = self._build(rules)

    def _build(self, rules: RuleSet) -> tuple[RuleSet, str | None, SASEncoder | None]:
        return (rules, conditional_domain(rules, self.model_hash) if self.form == "conditional" else None,
                SASEncoder(rules) if self.form == "sas" else None)

    def _tools_for(self, transition: TransitionFn) -> tuple[RuleSet, str | None, SASEncoder | None]:
        """(rules, conditional domain, SAS+ encoder) for this call: overridden by the transition's observations."""
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
        rules, domain, encoder = self._tools_for(transition)
        if encoder is not None:
            return self._checked(transition, self._solve_sas(rules, encoder, init, goal, timeout_s))
        return self._solve_pddl(rules, domain, transition, init, goal, timeout_s)

    def _solve_sas(self, rules: RuleSet, encoder: SASEncoder, init: list[int], goal: SymbolicGoal,
                   timeout_s: float) -> PlanResult:
        prob_path = self._next_path("problem", ".pddl")
        if prob_path is not None:  # the SAS+ task is saved next to the same problem in PDDL, for reading
            try:
                atomic_write_text(prob_path, problem_pddl(rules, init, goal, self.model_hash))
            except ValueError:
                pass  # codes outside the vocabulary have no PDDL predicate; the SAS+ task holds them (inert)
        sas_path = None if prob_path is None else prob_path.with_name(prob_path.name.replace("problem", "task")
                                                                      .replace(".pddl", ".sas"))
        return solve_sas(encoder, init, goal, self.engine, timeout_s, write_to=sas_path)

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


def _build_outcome_rules_planner(context: PlannerContext) -> PlannerFn:
    if context.rules is None or context.outcomes is None:
        raise ValueError(f"planner {OUTCOME_RULES_PLANNER!r} plans on the exported rules and their second outcomes "
                         f"(RUN/pddl/rules.json and outcomes.json); run 'symlearn export-pddl --rules' first")
    return _RulesOutcomesPlanner(context.rules, context.outcomes, context.model_hash, context.risk_weight)


# registry name -> (engine name in search.classical / search.sas_planners / search.rules_search, task form); the
# descriptions are in symlearn.planning.planner_catalogue
_RULES_PLANNERS = {
    "fast-downward": ("fast-downward", "conditional"),
    "symk": ("symk", "conditional"),
    "pyperplan": ("pyperplan", "strips"),
    "fast-downward-opt": ("fast-downward-opt", "strips"),
    "fast-downward-blind": ("fast-downward-blind", "conditional"),
    "fast-downward-sas": ("fast-downward-sas", "sas"),
    "fast-downward-sas-opt": ("fast-downward-sas-opt", "sas"),
    "symk-sas": ("symk-sas", "sas"),
    "symk-sas-topk": ("symk-sas-topk", "sas"),
    "fast-downward-sas-ms": ("fast-downward-sas-ms", "sas"),
    "fast-downward-sas-lama": ("fast-downward-sas-lama", "sas"),
    "rules-astar": ("astar", "in-process"),
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


# ------------------------------------------------------------------------------- stock planners, lifted domain

# registry name -> (search.stock_planners configuration, whether it plans on the domain's all-outcomes cost form)
LIFTED_PLANNERS = {"fast-downward-lifted": ("fd-lama-first", False), "fast-downward-lifted-opt": ("fd-lmcut", False),
                   "fast-downward-lifted-outcomes": ("fd-lmcut", True)}


def _build_lifted_planner(name: str, engine: str, costs: bool, context: PlannerContext) -> PlannerFn:
    if context.lifted is None:
        raise ValueError(f"planner {name!r} plans on the lifted domain (RUN/pddl/lifted.json); "
                         f"run 'symlearn export-pddl' first")
    from symlearn.planning.lifted_planner import LiftedPlanner
    return LiftedPlanner(context.lifted, name, engine, context.write_dir, costs=costs)


# ------------------------------------------------------------------------------- the registry


def _registry() -> Mapping[str, PlannerSpec]:
    specs = [PlannerSpec("astar", DESCRIPTIONS["astar"], False, lambda _: _astar),
             PlannerSpec("astar-ucs", DESCRIPTIONS["astar-ucs"], False, lambda _: _astar_ucs),
             PlannerSpec(RISK_PLANNER, DESCRIPTIONS[RISK_PLANNER], False,
                         lambda context: partial(_astar_likely, context.risk_weight)),
             PlannerSpec(OUTCOMES_PLANNER, DESCRIPTIONS[OUTCOMES_PLANNER], False,
                         lambda context: partial(_astar_outcomes, context.risk_weight))]
    specs += [PlannerSpec(n, DESCRIPTIONS[n], True, partial(_build_rules_planner, n)) for n in _RULES_PLANNERS]
    specs.append(PlannerSpec(OUTCOME_RULES_PLANNER, DESCRIPTIONS[OUTCOME_RULES_PLANNER], True,
                             _build_outcome_rules_planner))
    specs += [PlannerSpec(n, DESCRIPTIONS[n], False, partial(_build_lifted_planner, n, engine, costs),
                          needs_lifted=True) for n, (engine, costs) in LIFTED_PLANNERS.items()]
    return types.MappingProxyType({s.name: s for s in specs})


PLANNERS: Mapping[str, PlannerSpec] = _registry()


def planner_spec(name: str) -> PlannerSpec:
    """The registry entry of `name`, or a one-line ValueError listing every planner."""
    if name not in PLANNERS:
        raise ValueError(f"unknown planner {name!r}; known: {', '.join(PLANNERS)}")
    return PLANNERS[name]


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
    return WithinLimit(planner_spec(name).build(context), name)


def make_planners(names: list[str], run_dir: Path, write_dir: Path | None = None,
                  risk_weight: float = 1.0) -> dict[str, PlannerFn]:
    """name -> planner function for a run (its rules loaded once, only if needed); every name is checked first."""
    context = PlannerContext.for_run(run_dir, names, write_dir, risk_weight)
    return {name: make_planner(name, context) for name in names}
