"""README's headline figures are recomputed from the one result file each row names, within the printed rounding.

Each row of the table under "## Results next to the paper" names a file (the shipped run's `pretrained/recommended`
JSONs or a `bench/results` JSON); HEADLINE says, per row label, how its figures are read from that file. Every number
printed in the row's "ours" cell must equal the recomputed one to the digits printed (0.947 stands for 0.9465 up to
0.9475), so a re-run that moves a figure, a row pointing at another run's file, or a row without a recipe here fails.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHORT = ("1-2", "3-4")  # the cells of 1-4-action shortest plans
DEEP = ("5-6", "7-8")


def _placement(d: dict, planner: str, where: str) -> float:
    return d["goal_placement"][planner][where]["success_rate_closed_loop"]


def _cells(d: dict, planner: str, lengths: tuple[str, ...], objects: range) -> list[float]:
    grid = d["shortest_grid"][planner]["closed"]
    return [cell["success_rate"] for k, row in grid.items() if int(k) in objects
            for length, cell in row.items() if length in lengths]


def _mae(d: dict) -> list[float]:
    return [d["effect_mae_mm"][a] for a in "xyz"]


def _table1(d: dict) -> list[float]:
    c = d["criteria"]
    return [int(n) for n in c["objects_motion_right"].split("/") + c["riders_right"].split("/")]


def _short(d: dict) -> list[float]:
    cells = _cells(d, "astar-outcomes", SHORT, range(1, 6))
    return [min(cells), len(cells)]


def _deep(d: dict) -> list[float]:
    cells = _cells(d, "astar-outcomes", DEEP, range(3, 6))
    return [min(cells), max(cells)]


def _stock(d: dict) -> list[float]:
    t = d["summary"]["fd-lama-first"]["translate_plus_search_s"]
    return [t["median"], t["max"]]


def _heldout(d: dict) -> list[float]:
    shipped = d["summary"]["m20r6"]  # the shipped export's setting: min count 20, rider moves 6
    assert shipped["setting"]["min_count"] == 20 and shipped["setting"]["rider_min_count"] == 6
    return [shipped["all"]["rules"], shipped["all"]["m(z)"]]


# row label (its first words) -> (file, the row's figures in the order printed)
HEADLINE = {
    "effect MAE": ("pretrained/recommended/eval.json", _mae),
    "Table I": ("pretrained/recommended/table1.json", _table1),
    "symbols": ("pretrained/recommended/symbols.json", lambda d: [d["n_distinct"], d["n_symbols_for_95pct"]]),
    "m(z), whole scene": ("pretrained/recommended/transition_metrics.json",
                          lambda d: [d["test"]["rollout"]["1"]["scene_accuracy"],
                                     d["test"]["rollout"]["5"]["scene_accuracy"]]),
    "`astar-outcomes`: goals on": ("bench/results/test_grid_recommended.json",
                                   lambda d: [_placement(d, "astar-outcomes", w) for w in ("on_locations",
                                                                                          "off_locations")]),
    "`astar-outcomes`: worst cell": ("bench/results/test_grid_recommended.json", _short),
    "`astar-outcomes`: cells": ("bench/results/test_grid_recommended.json", _deep),
    "`fast-downward-lifted`: goals": ("bench/results/test_fdl_recommended.json",
                                      lambda d: [_placement(d, "fast-downward-lifted", "on_locations"),
                                                 _placement(d, "fast-downward-lifted", "off_locations"),
                                                 d["summary"]["fast-downward-lifted"]["median_time_s"]]),
    "stock Fast Downward": ("bench/results/stock_fd_test_recommended.json", _stock),
    "`astar-outcomes`, 48 goals": ("bench/results/zeroshot_grid_recommended.json",
                                   lambda d: [_placement(d, "astar-outcomes", "on_locations")]),
    "`fast-downward-lifted`, the same": ("bench/results/zeroshot_fdl_recommended.json",
                                         lambda d: [_placement(d, "fast-downward-lifted", "on_locations")]),
    "the lifted domain / m(z)": ("bench/results/heldout_k15h2.json", _heldout),
}


def headline_rows(readme: str) -> list[list[str]]:
    """The cells of each body row of the table under '## Results next to the paper'."""
    section = readme.split("## Results next to the paper", 1)[1].split("\n## ", 1)[0]
    lines = [ln for ln in section.splitlines() if ln.startswith("|")]
    return [[c.strip() for c in ln.strip().strip("|").split("|")] for ln in lines[2:]]


def printed_numbers(cell: str) -> list[str]:
    """The numbers of an "ours" cell as printed ('9/9' is two numbers; a range 'a-b' two)."""
    return re.findall(r"\d+(?:\.\d+)?", cell)


def matches(printed: str, value: float) -> bool:
    """Whether `value` rounds to `printed` at the digits printed (half a unit of the last digit either way)."""
    digits = len(printed.partition(".")[2])
    return abs(float(printed) - value) <= 0.5 * 10 ** -digits + 1e-9


def spec_for(label: str) -> tuple[str, object]:
    found = [k for k in HEADLINE if label.startswith(k)]
    assert len(found) == 1, f"README headline row {label!r} has no recipe (or several) in HEADLINE"
    return HEADLINE[found[0]]


def test_every_headline_figure_is_recomputed_from_its_named_file():
    rows = headline_rows((ROOT / "README.md").read_text(encoding="utf-8"))
    assert len(rows) == len(HEADLINE), [r[0] for r in rows]  # every recipe used once, every row has one
    for label, _paper, ours, named in rows:
        path, figures = spec_for(label)
        assert named == f"`{path}`", f"{label}: names {named}, its figures come from {path}"
        data = json.loads((ROOT / path).read_text(encoding="utf-8"))
        want, got = figures(data), printed_numbers(ours)
        assert len(got) == len(want), f"{label}: printed {got}, recomputed {want}"
        bad = [(p, w) for p, w in zip(got, want) if not matches(p, w)]
        assert not bad, f"{label}: printed vs recomputed from {path}: {bad}"


def test_the_headline_files_are_of_one_shipped_run():
    """Every planning figure comes from a run of the shipped m(z) (the same transition hash), closed loop, 10 s."""
    shipped = {json.loads((ROOT / path).read_text(encoding="utf-8")).get("transition_sha256")
               for path, _ in HEADLINE.values() if path.startswith("bench/results/test_")
               or path.startswith("bench/results/zeroshot_")}
    assert len(shipped) == 1 and None not in shipped, shipped
    for path, _ in HEADLINE.values():
        d = json.loads((ROOT / path).read_text(encoding="utf-8"))
        if "goal_placement" in d:
            assert d["closed_loop"] is True and d["timeout_s"] == 10.0, path


@pytest.mark.parametrize("printed, value, ok", [("0.947", 0.9467, True), ("0.947", 0.9476, False),
                                                ("0.37", 0.37407, True), ("9", 9, True), ("0.48", 0.47, False),
                                                ("1.00", 0.995, True), ("1.00", 0.994, False)])
def test_the_rounding_tolerance(printed, value, ok):
    assert matches(printed, value) is ok


def test_a_figure_that_drifted_is_caught():
    rows = headline_rows((ROOT / "README.md").read_text(encoding="utf-8"))
    label, _, ours, _ = next(r for r in rows if r[0].startswith("`fast-downward-lifted`: goals"))
    path, figures = spec_for(label)
    want = figures(json.loads((ROOT / path).read_text(encoding="utf-8")))
    assert not matches("0.893", want[0])  # the earlier domain's figure (2026-12-03)
    assert printed_numbers("**0.80-1.00**") == ["0.80", "1.00"] and printed_numbers("9/9, 3/3") == ["9", "9", "3", "3"]


def test_the_results_grid_is_recomputed_from_its_two_files():
    """docs/RESULTS.md's test grid, `astar-outcomes / fast-downward-lifted` per cell of objects x shortest-plan
    length, equals the closed-loop cells of the two files it names (no row of an earlier domain left in it)."""
    text = (ROOT / "docs" / "RESULTS.md").read_text(encoding="utf-8")
    section = text.split("## Planning on the test set", 1)[1].split("\n## ", 1)[0]
    assert "`bench/results/test_grid_recommended.json`" in section and "`bench/results/test_fdl_recommended.json`" in section
    grids = [json.loads((ROOT / "bench" / "results" / f).read_text(encoding="utf-8"))["shortest_grid"][p]["closed"]
             for f, p in (("test_grid_recommended.json", "astar-outcomes"),
                          ("test_fdl_recommended.json", "fast-downward-lifted"))]
    lines = [ln for ln in section.splitlines() if ln.startswith("| objects |")]
    assert len(lines) == 1
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    columns = ["off" if c.startswith("off") else c for c in header[1:]]
    rows = [[c.strip() for c in ln.strip("|").split("|")] for ln in section.splitlines()
            if re.match(r"\| [1-5] \|", ln)]
    assert [r[0] for r in rows] == ["1", "2", "3", "4", "5"]
    checked = 0
    for k, *cells in rows:
        for column, cell in zip(columns, cells):
            if cell == "-":
                assert all(column not in g[k] for g in grids), (k, column)
                continue
            printed = printed_numbers(cell)
            want = [g[k][column]["success_rate"] for g in grids]
            assert len(printed) == 2 and all(matches(p, w) for p, w in zip(printed, want)), (k, column, cell, want)
            checked += 1
    assert checked == 20


def test_the_learned_route_table_is_the_one_its_result_file_holds():
    # README's table under "A domain learned all the way down": each route's success at 1-5, 6-8, 9-10 objects and on
    # structures, two digits, from bench/results/relations_test21_table.json (one run each on the fresh sets
    # 1011-1014; docs/RELATIONS.md prints the same figures), the learned row's runs also in relations_test21_runs.json
    table = json.loads((ROOT / "bench/results/relations_test21_table.json").read_text())["table"]
    runs = json.loads((ROOT / "bench/results/relations_test21_runs.json").read_text())["runs"]
    rows = {"learned carry `at` + `on`, stock lama-first, then LM-cut on its task (`pretrained/relations_carry`)":
            "learned carry (fd-lama-first)",
            "oracle predicates, stock Fast Downward (`fast-downward-lifted`)": "oracle predicates (fast-downward-lifted)",
            "whole codes (`astar-outcomes`, the paper's route)": "whole codes (astar-outcomes)"}
    readme = (ROOT / "README.md").read_text()
    sets = ("rel_test21", "rel_test2168", "rel_test21910", "rel_struct_test21")
    for label, route in rows.items():
        m = re.search(rf"^\| {re.escape(label)} \| ([^|]+) \| ([^|]+) \| ([^|]+) \| ([^|]+) \|$", readme, re.M)
        assert m, label
        cells = [[float(x) for x in re.findall(r"[0-9]+\.[0-9]+", c)] for c in m.groups()]
        want = [table[route][band]["all"]["success"] for band in ("1-5", "6-8", "9-10", "structures")]
        assert [c[0] for c in cells] == [round(w, 2) for w in want], (label, want)
        if route.startswith("learned"):  # the same runs, as their own result file holds them
            for s, c in zip(sets, cells):
                assert next(iter(runs[f"s0_{s}"]["summary"].values()))["success"] == pytest.approx(c[0], abs=0.005)
