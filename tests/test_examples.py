"""The examples run as written, on the shipped run, with no data collected first: each one's defaults, from a fresh
folder, and what it prints and writes checked against the run it reads."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RECOMMENDED = ROOT / "pretrained" / "recommended"


def _example(name: str, cwd: Path, *args: str) -> str:
    r = subprocess.run([sys.executable, str(ROOT / "examples" / name), *args], cwd=cwd, capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout


def test_generate_domain_writes_the_runs_lifted_domain_and_problems_a_parser_loads(tmp_path):
    from pddl import parse_domain, parse_problem
    out = _example("generate_domain.py", tmp_path)
    folder = tmp_path / "lifted_domain"
    assert (folder / "domain.pddl").read_text() == (RECOMMENDED / "pddl" / "lifted" / "domain.pddl").read_text()
    domain = parse_domain(folder / "domain.pddl")
    from pddl_export.lifted_rules_io import load_lifted
    from pddl_export.lifted_domain import schemas
    n = len(schemas(load_lifted(RECOMMENDED / "pddl" / "lifted.json")))  # one per distinct action of the rules
    assert n == json.loads((RECOMMENDED / "pddl" / "lifted.json").read_text())["stats"]["n_schemas"]
    assert len(domain.actions) == n and f"{n} typed STRIPS schemas" in out
    index = json.loads((folder / "index.json").read_text())
    shipped = sorted(p.name for p in (RECOMMENDED / "problems").glob("*.json"))
    assert sorted(p["file"] for p in index["problems"].values()) == shipped
    for name, entry in index["problems"].items():
        problem = parse_problem(folder / f"{name}.pddl")
        assert len(problem.objects) == entry["objects"]
        assert f"{name:<8} {entry['objects']:>7}" in out
    costed = parse_domain(folder / index["cost_form"])  # the all-outcomes cost form: one action per outcome
    alternatives = sum(len(r["alternatives"]) for r in json.loads((RECOMMENDED / "pddl" / "lifted.json").read_text())[
        "rules"])
    from pddl_export.lifted_moves import moves
    rules = load_lifted(RECOMMENDED / "pddl" / "lifted.json")  # each outcome one action at most; merged far-row
    assert len(costed.actions) == len(schemas(rules, costs=True))  # moves of one cost are one schema in either form
    assert n < len(costed.actions) <= 1 + len(moves(rules)) + alternatives
    assert f"{len(costed.actions)} schemas, one per outcome" in out
    assert len(parse_problem(folder / "costs" / "p01.pddl").objects) == index["problems"]["p01"]["objects"]
    (tmp_path / "lifted_domain" / "notes.txt").write_text("mine")  # a folder holding other files is refused
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "generate_domain.py")], cwd=tmp_path,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode != 0 and "holds files other than" in r.stderr


def test_call_planners_solves_the_tower_with_every_planner_the_run_supports(tmp_path):
    out = _example("call_planners.py", tmp_path)
    rows = {line.split()[0]: line.split() for line in out.splitlines()[4:] if line.strip()}
    # the shipped run has m(z) and the lifted domain, no rules.json: the learned net and stock Fast Downward
    assert set(rows) == {"astar-outcomes", "astar", "astar-ucs", "fast-downward-lifted",
                         "fast-downward-lifted-opt", "fast-downward-lifted-outcomes"}
    for name, cells in rows.items():  # every planner plans it; none in fewer actions than the tower's shortest, 2
        assert cells[1] == "solved" and int(cells[3]) >= 2, (name, cells)
    for name in ("astar-outcomes", "fast-downward-lifted", "fast-downward-lifted-opt",
                 "fast-downward-lifted-outcomes"):  # and these in exactly 2
        assert rows[name][3] == "2", rows[name]
    assert not any((RECOMMENDED / "pddl").glob("problems"))  # nothing written into the shipped run


@pytest.mark.slow
def test_compare_planners_executes_every_plan_and_plots(tmp_path):
    """Slow (a minute or two): every default planner on the shipped run's four problems, closed loop."""
    import matplotlib.image
    out = _example("compare_planners.py", tmp_path)
    bench = json.loads((tmp_path / "compare" / "benchmark.json").read_text())
    assert list(bench["summary"]) == ["astar-outcomes", "astar", "fast-downward-lifted", "fast-downward-lifted-opt"]
    assert bench["summary"]["astar-outcomes"]["success_rate_closed_loop"] == 1.0
    assert bench["n_problems"] == 4 and "astar-outcomes" in out
    assert matplotlib.image.imread(tmp_path / "compare" / "comparison.png").std() > 0
