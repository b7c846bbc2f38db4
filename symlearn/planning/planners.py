"""Classical planners on the exported PDDL, as entries of the benchmark's planner registry.

Each planner writes the problem for the start and goal codes (and, for STRIPS-only planners,
the grounded STRIPS form of the domain for this problem), calls the planner through
unified-planning (search.classical), or, for the `-sas` planners, writes the rules for this
problem as a SAS+ task and runs Fast Downward's or SymK's search on it without a translator
(search.sas_planners), and checks the plan against the network: if rolling the
transition network along the plan gives other states than the PDDL predicted, the result is
marked `rules_vs_net`. PDDL writing time and the planner's own time are reported separately.

    >>> register_pddl_planners(Path("runs/paper"))  # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

from pddl_export.files import atomic_write_text
from pddl_export.pddl_writer import conditional_domain, problem_pddl, strips_pddl
from pddl_export.rules import RuleSet
from pddl_export.rules_io import load_rules
from pddl_export.sas_writer import SASEncoder
from search.classical import solve_pddl
from search.up_problem import strips_problem
from search.sas_planners import solve_sas
from search.result import PlanResult, PlanStatus, failed
from pddl_export.symbolic import SymbolicGoal, TransitionFn
from symlearn.planning.benchmark import PLANNERS, register_planner

# registry name -> (unified-planning engine name in search.classical, PDDL form)
PDDL_PLANNERS = {
    "fast-downward": ("fast-downward", "conditional"),
    "symk": ("symk", "conditional"),
    "pyperplan": ("pyperplan", "strips"),
    "fast-downward-opt": ("fast-downward-opt", "strips"),
    "fast-downward-blind": ("fast-downward-blind", "conditional"),
    "fast-downward-sas": ("fast-downward-sas", "sas"),  # Fast Downward's search on a direct SAS+ task
    "fast-downward-sas-opt": ("fast-downward-sas-opt", "sas"),
    "symk-sas": ("symk-sas", "sas"),  # SymK's symbolic search on the same SAS+ task
}


def network_agrees(transition: TransitionFn, plan: PlanResult) -> bool:
    """Whether the network, run along the plan, predicts the same states as the planner did."""
    if not plan.predicted_states:
        return True
    state = np.asarray(plan.predicted_states[0], np.int64)
    for a, want in zip(plan.plan, plan.predicted_states[1:]):
        state = transition(state[None], np.array([a]))[0]
        if tuple(int(c) for c in state) != tuple(want):
            return False
    return True


def make_pddl_planner(rules: RuleSet, model_hash: str, name: str, write_dir: Path | None = None):
    """A benchmark planner function for registry name `name` over the exported rules.

    With `write_dir`, every problem it writes is also saved there (problem.pddl, then
    problem_2.pddl for a replan, ...; STRIPS planners save their grounded domain beside it,
    SAS+ planners the task.sas they ran).
    """
    engine, form = PDDL_PLANNERS[name]
    domain = conditional_domain(rules, model_hash) if form == "conditional" else None
    encoder = SASEncoder(rules) if form == "sas" else None
    calls = [0]

    def plan(transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
        t0 = time.perf_counter()
        init = [int(c) for c in start]
        if encoder is not None:  # the SAS+ task is saved next to the same problem in PDDL, for reading
            prob_path = _next_path("problem", ".pddl")
            if prob_path is not None:
                try:
                    atomic_write_text(prob_path, problem_pddl(rules, init, goal, model_hash))
                except ValueError:
                    pass  # unknown codes: solve_sas reports them
            sas_path = None if prob_path is None else prob_path.with_name(prob_path.name.replace("problem", "task")
                                                                          .replace(".pddl", ".sas"))
            return _checked(transition, solve_sas(encoder, init, goal, engine, timeout_s, write_to=sas_path))
        try:
            prebuilt = None
            if form == "strips":  # built directly: unified-planning's reader is too slow for its size
                task = strips_pddl(rules, init, goal, model_hash)
                dom, prob, prebuilt = task.domain, task.problem, strips_problem(task)
            else:
                dom, prob = domain, problem_pddl(rules, init, goal, model_hash)
        except (ValueError, RuntimeError) as e:  # codes outside the vocabulary, too many states
            return failed(name, PlanStatus.ERROR, t0, str(e))
        prob_path = _next_path("problem", ".pddl")
        if prob_path is not None:
            atomic_write_text(prob_path, prob)
            if form == "strips":
                atomic_write_text(prob_path.with_name(prob_path.name.replace("problem", "domain_strips")), dom)
        write_s = time.perf_counter() - t0
        res = solve_pddl(dom, prob, engine, max(timeout_s - write_s, 0.001), cache_domain=form == "conditional",
                         problem=prebuilt)
        res = dataclasses.replace(res, planning_time_s=write_s + res.planning_time_s,
                                  extra=dict(res.extra, pddl_write_time_s=round(write_s, 5)))
        return _checked(transition, res)

    def _next_path(stem: str, suffix: str) -> Path | None:
        """RUN's write_dir/problem.pddl, then problem_2.pddl for a replan, ... (None without write_dir)."""
        if write_dir is None:
            return None
        calls[0] += 1
        Path(write_dir).mkdir(parents=True, exist_ok=True)
        return Path(write_dir) / (f"{stem}{suffix}" if calls[0] == 1 else f"{stem}_{calls[0]}{suffix}")

    def _checked(transition: TransitionFn, res: PlanResult) -> PlanResult:
        extra = dict(res.extra)
        if res.found:
            extra["rules_vs_net"] = not network_agrees(transition, res)
        return dataclasses.replace(res, planner=name, extra=extra)

    return plan


def register_pddl_planners(run_dir: Path, names: list[str] | None = None, write_dir: Path | None = None) -> list[str]:
    """Register the PDDL planners over RUN/pddl/rules.json (replacing earlier registrations)."""
    names = list(PDDL_PLANNERS) if names is None else [n for n in names if n in PDDL_PLANNERS]
    if not names:
        return []
    rules, model_hash = load_rules(Path(run_dir))
    for n in names:
        register_planner(n, make_pddl_planner(rules, model_hash, n, write_dir), replace=n in PLANNERS)
    return names
