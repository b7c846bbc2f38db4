"""Benchmark the learned relational route on a problem set, closed loop, resumable problem by problem.

    symlearn benchmark-learned --run RUN --problems problems/dev --out RUN/learned/dev.json
"""
from __future__ import annotations

import json
from pathlib import Path

from pddl_export.files import atomic_write_text, sha256_file
from pddl_export.learned_domain import operators_from_json
from symlearn.learning.relational_training import CHECKPOINT, load_relational
from symlearn.planning.learned_loop import LearnedLoopConfig, LoopResult, run_learned, summarize
from symlearn.problems.problem import load_problems
from symlearn.provenance import versions


def benchmark_learned(run_dir: Path, problems_dir: Path, out: Path, timeout_s: float = 10.0,
                      goal_relations: tuple[str, ...] = (), drop: tuple[str, ...] = ()) -> dict:
    """Run every problem of problems_dir; the result file is rewritten after each problem and a rerun with the
    same settings skips the problems it holds."""
    from symlearn.sim.simulator import TabletopSimulator

    cfg = LearnedLoopConfig(timeout_s=timeout_s, goal_relations=goal_relations, drop=drop)
    ops_path = Path(run_dir) / "learned" / "operators.json"
    if not ops_path.is_file():
        raise ValueError(f"{ops_path} is missing: run symlearn export-learned --run {run_dir} first")
    ops = operators_from_json(json.loads(ops_path.read_text()), str(ops_path))
    model, blob = load_relational(Path(run_dir))
    settings = {"run": str(run_dir), "model_sha256": sha256_file(Path(run_dir) / CHECKPOINT),
                "operators_sha256": sha256_file(ops_path), "problems": str(problems_dir),
                "config": {**cfg.__dict__, "goal_relations": list(cfg.goal_relations), "drop": list(cfg.drop)}}
    done: dict[str, dict] = {}
    if out.is_file():
        old = json.loads(out.read_text())
        if old.get("settings") != settings:
            raise ValueError(f"{out} holds a benchmark of other settings; choose another --out")
        done = {r["name"]: r for r in old["results"]}
    results = []
    with TabletopSimulator() as sim:
        for _, problem in load_problems(Path(problems_dir)):
            if problem.name in done:
                results.append(done[problem.name])
                continue
            r = run_learned(sim, model, blob, ops, problem, cfg)
            results.append(r.to_json())
            rows = [LoopResult(**x) for x in results]
            atomic_write_text(out, json.dumps({"settings": settings, "summary": summarize(rows), "results": results,
                                               "versions": versions()}, indent=1))
    rows = [LoopResult(**x) for x in results]
    res = {"settings": settings, "summary": summarize(rows), "results": results, "versions": versions()}
    atomic_write_text(out, json.dumps(res, indent=1))
    return res


def carry_goals(run_dir: Path, goal_relations: tuple[str, ...] = ()) -> list[dict]:
    """Each carrying goal planned by stock Fast Downward on RUN/learned/domain.pddl and executed, closed loop."""
    from symlearn.learning.carrying import carry_problems
    from symlearn.sim.simulator import TabletopSimulator

    model, blob = load_relational(Path(run_dir))
    ops_path = Path(run_dir) / "learned" / "operators.json"
    ops = operators_from_json(json.loads(ops_path.read_text()), str(ops_path))
    with TabletopSimulator() as sim:
        return [run_learned(sim, model, blob, ops, p, LearnedLoopConfig(goal_relations=goal_relations)).to_json()
                for p in carry_problems(sim)]
