"""The objects x shortest-plan-length grid of a benchmark (and the older reference-length one) as text,
Markdown and plots.

`symlearn benchmark` prints `format_grid` after a run; `symlearn plots` (plots_of_results) writes
`write_plots`' figures of saved result JSONs and prints the Markdown tables for the docs:

    symlearn plots bench.json --out plots/
    symlearn plots a.json b.json --out plots/ --merged ab.json   # planners split over processes
"""
from __future__ import annotations

import math
from pathlib import Path

from pddl_export.bounded_json import JsonFileError, MiB, read_json_file
from symlearn.planning.benchmark_summary import (LENGTH_BUCKETS, LOOPS, SHORTEST_BUCKETS, summary_failure_causes,
                                                 summary_grid, summary_shortest_grid, summary_tasks)
from symlearn.planning.execution import ProblemRun
from symlearn.provenance import atomic_write_png

MAIN_BUCKETS = LENGTH_BUCKETS[:4]  # always shown; "9+" and "?" only when some row falls there
DPI = 100
PANEL_IN = (4.0, 3.2)  # inches per object-count panel (width, height)
PLOT_FILES = ("success_by_length.png", "time_by_length.png")
SHORTEST_PLOT_FILES = ("success_by_shortest.png", "length_ratio_by_shortest.png")
MAIN_SHORTEST = SHORTEST_BUCKETS[:5]  # always shown; "off" and "?" only when some row falls there


def grid_of(result: dict) -> dict:
    """The result's grids, failure causes and tasks (recomputed from its rows when an older JSON lacks them).

    A result written before shortest plans has no `shortest_grid`; from its rows every problem falls in the
    "?" column (its rows carry no shortest length), which says the problems must be annotated and re-run.
    """
    if "grid" in result and "failure_causes" in result and "shortest_grid" in result:
        return {"grid": result["grid"], "failure_causes": result["failure_causes"], "tasks": result.get("tasks", {}),
                "shortest_grid": result["shortest_grid"]}
    rows = [ProblemRun(**r) for r in result.get("rows", [])]
    if not rows:
        if "grid" in result and "failure_causes" in result:
            return {"grid": result["grid"], "failure_causes": result["failure_causes"],
                    "tasks": result.get("tasks", {}), "shortest_grid": {}}
        raise ValueError("the benchmark result holds neither a grid nor rows")
    return {"grid": summary_grid(rows), "failure_causes": summary_failure_causes(rows), "tasks": summary_tasks(rows),
            "shortest_grid": summary_shortest_grid(rows)}


def merge_results(results: list[dict], names: list[str]) -> dict:
    """One result from benchmarks of the same run and problems split by planner (e.g. run in parallel).

    Refused (ValueError naming the files) when they were run on other runs, problems, time limits, replan bounds
    or other execution settings, or when two of them hold the same (problem, planner, loop) row.
    """
    if len(results) == 1:
        return results[0]
    keys = ("run", "problems", "problems_sha256", "transition_sha256", "timeout_s", "max_replans", "closed_loop",
            "execution")
    for name, r in zip(names[1:], results[1:]):
        diff = [k for k in keys if r.get(k) != results[0].get(k)]
        if diff:
            raise ValueError(f"{name} and {names[0]} are benchmarks of other settings ({', '.join(diff)})")
    seen: dict[tuple, str] = {}
    rows = []
    for name, r in zip(names, results):
        keys_here = {(row["problem"], row["planner"], row["closed_loop"]) for row in r.get("rows", [])}
        clash = sorted(keys_here & set(seen))
        if clash:
            raise ValueError(f"{name} and {seen[clash[0]]} both hold the row {clash[0]}")
        seen.update(dict.fromkeys(keys_here, name))
        rows += r.get("rows", [])
    merged = {k: results[0].get(k) for k in keys}
    merged["planners"] = [p for r in results for p in r.get("planners", [])]
    merged["rows"] = rows
    merged.update(grid_of({"rows": rows}))
    return merged


def _axes(by_loop: dict, buckets=LENGTH_BUCKETS, main=MAIN_BUCKETS) -> tuple[list[str], list[str]]:
    """Object counts (rows) and buckets (columns) of one planner's grid, in order."""
    objects = sorted({k for loop in by_loop.values() for k in loop}, key=int)
    used = {b for loop in by_loop.values() for cells in loop.values() for b in cells}
    return objects, [b for b in buckets if b in main or b in used]


def _cell_text(by_loop: dict, k: str, bucket: str, sep: str) -> str:
    """"open/closed (n)" success rates of one cell; "-" where a loop has no rows."""
    cells = [by_loop.get(loop, {}).get(k, {}).get(bucket) for loop in LOOPS]
    if not any(cells):
        return "-"
    rates = [f"{c['success_rate']:.2f}" if c else "-" for c in cells]
    return f"{rates[0]}{sep}{rates[1]} ({next(c for c in cells if c)['n']})"


def format_grid(grid: dict) -> str:
    """One text table per planner: rows object counts, columns reference-length buckets, cells open/closed (n)."""
    out = []
    for planner, by_loop in grid.items():
        objects, buckets = _axes(by_loop)
        lines = [f"{planner}: success open/closed (n) by objects x reference length",
                 f"{'objects':>8}" + "".join(f"{b:>18}" for b in buckets)]
        lines += [f"{k:>8}" + "".join(f"{_cell_text(by_loop, k, b, '/'):>18}" for b in buckets) for k in objects]
        out.append("\n".join(lines))
    return "\n\n".join(out)


def _main_loop(by_loop: dict) -> str:
    """The loop a planner's ratio and causes are shown for: closed where it ran, else open."""
    return "closed" if "closed" in by_loop else "open"


def _ratio_text(by_loop: dict, k: str, bucket: str) -> str:
    c = by_loop.get(_main_loop(by_loop), {}).get(k, {}).get(bucket)
    return "-" if not c or c.get("mean_length_ratio") is None else f"{c['mean_length_ratio']:.2f}"


def _causes_text(by_loop: dict, k: str, bucket: str) -> str:
    c = by_loop.get(_main_loop(by_loop), {}).get(k, {}).get(bucket)
    if not c:
        return "-"
    causes = c.get("failure_causes") or {}
    return ", ".join(f"{name} {n}" for name, n in sorted(causes.items(), key=lambda kv: -kv[1])) or "none"


def format_shortest_grid(shortest: dict) -> str:
    """Per planner: success open/closed (n) by objects x shortest-plan length ("off": goals off the locations,
    "?": undecided), executed / shortest plan length over the successes, and failure causes per cell."""
    out = []
    for planner, by_loop in shortest.items():
        objects, buckets = _axes(by_loop, SHORTEST_BUCKETS, MAIN_SHORTEST)
        loop = _main_loop(by_loop)
        lines = [f"{planner}: success open/closed (n) by objects x shortest-plan length",
                 f"{'objects':>8}" + "".join(f"{b:>18}" for b in buckets)]
        lines += [f"{k:>8}" + "".join(f"{_cell_text(by_loop, k, b, '/'):>18}" for b in buckets) for k in objects]
        lines += [f"{planner}: executed / shortest plan length ({loop} loop, successful problems)",
                  f"{'objects':>8}" + "".join(f"{b:>18}" for b in buckets)]
        lines += [f"{k:>8}" + "".join(f"{_ratio_text(by_loop, k, b):>18}" for b in buckets) for k in objects]
        lines.append(f"{planner}: failure causes ({loop} loop) per cell")
        lines += [f"  {k} objects, {b}: {_causes_text(by_loop, k, b)}" for k in objects for b in buckets
                  if by_loop.get(loop, {}).get(k, {}).get(b, {}).get("failure_causes")]
        out.append("\n".join(lines))
    return "\n\n".join(out)


def markdown_shortest(shortest: dict) -> str:
    """Markdown of the shortest-plan grid: per planner success open / closed (n), executed / shortest length,
    and failure causes per cell (closed loop where it ran)."""
    parts = []
    for planner, by_loop in shortest.items():
        objects, buckets = _axes(by_loop, SHORTEST_BUCKETS, MAIN_SHORTEST)
        head = ["| objects | " + " | ".join(buckets) + " |", "|---:|" + "---:|" * len(buckets)]
        rows = [f"**{planner}**: success open / closed (n) by shortest-plan length", "", *head]
        rows += [f"| {k} | " + " | ".join(_cell_text(by_loop, k, b, " / ") for b in buckets) + " |" for k in objects]
        rows += ["", f"executed / shortest plan length ({_main_loop(by_loop)} loop, successes)", "", *head]
        rows += [f"| {k} | " + " | ".join(_ratio_text(by_loop, k, b) for b in buckets) + " |" for k in objects]
        rows += ["", f"failure causes ({_main_loop(by_loop)} loop)", "", *head]
        rows += [f"| {k} | " + " | ".join(_causes_text(by_loop, k, b) for b in buckets) + " |" for k in objects]
        parts.append("\n".join(rows))
    return "\n\n".join(parts)


def markdown_grid(summary: dict) -> str:
    """Markdown for the docs: the shortest-plan grids, then the reference-length grid per planner,
    failure causes, and structure-suite tasks."""
    parts = [markdown_shortest(summary["shortest_grid"])] if summary.get("shortest_grid") else []
    for planner, by_loop in summary["grid"].items():
        objects, buckets = _axes(by_loop)
        rows = [f"**{planner}**: success open / closed (n) by reference length (secondary view)", "",
                "| objects | " + " | ".join(buckets) + " |", "|---:|" + "---:|" * len(buckets)]
        rows += [f"| {k} | " + " | ".join(_cell_text(by_loop, k, b, " / ") for b in buckets) + " |" for k in objects]
        parts.append("\n".join(rows))
    causes = sorted({c for loops in summary["failure_causes"].values() for counts in loops.values() for c in counts})
    if causes:
        rows = ["| planner | loop | " + " | ".join(causes) + " |", "|---|---|" + "---:|" * len(causes)]
        rows += [f"| {planner} | {loop} | " + " | ".join(str(counts.get(c, 0)) for c in causes) + " |"
                 for planner, loops in summary["failure_causes"].items() for loop, counts in loops.items()]
        parts.append("Failure causes (failed rows)\n\n" + "\n".join(rows))
    if summary.get("tasks"):
        rows = ["| planner | loop | task | n | success | found | median time (s) |", "|---|---|---|---:|---:|---:|---:|"]
        rows += [f"| {planner} | {loop} | {task} | {c['n']} | {c['success_rate']:.2f} | {c['found_rate']:.2f} | "
                 f"{c['median_time_s']:.3f} |" for planner, loops in summary["tasks"].items()
                 for loop, tasks in loops.items() for task, c in tasks.items()]
        parts.append("Structure-suite tasks\n\n" + "\n".join(rows))
    return "\n\n".join(parts)


def _series(by_loop: dict, loop: str, k: str, buckets: list[str], key: str) -> list[float]:
    """A cell value per bucket for one loop and object count, NaN where there is no cell."""
    cells = by_loop.get(loop, {}).get(k, {})
    return [math.nan if cells.get(b, {}).get(key) is None else cells[b][key] for b in buckets]


def _figure(grid: dict, key: str, ylabel: str, log: bool, loops: tuple[str, ...], all_buckets=LENGTH_BUCKETS,
            main=MAIN_BUCKETS, xlabel: str = "reference plan length", ylim=(-0.03, 1.03)):
    """One panel per object count, one colour per planner; open loop solid, closed loop dashed."""
    from matplotlib.figure import Figure

    objects = sorted({k for by_loop in grid.values() for loop in by_loop.values() for k in loop}, key=int)
    buckets = [b for b in all_buckets if b in main or any(
        b in cells for by_loop in grid.values() for loop in by_loop.values() for cells in loop.values())]
    fig = Figure(figsize=(PANEL_IN[0] * max(len(objects), 1), PANEL_IN[1]), dpi=DPI, layout="constrained")
    axes = fig.subplots(1, max(len(objects), 1), squeeze=False, sharey=True)[0]
    colours = {p: f"C{i % 10}" for i, p in enumerate(grid)}
    xs = list(range(len(buckets)))  # the same bucket positions on every panel
    handles: dict = {}
    for ax, k in zip(axes, objects):
        for planner, by_loop in grid.items():
            for loop in loops:
                ys = _series(by_loop, loop, k, buckets, key)
                if not all(math.isnan(y) for y in ys):
                    (line,) = ax.plot(xs, ys, marker="o", color=colours[planner],
                                      linestyle="-" if loop == "open" else "--")
                    handles.setdefault(f"{planner} ({loop})", line)
        ax.set_title(f"{k} object{'s' if k != '1' else ''}")
        ax.set_xticks(xs, buckets)
        ax.set_xlim(-0.5, len(buckets) - 0.5)
        ax.set_xlabel(xlabel)
        if log:
            ax.set_yscale("log")
        elif ylim is not None:
            ax.set_ylim(*ylim)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(ylabel)
    if handles:
        fig.legend(list(handles.values()), list(handles), loc="outside right upper", fontsize=7)
    return fig


def _save(fig, path: Path) -> Path:
    atomic_write_png(fig, path, DPI)
    return path


def write_plots(grid: dict, out_dir: Path, shortest: dict | None = None) -> list[Path]:
    """Success and median planning time (log scale) against the reference-length bucket, as PNGs in out_dir;
    with the shortest-plan grid, success and executed / shortest plan length against the shortest-plan length."""
    if not grid:
        raise ValueError("the benchmark grid is empty: nothing to plot")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    if shortest:
        xlabel = "shortest plan length (off: goal off the locations)"
        success = _figure(shortest, "success_rate", "success rate", False, LOOPS, SHORTEST_BUCKETS, MAIN_SHORTEST,
                          xlabel)
        ratio = _figure(shortest, "mean_length_ratio", "executed / shortest plan length", False, LOOPS,
                        SHORTEST_BUCKETS, MAIN_SHORTEST, xlabel, ylim=None)
        written += [_save(success, out_dir / SHORTEST_PLOT_FILES[0]), _save(ratio, out_dir / SHORTEST_PLOT_FILES[1])]
    success = _figure(grid, "success_rate", "success rate", False, LOOPS)
    # the first planning call: open loop's, or closed loop's where only closed loop ran
    times = {p: {"open": by_loop.get("open") or by_loop.get("closed", {})} for p, by_loop in grid.items()}
    timing = _figure(times, "median_time_s", "median planning time (s)", True, ("open",))
    return written + [_save(success, out_dir / PLOT_FILES[0]), _save(timing, out_dir / PLOT_FILES[1])]


def plots_of_results(paths: list[Path], out_dir: Path, merged: Path | None = None) -> tuple[list[Path], str]:
    """Write the plots of saved benchmark results into out_dir (several results, of the same run and problems with
    other planners, are merged first; with `merged`, the merged JSON is written there too); returns the written
    paths and the Markdown tables. An unreadable or unmergeable result is a ValueError naming the file."""
    results = []
    for path in paths:
        try:
            results.append(read_json_file(path, what="benchmark JSON", max_bytes=512 * MiB))
        except JsonFileError as e:
            raise ValueError(f"not a readable benchmark JSON: {e}") from None
    try:
        result = merge_results(results, [str(p) for p in paths])
        summary = grid_of(result)
    except (ValueError, TypeError, KeyError) as e:
        raise ValueError(f"{paths[0]}: {e}") from None
    written = []
    if merged:
        from pddl_export.files import atomic_write_json, finite_or_null

        atomic_write_json(merged, finite_or_null(result))
        written.append(merged)
    return written + write_plots(summary["grid"], out_dir, summary.get("shortest_grid")), markdown_grid(summary)
