"""Benchmarking planners on a directory of problems: plan with the learned symbols, execute, score.

Planners are named entries of the one registry, symlearn.planning.planners.PLANNERS (the
learned-net A* variants and the planners on the exported rules); `benchmark` builds the named
ones for the run and refuses unknown names before any work.

    >>> res = benchmark(Path("runs/paper"), Path("problems/p13"), ["astar", "astar-ucs"],
    ...                 Path("runs/paper/bench.json"), closed_loop=True, timeout_s=30)  # doctest: +SKIP
    >>> print(format_table(res))                                                        # doctest: +SKIP
"""
from __future__ import annotations

import statistics
import time
from pathlib import Path

from symlearn.planning.execution import ExecutionConfig, ProblemRun, run_problem
from symlearn.planning.planners import make_planners
from symlearn.planning.recording import PlanRecorder
from symlearn.provenance import atomic_write_json, sha256_bytes, versions


def _rate(rows: list[ProblemRun], key: str) -> float | None:
    return round(sum(bool(getattr(r, key)) for r in rows) / len(rows), 4) if rows else None


def summarize_rows(rows: list[ProblemRun]) -> dict:
    """Per-planner aggregates: success, found rate, median planning time, plan and generator lengths."""
    out = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        open_rows = [r for r in rows if r.planner == planner and not r.closed_loop]
        closed = [r for r in rows if r.planner == planner and r.closed_loop]
        base = open_rows or closed
        found = [r for r in base if r.found]
        stages: dict[str, int] = {}
        for r in base:
            if r.failure_stage is not None:
                stages[r.failure_stage.value] = stages.get(r.failure_stage.value, 0) + 1
        s = {"n_problems": len(base), "success_rate": _rate(open_rows, "success"), "found_rate": _rate(base, "found"),
             "symbolic_match_rate": _rate(open_rows, "symbolic_match"),
             "median_time_s": round(statistics.median(r.planning_time_s for r in base), 5) if base else None,
             # lengths over the problems the planner solved, so the two means compare like with like
             "mean_plan_length": round(statistics.mean(r.plan_length for r in found), 3) if found else None,
             "mean_generator_length": round(statistics.mean(r.generator_length for r in found), 3) if found else None,
             "failure_stages": stages}
        for key in ("planner_time_s", "pddl_write_time_s"):
            vals = [r.timings[key] for r in base if key in r.timings]
            if vals:
                s[f"median_{key}"] = round(statistics.median(vals), 5)
        s["median_time_s_by_objects"] = {
            str(k): round(statistics.median(r.planning_time_s for r in base if r.n_objects == k), 5)
            for k in sorted({r.n_objects for r in base})}
        s["success_rate_by_objects"] = {
            str(k): _rate([r for r in open_rows if r.n_objects == k], "success")
            for k in sorted({r.n_objects for r in open_rows})}
        if closed:
            s["success_rate_closed_loop"] = _rate(closed, "success")
            s["mean_replans_closed_loop"] = round(statistics.mean(r.replans for r in closed), 3)
        out[planner] = s
    return out


def benchmark(run_dir: Path, problems_dir: Path, planners: list[str], out_file: Path,
              closed_loop: bool = False, timeout_s: float = 30.0, max_replans: int = 3,
              show_progress: bool = True, record_dir: Path | None = None) -> dict:
    """Plan and execute every problem with every planner (closed loop too if asked); write out_file.

    With record_dir, each failed open-loop run is saved as record_dir/<problem>_<planner>.gif."""
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.planning.problem import load_problems
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import LearnedTransition
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    if not planners:
        raise ValueError("no planners given")
    run_dir, problems_dir, out_file = Path(run_dir), Path(problems_dir), Path(out_file)
    fns = make_planners(list(planners), run_dir)  # refuses unknown names (and missing rules) before any work
    problems = load_problems(problems_dir)
    encoder, _ = load_effect_model(run_dir)
    transition = LearnedTransition.from_run(run_dir)
    open_cfg = ExecutionConfig(closed_loop=False, max_replans=max_replans, timeout_s=timeout_s)
    closed_cfg = ExecutionConfig(closed_loop=True, max_replans=max_replans, timeout_s=timeout_s)
    rows: list[ProblemRun] = []
    t0 = time.perf_counter()
    with TabletopSimulator() as sim:
        for i, (path, problem) in enumerate(problems):
            for name, fn in fns.items():
                rec = None if record_dir is None else PlanRecorder()
                row = run_problem(sim, encoder, transition, problem, name, fn, open_cfg, recorder=rec)
                if rec is not None and not row.success:
                    rec.save_gif(Path(record_dir) / f"{problem.name}_{name}.gif")
                rows.append(row)
                if closed_loop:
                    rows.append(run_problem(sim, encoder, transition, problem, name, fn, closed_cfg))
                if show_progress:
                    print(f"[{i + 1}/{len(problems)}] {problem.name} {name}: {row.status} "
                          f"len {row.plan_length} success {row.success}"
                          + (f" closed-loop {rows[-1].success}" if closed_loop else ""), flush=True)
    result = {"run": str(run_dir), "problems": str(problems_dir), "n_problems": len(problems),
              "planners": list(planners), "closed_loop": closed_loop, "timeout_s": timeout_s,
              "max_replans": max_replans,
              "transition_sha256": sha256_bytes((run_dir / TRANSITION_FILE).read_bytes())[:16],
              "problems_sha256": sha256_bytes(b"".join(sha256_bytes(p.read_bytes()).encode()
                                                       for p, _ in problems))[:16],
              "versions": versions(), "wall_time_s": round(time.perf_counter() - t0, 2),
              "summary": summarize_rows(rows), "rows": [r.to_json() for r in rows]}
    out_file.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_json(out_file, result)
    return result


def format_table(result: dict) -> str:
    """The benchmark summary as a text table, one row per planner."""
    cols = [("success_rate", "success"), ("success_rate_closed_loop", "closed"), ("found_rate", "found"),
            ("median_time_s", "med t (s)"), ("mean_plan_length", "plan len"), ("mean_generator_length", "gen len")]
    head = f"{'planner':<20}" + "".join(f"{label:>11}" for _, label in cols)
    lines = [head, "-" * len(head)]
    for planner, s in result["summary"].items():
        cells = []
        for key, _ in cols:
            v = s.get(key)
            cells.append(f"{'-':>11}" if v is None else f"{v:>11.3f}" if isinstance(v, float) else f"{v:>11}")
        lines.append(f"{planner:<20}" + "".join(cells))
    return "\n".join(lines)
