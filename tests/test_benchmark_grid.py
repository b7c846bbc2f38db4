"""The benchmark's objects x reference-length grid, failure causes, task summary, plots and multi-set runs.

The summaries are checked on hand-made rows whose rates, medians and means are worked out by
hand; the plots are read back as images; a benchmark over two problem sets runs end to end.
"""
from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from conftest import cli
from symlearn.planning.benchmark_rows import load_sets, problem_sets
from symlearn.planning.benchmark_summary import length_bucket, summary_failure_causes, summary_grid, summary_tasks
from symlearn.planning.benchmark_plots import (DPI, PANEL_IN, PLOT_FILES, format_grid, grid_of,
                                               markdown_grid, write_plots)
from symlearn.planning.execution import ProblemRun

PRETRAINED_PROBLEMS = Path(__file__).resolve().parents[1] / "pretrained" / "quick-authors12k" / "problems"


def _row(planner: str, k: int, ref: int, *, success: bool, found: bool = True, closed: bool = False,
         t: float = 1.0, length: int | None = None, cause: str | None = None, task: str = "random-walk") -> ProblemRun:
    return ProblemRun(problem=f"p{k}_{ref}", planner=planner, found=found, status="solved" if found else "timeout",
                      plan_length=(length if length is not None else ref) if found else None, planning_time_s=t,
                      expansions=None, success=success, symbolic_match=success, max_distance_m=None,
                      closed_loop=closed, replans=0,
                      failure_stage=None if success else ("execution" if found else "timeout"),
                      generator_length=ref, n_objects=k, task=task,
                      failure_cause=None if success else cause)


ROWS = [
    # astar, open loop, 4 objects, references 5 and 6 (bucket "5-6")
    _row("astar", 4, 5, success=True, t=1.0, length=5),
    _row("astar", 4, 6, success=False, t=3.0, length=7, cause="departure"),
    _row("astar", 4, 5, success=False, found=False, t=10.0, cause="timeout"),
    # astar, closed loop, the same problems
    _row("astar", 4, 5, success=True, closed=True, t=1.5, length=5),
    _row("astar", 4, 6, success=True, closed=True, t=2.5, length=6),
    _row("astar", 4, 5, success=False, found=False, closed=True, t=10.0, cause="timeout"),
    # outside the main buckets: a long reference, an unknown one
    _row("astar", 5, 9, success=False, t=4.0, length=9, cause="symbol_aliasing"),
    _row("astar", 1, 0, success=True, t=0.1, length=0),
    _row("astar", 2, 3, success=False, t=0.2, length=3, cause=None, task="tower-2"),
    _row("astar", 2, 4, success=True, t=0.4, length=4, task="tower-2"),
    # another planner, one cell
    _row("fast-downward-lifted", 4, 7, success=False, t=20.0, length=7, cause="departure"),
    _row("fast-downward-lifted", 4, 8, success=True, t=30.0, length=8),
]


def test_length_buckets():
    assert [length_bucket(n) for n in (1, 2, 3, 4, 5, 6, 7, 8, 9, 15)] == (
        ["1-2", "1-2", "3-4", "3-4", "5-6", "5-6", "7-8", "7-8", "9+", "9+"])
    assert length_bucket(0) == length_bucket(None) == length_bucket(-1) == "?"


def test_grid_cells_hold_the_hand_computed_rates_medians_and_means():
    grid = summary_grid(ROWS)
    assert list(grid) == ["astar", "fast-downward-lifted"]
    cell = grid["astar"]["open"]["4"]["5-6"]
    assert cell["n"] == 3
    assert cell["success_rate"] == pytest.approx(1 / 3, abs=1e-4) and cell["found_rate"] == pytest.approx(2 / 3, abs=1e-4)
    assert cell["median_time_s"] == pytest.approx(3.0)
    assert cell["mean_plan_length"] == pytest.approx(6.0) and cell["mean_reference_length"] == pytest.approx(5.5)
    closed = grid["astar"]["closed"]["4"]["5-6"]
    assert closed["n"] == 3 and closed["success_rate"] == pytest.approx(2 / 3, abs=1e-4)
    assert closed["median_time_s"] == pytest.approx(2.5) and closed["mean_plan_length"] == pytest.approx(5.5)
    assert set(grid["astar"]["open"]) == {"1", "2", "4", "5"} and set(grid["astar"]["closed"]) == {"4"}
    assert list(grid["astar"]["open"]["5"]) == ["9+"] and list(grid["astar"]["open"]["1"]) == ["?"]
    assert grid["astar"]["open"]["2"]["3-4"]["success_rate"] == pytest.approx(0.5)
    sym = grid["fast-downward-lifted"]["open"]["4"]["7-8"]
    assert (sym["n"], sym["success_rate"], sym["median_time_s"], sym["mean_reference_length"]) == (2, 0.5, 25.0, 7.5)
    assert "closed" not in grid["fast-downward-lifted"]
    assert sum(c["n"] for loops in grid.values() for objs in loops.values() for cells in objs.values()
               for c in cells.values()) == len(ROWS)


def test_failure_causes_add_up_to_the_failures():
    causes = summary_failure_causes(ROWS)
    for planner, loops in causes.items():
        for loop, counts in loops.items():
            failed = [r for r in ROWS if r.planner == planner and r.closed_loop == (loop == "closed") and not r.success]
            assert sum(counts.values()) == len(failed)
    assert causes["astar"]["open"] == {"departure": 1, "symbol_aliasing": 1, "timeout": 1, "unattributed": 1}
    assert causes["astar"]["closed"] == {"timeout": 1} and causes["fast-downward-lifted"] == {"open": {"departure": 1}}


def test_task_summary_covers_structure_tasks_only():
    tasks = summary_tasks(ROWS)
    assert list(tasks) == ["astar"] and list(tasks["astar"]) == ["open"]
    cell = tasks["astar"]["open"]["tower-2"]
    assert cell["n"] == 2 and cell["success_rate"] == 0.5 and cell["median_time_s"] == pytest.approx(0.3)


def test_text_and_markdown_renderings_show_the_cells():
    grid = summary_grid(ROWS)
    text = format_grid(grid)
    line = next(ln for ln in text.splitlines()[text.splitlines().index(
        "astar: success open/closed (n) by objects x reference length") + 2:] if ln.split()[0] == "4")
    assert line.split() == ["4", "-", "-", "0.33/0.67", "(3)", "-", "-", "-"]
    md = markdown_grid({"grid": grid, "failure_causes": summary_failure_causes(ROWS), "tasks": summary_tasks(ROWS)})
    assert "| objects | 1-2 | 3-4 | 5-6 | 7-8 | 9+ | ? |" in md  # astar reaches the extra buckets
    assert "| 4 | - | - | 0.33 / 0.67 (3) | - | - | - |" in md
    assert "| 4 | - | - | - | 0.50 / - (2) |" in md  # fast-downward-lifted: open loop only
    assert "| astar | open | 1 | 1 | 1 | 1 |" in md and "| fast-downward-lifted | open | 1 | 0 | 0 | 0 |" in md
    assert "| astar | open | tower-2 | 2 | 0.50 | 1.00 | 0.300 |" in md


def test_plots_are_pngs_of_the_expected_size(tmp_path):
    from PIL import Image
    import matplotlib.image as mpimg

    paths = write_plots(summary_grid(ROWS), tmp_path / "plots")
    assert [p.name for p in paths] == list(PLOT_FILES)
    panels = 4  # object counts 1, 2, 4, 5
    for path in paths:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 1000
        with Image.open(path) as im:
            assert im.format == "PNG" and im.size == (round(PANEL_IN[0] * panels * DPI), round(PANEL_IN[1] * DPI))
        pixels = mpimg.imread(path)
        assert pixels.shape[:2] == (round(PANEL_IN[1] * DPI), round(PANEL_IN[0] * panels * DPI))
        assert np.ptp(pixels[..., :3]) > 0.5  # something is drawn on the white figure
    assert not list((tmp_path / "plots").glob("*.tmp*"))
    with pytest.raises(ValueError, match="empty"):
        write_plots({}, tmp_path / "none")


def test_module_main_renders_a_saved_result_even_without_a_grid(tmp_path, capsys):
    """An older result JSON holds rows only: the grid is recomputed from them, the same as a new one's."""
    old = tmp_path / "old.json"
    old.write_text(json.dumps({"rows": [r.to_json() for r in ROWS]}))
    rc, printed = cli("plots", old, "--out", tmp_path / "plots")
    assert rc == 0
    want = markdown_grid(grid_of({"rows": [r.to_json() for r in ROWS]}))
    assert want in printed and all((tmp_path / "plots" / f).stat().st_size > 0 for f in PLOT_FILES)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"rows": []}))
    assert cli("plots", bad, "--out", tmp_path / "p2")[0] == 2
    assert "neither a grid nor rows" in capsys.readouterr().err


def test_results_split_by_planner_merge_into_one(tmp_path, capsys):
    """Two benchmarks of the same settings, other planners: one grid, equal to the grid of all rows together."""
    settings = {"run": "r", "problems": ["a", "b"], "problems_sha256": "h", "transition_sha256": "t",
                "timeout_s": 10, "max_replans": 3, "closed_loop": True}
    astar = [r.to_json() for r in ROWS if r.planner == "astar"]
    lifted = [r.to_json() for r in ROWS if r.planner == "fast-downward-lifted"]
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps({**settings, "planners": ["astar"], "rows": astar}))
    b.write_text(json.dumps({**settings, "planners": ["fast-downward-lifted"], "rows": lifted}))
    merged = tmp_path / "merged.json"
    rc, printed = cli("plots", a, b, "--out", tmp_path / "plots", "--merged", merged)
    assert rc == 0
    m = json.loads(merged.read_text())
    assert m["planners"] == ["astar", "fast-downward-lifted"] and len(m["rows"]) == len(ROWS)
    assert m["grid"] == json.loads(json.dumps(summary_grid(ROWS)))
    assert markdown_grid(grid_of(m)) in printed
    b.write_text(json.dumps({**settings, "timeout_s": 30, "planners": ["fast-downward-lifted"], "rows": lifted}))
    assert cli("plots", a, b, "--out", tmp_path / "p2")[0] == 2
    assert re.search("other settings .*timeout_s", capsys.readouterr().err)
    b.write_text(json.dumps({**settings, "planners": ["astar"], "rows": astar[:1]}))
    assert cli("plots", a, b, "--out", tmp_path / "p3")[0] == 2
    assert "both hold the row" in capsys.readouterr().err


def _sets(tmp_path: Path) -> Path:
    """A parent folder with two problem sets holding the same file names (and a stray non-set folder)."""
    parent = tmp_path / "grid"
    for name, files in (("o2-l1", ["tower_of_two.json"]), ("o3-l2", ["three_objects_two_actions.json"])):
        (parent / name).mkdir(parents=True)
        for f in files:
            shutil.copy(PRETRAINED_PROBLEMS / f, parent / name / "problem.json")
    (parent / "notes").mkdir()
    return parent


def test_several_sets_give_unique_prefixed_keys(tmp_path):
    parent = _sets(tmp_path)
    sets = problem_sets(parent)
    assert [d.name for d in sets] == ["o2-l1", "o3-l2"]
    assert problem_sets(f"{sets[0]},{sets[1]}") == sets == problem_sets(sets)
    problems = load_sets(sets)
    keys = [p.key for p in problems]
    assert keys == ["o2-l1/problem.json", "o3-l2/problem.json"] and len(set(keys)) == len(keys)
    assert [p.label for p in problems] == [f"{d.name}/{p.problem.name}" for d, p in zip(sets, problems)]
    one = load_sets(problem_sets(sets[0]))
    assert [p.key for p in one] == ["problem.json"] and one[0].label == one[0].problem.name  # one set: unprefixed
    (tmp_path / "again" / "o2-l1").mkdir(parents=True)
    with pytest.raises(ValueError, match="o2-l1 are named twice"):
        problem_sets([sets[0], tmp_path / "again" / "o2-l1"])


def test_benchmark_over_two_sets_end_to_end(tiny_run_copy, tmp_path):
    """Two generated sets with the same file names: every row is kept apart, summarized and plotted."""
    for name, seed in (("a", 0), ("b", 1)):
        rc, _ = cli("problems", "--kind", "walks", "--out", tmp_path / "sets" / name, "--n", 2, "--objects", "1-2",
                    "--length", "1-2", "--seed", seed)
        assert rc == 0
    out, plots = tmp_path / "bench.json", tmp_path / "plots"
    rc, text = cli("benchmark", "--run", tiny_run_copy, "--problems", tmp_path / "sets", "--planners", "astar",
                   "--timeout", 5, "--out", out)
    assert rc == 0 and "astar: success open/closed (n)" in text
    assert cli("plots", out, "--out", plots)[0] == 0
    b = json.loads(out.read_text())
    names = [r["problem"] for r in b["rows"] if not r["closed_loop"]]  # each problem open, then closed loop
    assert names == ["a/problem_0000", "a/problem_0001", "b/problem_0000", "b/problem_0001"]
    assert b["n_problems"] == 4 and [Path(p).name for p in b["problems"]] == ["a", "b"]
    cells = [c for objs in b["grid"]["astar"].values() for cs in objs.values() for c in cs.values()]
    assert sum(c["n"] for c in cells) == 8  # 4 problems, open and closed loop
    for loop in ("open", "closed"):
        rows = [r for r in b["rows"] if r["closed_loop"] == (loop == "closed")]
        assert sum(b["failure_causes"]["astar"][loop].values()) == sum(not r["success"] for r in rows)
    assert all((plots / f).stat().st_size > 0 for f in PLOT_FILES)
    assert not (tmp_path / "bench.json.rows.jsonl").exists()


def _srow(k: int, optimal: int | None, *, success: bool, executed: int | None = None, closed: bool = True,
          off: int = 0, cause: str | None = None) -> ProblemRun:
    return dataclasses_replace(_row("astar", k, 8, success=success, closed=closed, cause=cause,
                                    length=executed or 1),
                               optimal_length=optimal, executed_length=executed, goal_off_locations=off)


def dataclasses_replace(row, **kw):
    import dataclasses

    return dataclasses.replace(row, **kw)


SHORT_ROWS = [
    _srow(3, 5, success=True, executed=5), _srow(3, 6, success=True, executed=9),  # ratios 1 and 1.5
    _srow(3, 5, success=False, executed=2, cause="departure"), _srow(3, 6, success=False, cause="no_plan"),
    _srow(3, 1, success=True, executed=1),
    _srow(3, None, success=False, off=1, executed=4, cause="departure"),  # off the locations: its own column
    _srow(3, None, success=True, executed=2),  # undecided: "?"
    _srow(5, 9, success=True, executed=11), _srow(5, 12, success=False, cause="timeout"),
    _srow(3, 5, success=False, closed=False, cause="departure", executed=5),
]


def test_shortest_grid_cells_hold_rates_ratios_and_causes():
    from symlearn.planning.benchmark_summary import shortest_bucket, summary_shortest_grid

    assert [shortest_bucket(r) for r in SHORT_ROWS[:9]] == ["5-6", "5-6", "5-6", "5-6", "1-2", "off", "?", "9-12",
                                                            "9-12"]
    grid = summary_shortest_grid(SHORT_ROWS)["astar"]
    cell = grid["closed"]["3"]["5-6"]
    assert cell["n"] == 4 and cell["success_rate"] == 0.5 and cell["mean_optimal_length"] == 5.5
    assert cell["mean_length_ratio"] == 1.25 and cell["failure_causes"] == {"departure": 1, "no_plan": 1}
    assert grid["closed"]["3"]["off"]["failure_causes"] == {"departure": 1} and grid["closed"]["3"]["off"]["n"] == 1
    assert grid["closed"]["3"]["?"]["success_rate"] == 1.0 and grid["closed"]["3"]["?"]["mean_length_ratio"] is None
    assert grid["closed"]["5"]["9-12"]["mean_length_ratio"] == pytest.approx(11 / 9, abs=1e-3)
    assert grid["open"] == {"3": {"5-6": grid["open"]["3"]["5-6"]}} and grid["open"]["3"]["5-6"]["success_rate"] == 0


def test_shortest_grid_text_markdown_plots_and_report(tmp_path):
    from PIL import Image

    from symlearn.planning.benchmark_summary import summary_shortest_grid
    from symlearn.planning.benchmark_plots import SHORTEST_PLOT_FILES, format_shortest_grid
    from symlearn.report.gather import benchmark_section

    shortest = summary_shortest_grid(SHORT_ROWS)
    text = format_shortest_grid(shortest).splitlines()
    head = text.index("astar: success open/closed (n) by objects x shortest-plan length")
    assert text[head + 1].split() == ["objects", "1-2", "3-4", "5-6", "7-8", "9-12", "off", "?"]
    assert text[head + 2].split() == ["3", "-/1.00", "(1)", "-", "0.00/0.50", "(1)", "-", "-", "-/0.00", "(1)",
                                      "-/1.00", "(1)"]
    ratio = text.index("astar: executed / shortest plan length (closed loop, successful problems)")
    assert text[ratio + 2].split() == ["3", "1.00", "-", "1.25", "-", "-", "-", "-"]
    assert "  3 objects, 5-6: departure 1, no_plan 1" in text
    md = markdown_grid({"grid": summary_grid(SHORT_ROWS), "failure_causes": summary_failure_causes(SHORT_ROWS),
                        "tasks": {}, "shortest_grid": shortest})
    assert md.index("by shortest-plan length") < md.index("by reference length (secondary view)")
    assert "| 5 | - | - | - | - | 1.22 | - | - |" in md
    paths = write_plots(summary_grid(SHORT_ROWS), tmp_path, shortest)
    assert [p.name for p in paths] == [*SHORTEST_PLOT_FILES, *PLOT_FILES]
    with Image.open(paths[0]) as im:
        assert im.size == (round(PANEL_IN[0] * 2 * DPI), round(PANEL_IN[1] * DPI))  # panels for 3 and 5 objects
    section = benchmark_section({"summary": {"astar": {}}, "shortest_grid": shortest})
    grid_table = next(t for t in section.tables if t.key == "shortest_grid")
    assert grid_table.header == ("planner", "objects", "1-2", "3-4", "5-6", "7-8", "9-12", "off", "?")
    assert grid_table.rows[0] == ("astar", "3", "- / 1.00 (1)", "-", "0.00 / 0.50 (1)", "-", "-", "- / 0.00 (1)",
                                  "- / 1.00 (1)")
    detail = next(t for t in section.tables if t.key == "shortest_detail")
    assert detail.rows[0][:4] == ("astar", "closed", "3", "1.00") and detail.rows[0][5] == "1.25; departure 1, no_plan 1"
    old = benchmark_section({"summary": {"astar": {}}})
    assert any("before problems recorded their shortest plans" in line for line in old.text)


def test_every_row_field_is_one_the_row_log_reads():
    """A field added to ProblemRun must be in the row log's schema, or a resumed benchmark refuses its own rows."""
    import dataclasses

    from pddl_export.bounded_json import check
    from symlearn.planning.benchmark_rows import ROW_SCHEMA

    names = {f.name for f in dataclasses.fields(ProblemRun)}
    assert names == set(ROW_SCHEMA.required) | set(ROW_SCHEMA.optional)
    row = ProblemRun(problem="p", planner="astar", found=True, status="solved", plan_length=2, planning_time_s=0.1,
                     expansions=3, success=True, symbolic_match=True, max_distance_m=0.001, closed_loop=True,
                     replans=0, failure_stage=None, generator_length=2, optimal_length=2, executed_length=2)
    check(json.loads(json.dumps(row.to_json())), ROW_SCHEMA, "row")
