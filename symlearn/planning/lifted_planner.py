"""Stock planners on the lifted domain (RUN/pddl/lifted/domain.pddl), as planner functions of the registry.

Each call writes the problem for the start and goal codes (pddl_export.lifted_problem.problem_pddl) and runs the
stock Fast Downward driver on domain.pddl and problem.pddl with its own translator (search.stock_planners), as a
user outside the project would; the ground plan is read back as robot actions. Its predictions are the lifted
rules rolled along the plan (pddl_export.lifted_rules.LiftedRules.step_codes), so closed-loop execution sees
departures as it does for the other planners; where an object's predicted fields are its goal's, its predicted
code is the goal's code.

With `costs`, the planner reads the domain's cost form (pddl_export.lifted_moves: one action per outcome of each
rule, costing by how often m(z) answered it) and its predictions follow the outcome each step of the plan chose.

    >>> plan = LiftedPlanner(load_lifted(run / "pddl/lifted.json"), "fast-downward-lifted", "fd-lama-first")  # doctest: +SKIP
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

from pddl_export.files import atomic_write_text
from pddl_export.lifted_domain import domain_pddl, static_facts
from pddl_export.lifted_moves import moves
from pddl_export.lifted_plans import plan_decoder
from pddl_export.lifted_problem import problem_pddl
from pddl_export.lifted_rules import LiftedRules, LiftedTransition
from pddl_export.symbolic import SymbolicGoal, TransitionFn
from search.result import PlanResult, PlanStatus, failed
from search.stock_planners import solve_texts
from symlearn.problems.paths import path_under


def _fields(rules: LiftedRules, code: int, stick: bool) -> tuple:
    p = rules.layout.piece(code, stick)
    return (p.loc, p.place, p.level)


class LiftedPlanner:
    """A stock planner (search.stock_planners name, e.g. fd-lama-first) on the lifted domain of a run."""

    def __init__(self, rules: LiftedRules, name: str, engine: str, write_dir: Path | None = None,
                 costs: bool = False) -> None:
        self.lifted, self.name, self.engine, self.costs = rules, name, engine, costs
        self.domain = domain_pddl(rules, costs)
        self.decode = plan_decoder(rules, costs)
        self.statics = static_facts(moves(rules, costs))
        self.write_dir = None if write_dir is None else Path(write_dir)
        self.calls = 0

    def planning_model(self, transition: TransitionFn) -> TransitionFn:
        """What this planner predicts a step does: the lifted rules."""
        return LiftedTransition(self.lifted)

    def predictions(self, start: list[int], plan: list[int], goal: SymbolicGoal,
                    alternatives: list[int] | None = None) -> tuple[tuple[int, ...], ...]:
        """The lifted rules' states along a plan (each step with the outcome it chose, its rule's own by default);
        an object whose fields are its goal's gets its goal code."""
        sticks = [p.stick for p in self.lifted.pieces(start)]
        states, codes = [tuple(start)], tuple(start)
        for a, alt in zip(plan, alternatives or [0] * len(plan)):
            codes = self.lifted.step_codes(codes, a, alt)[0]
            states.append(codes)
        def at_goal(state):
            return tuple(g if g is not None and _fields(self.lifted, c, s) == _fields(self.lifted, g, s) else c
                         for c, g, s in zip(state, goal.codes, sticks))
        return tuple(at_goal(s) for s in states)

    def __call__(self, transition: TransitionFn, start: np.ndarray, goal: SymbolicGoal, timeout_s: float) -> PlanResult:
        t0 = time.perf_counter()
        init = [int(c) for c in start]
        try:
            problem = problem_pddl(self.lifted, init, goal, "task", self.costs, self.statics)
        except ValueError as e:
            return failed(self.name, PlanStatus.ERROR, t0, str(e))
        self._save(problem)
        write_s = time.perf_counter() - t0
        res = solve_texts(self.domain, problem, self.engine, max(timeout_s - write_s, 0.001),
                          action_ids=lambda steps: [a for a, _ in self.decode(steps)])
        extra = dict(res.extra, pddl_write_time_s=round(write_s, 5))
        alternatives = [alt for _, alt in self.decode(res.steps)] if res.found else None
        predicted = self.predictions(init, list(res.plan), goal, alternatives) if res.found else ()
        return dataclasses.replace(res, planner=self.name, predicted_states=predicted,
                                   planning_time_s=write_s + res.planning_time_s, extra=extra)

    def _save(self, problem: str) -> None:
        """With write_dir: domain.pddl once, then problem.pddl, problem_2.pddl for a replan, ..."""
        if self.write_dir is None:
            return
        self.calls += 1
        self.write_dir.mkdir(parents=True, exist_ok=True)
        if self.calls == 1:
            atomic_write_text(path_under(self.write_dir, "domain.pddl"), self.domain)
        name = "problem.pddl" if self.calls == 1 else f"problem_{self.calls}.pddl"
        atomic_write_text(path_under(self.write_dir, name), problem)
