"""A benchmark's summaries of its rows: per planner (success, found rate, times, lengths), the objects x
shortest-plan length grid (goals off the table locations in their own column), the older objects x
reference-length grid, failure causes, goals on and off the locations, structure-suite tasks; and the per-planner
summary as a text table. symlearn.planning.benchmark puts them in its result; symlearn.planning.benchmark_plots
draws the grids.
"""
from __future__ import annotations

import statistics

from symlearn.planning.execution import ProblemRun, failure_causes
from symlearn.problems.problem import RANDOM_WALK


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


LENGTH_BUCKETS = ("1-2", "3-4", "5-6", "7-8", "9+", "?")  # reference (generator) plan lengths, in plot order
LOOPS = ("open", "closed")


def _pair_bucket(length, top: str) -> str:
    """"1-2", "3-4", "5-6", "7-8" for a length of 1-8, `top` above 8, "?" for 0 or unknown."""
    if not isinstance(length, int) or length <= 0:
        return "?"
    if length > 8:
        return top
    lo = length - (length + 1) % 2
    return f"{lo}-{lo + 1}"


def length_bucket(length: int | None) -> str:
    """The reference-length bucket of a problem: "1-2", "3-4", "5-6", "7-8", "9+", or "?" for 0 or unknown."""
    return _pair_bucket(length, "9+")


def _cell(rows: list[ProblemRun]) -> dict:
    """Success, found rate, median planning time and (over solved rows) mean plan and reference lengths."""
    solved = [r for r in rows if r.found]
    return {"n": len(rows), "success_rate": _rate(rows, "success"), "found_rate": _rate(rows, "found"),
            "median_time_s": round(statistics.median(r.planning_time_s for r in rows), 5),
            "mean_plan_length": round(statistics.mean(r.plan_length for r in solved), 3) if solved else None,
            "mean_reference_length": round(statistics.mean(r.generator_length for r in solved), 3) if solved else None}


def summary_grid(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> object count -> length bucket -> cell (_cell); only cells with rows."""
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        out[planner] = {}
        for loop in LOOPS:
            mine = [r for r in rows if r.planner == planner and r.closed_loop == (loop == "closed")]
            by_objects: dict = {}
            for k in sorted({r.n_objects for r in mine}):
                cells = {b: [r for r in mine if r.n_objects == k and length_bucket(r.generator_length) == b]
                         for b in LENGTH_BUCKETS}
                by_objects[str(k)] = {b: _cell(rs) for b, rs in cells.items() if rs}
            if by_objects:
                out[planner][loop] = by_objects
    return out


SHORTEST_BUCKETS = ("1-2", "3-4", "5-6", "7-8", "9-12", "off", "?")  # shortest-plan lengths, in plot order
OFF_LOCATIONS = "off"  # the column of goals with a judged object off the table locations


def shortest_bucket(row: ProblemRun) -> str:
    """A row's shortest-plan column: "1-2" ... "9-12", "off" (a goal off the locations), or "?" (undecided)."""
    return OFF_LOCATIONS if row.goal_off_locations else _pair_bucket(row.optimal_length, "9-12")


def _shortest_cell(rows: list[ProblemRun]) -> dict:
    """_cell, plus the mean shortest length, executed / shortest length over the successes, and failure causes."""
    out = _cell(rows)
    known = [r for r in rows if r.optimal_length]
    ratios = [r.executed_length / r.optimal_length for r in known if r.success and r.executed_length is not None]
    out["mean_optimal_length"] = round(statistics.mean(r.optimal_length for r in known), 3) if known else None
    out["mean_length_ratio"] = round(statistics.mean(ratios), 3) if ratios else None
    out["failure_causes"] = failure_causes(rows)
    return out


def summary_shortest_grid(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> object count -> shortest-plan column (SHORTEST_BUCKETS) -> cell.

    A cell: n, success and found rates, median planning time, mean plan and reference lengths (solved rows),
    mean shortest length, mean executed / shortest length over its successes, and failure causes (counts).
    """
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        for loop in LOOPS:
            mine = [r for r in rows if r.planner == planner and r.closed_loop == (loop == "closed")]
            for k in sorted({r.n_objects for r in mine}):
                cells = {b: [r for r in mine if r.n_objects == k and shortest_bucket(r) == b]
                         for b in SHORTEST_BUCKETS}
                out.setdefault(planner, {}).setdefault(loop, {})[str(k)] = {
                    b: _shortest_cell(rs) for b, rs in cells.items() if rs}
    return out


def summary_failure_causes(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> failure cause -> count (adding up to that planner's failed rows)."""
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        out[planner] = {loop: failure_causes([r for r in rows if r.planner == planner
                                              and r.closed_loop == (loop == "closed")])
                        for loop in LOOPS if any(r.planner == planner and r.closed_loop == (loop == "closed")
                                                 for r in rows)}
    return out


def summary_goal_placement(rows: list[ProblemRun]) -> dict:
    """planner -> "on_locations"/"off_locations" -> n, open and closed success, closed-loop failure causes.

    A goal with an object off the table locations (Problem.goal_off_locations) asks for a pose that symbols of
    place and level cannot name; success there and elsewhere are kept apart. Rows without the count are left out.
    """
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        mine = [r for r in rows if r.planner == planner and r.goal_off_locations is not None]
        for name, off in (("on_locations", False), ("off_locations", True)):
            part = [r for r in mine if (r.goal_off_locations > 0) == off]
            opened, closed = [r for r in part if not r.closed_loop], [r for r in part if r.closed_loop]
            if part:
                out.setdefault(planner, {})[name] = {
                    "n_problems": len(opened or closed), "success_rate": _rate(opened, "success"),
                    "success_rate_closed_loop": _rate(closed, "success"),
                    "closed_loop_failure_causes": failure_causes(closed) if closed else None}
    return out


def summary_tasks(rows: list[ProblemRun]) -> dict:
    """planner -> "open"/"closed" -> structure-suite task -> cell; random-walk problems are left to the grid."""
    out: dict = {}
    for planner in dict.fromkeys(r.planner for r in rows):
        for loop in LOOPS:
            mine = [r for r in rows if r.planner == planner and r.closed_loop == (loop == "closed")
                    and r.task != RANDOM_WALK]
            for task in sorted({r.task for r in mine}):
                out.setdefault(planner, {}).setdefault(loop, {})[task] = _cell([r for r in mine if r.task == task])
    return out


def format_goal_placement(result: dict) -> str:
    """One line per planner: success on goals every object of which rests on a table location, and on the rest."""
    lines = []
    for planner, parts in result.get("goal_placement", {}).items():
        cells = []
        for name, label in (("on_locations", "goals on the locations"), ("off_locations", "goals off them")):
            c = parts.get(name)
            if c:
                rates = "/".join("-" if v is None else f"{v:.3f}" for v in (c["success_rate"],
                                                                             c["success_rate_closed_loop"]))
                cells.append(f"{label} {rates} ({c['n_problems']})")
        lines.append(f"{planner}: success open/closed, " + "; ".join(cells))
    return "\n".join(lines)


def format_table(result: dict) -> str:
    """The benchmark summary as a text table, one row per planner."""
    cols = [("success_rate", "success"), ("success_rate_closed_loop", "closed"), ("found_rate", "found"),
            ("median_time_s", "med t (s)"), ("mean_plan_length", "plan len"), ("mean_generator_length", "gen len")]
    width = max([20, *(len(p) + 2 for p in result["summary"])])  # the longest planner name still lines up
    head = f"{'planner':<{width}}" + "".join(f"{label:>11}" for _, label in cols)
    lines = [head, "-" * len(head)]
    for planner, s in result["summary"].items():
        cells = []
        for key, _ in cols:
            v = s.get(key)
            cells.append(f"{'-':>11}" if v is None else f"{v:>11.3f}" if isinstance(v, float) else f"{v:>11}")
        lines.append(f"{planner:<{width}}" + "".join(cells))
    return "\n".join(lines)
