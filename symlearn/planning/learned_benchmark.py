"""Benchmark the learned relational route on a problem set, closed loop, resumable problem by problem.

    symlearn benchmark-learned --run RUN --problems problems/dev --out RUN/learned/dev.json
"""
from __future__ import annotations

import json
from pathlib import Path

from pddl_export.bounded_json import read_json_file
from pddl_export.files import atomic_write_text
from symlearn.export.learned_export import load_operators, operators_path, run_hashes
from symlearn.learning.relational_training import load_relational
from symlearn.planning.learned_loop import LearnedLoopConfig, LoopResult, check_ablation, run_learned, summarize
from symlearn.problems.problem import load_problems
from symlearn.provenance import versions


def benchmark_learned(run_dir: Path, problems_dir: Path, out: Path,
                      cfg: LearnedLoopConfig = LearnedLoopConfig()) -> dict:
    """Run every problem of problems_dir under cfg; the result file (cfg recorded in its settings) is rewritten after
    each problem and a rerun with the same settings skips the problems it holds."""
    from symlearn.sim.simulator import TabletopSimulator

    ops = load_operators(run_dir)
    check_ablation(cfg, ops, str(operators_path(run_dir)))
    model, blob = load_relational(Path(run_dir))
    settings = {"run": str(run_dir), **run_hashes(run_dir), "problems": str(problems_dir),
                "config": {k: list(v) if isinstance(v, tuple) else v for k, v in cfg.__dict__.items()}}
    done: dict[str, dict] = {}
    if out.is_file():
        old = read_json_file(out, what="learned-route benchmark")
        if old.get("settings") != settings:
            raise ValueError(f"{out} holds a benchmark of other settings; choose another --out")
        done = {r["name"]: r for r in old["results"]}
    results: list[dict] = []

    def record() -> dict:
        res = {"settings": settings, "summary": summarize([LoopResult(**x) for x in results]), "results": results,
               "versions": versions()}
        atomic_write_text(out, json.dumps(res, indent=1))
        return res

    with TabletopSimulator() as sim:
        for _, problem in load_problems(Path(problems_dir)):
            if problem.name in done:
                results.append(done[problem.name])
                continue
            results.append(run_learned(sim, model, blob, ops, problem, cfg).to_json())
            record()
    return record()


def carry_goals(run_dir: Path, goal_relations: tuple[str, ...] = (), relax_unreachable: bool = False) -> list[dict]:
    """Each carrying goal planned by stock Fast Downward on RUN/learned/domain.pddl and executed, closed loop."""
    from symlearn.learning.carrying import carry_problems
    from symlearn.sim.simulator import TabletopSimulator

    model, blob = load_relational(Path(run_dir))
    ops = load_operators(run_dir)
    with TabletopSimulator() as sim:
        cfg = LearnedLoopConfig(goal_relations=goal_relations, relax_unreachable=relax_unreachable)
        return [run_learned(sim, model, blob, ops, p, cfg).to_json()
                for p in carry_problems(sim)]
