"""export-pddl on a real (tiny) run, PDDL planners in the benchmark registry, and the examples."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import cli
from pddl_export.pddl_writer import action_name
from search.result import PlanResult, PlanStatus
from symlearn.planning.export import ExportConfig, export_pddl, load_rules, rules_from_json, rules_to_json
from symlearn.planning.planners import make_pddl_planner, network_agrees
from symlearn.symbolic.transition import LearnedTransition

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def run(tmp_path_factory, tiny_data, tiny_run):
    """ROOT/data: the session's tiny data set; ROOT/run: a copy of the tiny run; ROOT/problems: two problems."""
    root = tmp_path_factory.mktemp("pddl_pipeline")
    (root / "data").symlink_to(tiny_data.path, target_is_directory=True)
    shutil.copytree(tiny_run.path, root / "run")
    rc, _ = cli("problems", "--out", root / "problems", "--n", 2, "--objects", "1-2", "--length", "1-2", "--seed", 0)
    assert rc == 0
    return root


def test_export_writes_domain_rules_and_exact_report(run):
    rep = export_pddl(run / "run", run / "data", ExportConfig(max_objects=2, pddl_fidelity_cases=60))
    out = run / "run" / "pddl"
    for f in ("domain.pddl", "rules.json", "report.json"):
        assert (out / f).stat().st_size > 0
    assert rep["fidelity"] == 1.0 and rep["pddl_fidelity"] == 1.0 and rep["pddl_fidelity_cases"] >= 1
    assert rep["n_rules"] <= rep["n_rules_before_generalization"]
    assert json.loads((out / "report.json").read_text())["vocabulary_size"] == rep["vocabulary_size"] >= 1
    rules, model_hash = load_rules(run / "run")
    assert rules_to_json(rules_from_json(rules_to_json(rules))) == rules_to_json(rules) and len(model_hash) == 16
    domain = (out / "domain.pddl").read_text()
    assert model_hash in domain and "(:requirements" in domain
    assert all(action_name(a) in domain for a in rules.actions)


def test_malformed_rules_refused(tmp_path):
    with pytest.raises(ValueError, match="malformed rules file"):
        rules_from_json({"bits": 8, "rules": [{"action": 1}]})
    with pytest.raises(ValueError, match="no exported rules"):
        load_rules(tmp_path)


def test_pddl_planner_plans_on_exported_rules_and_agrees_with_net(run):
    rules, model_hash = load_rules(run / "run")
    tr = LearnedTransition.from_run(run / "run")
    changing = [r for r in rules.rules if not r.requires and not r.at_least]
    if not changing:
        pytest.skip("the tiny network changes no code without context")
    r = changing[0]
    start = np.array([r.code_from])
    goal_code = int(tr(start[None], np.array([r.action]))[0, 0])
    from pddl_export.symbolic import SymbolicGoal

    goal = SymbolicGoal((goal_code,))
    for name in ("fast-downward", "pyperplan", "fast-downward-sas"):
        res = make_pddl_planner(rules, model_hash, name)(tr, start, goal, 30.0)
        assert res.status is PlanStatus.SOLVED, res.message
        write_key = "sas_write_time_s" if name.endswith("-sas") else "pddl_write_time_s"
        assert write_key in res.extra and res.extra["rules_vs_net"] is False
        assert network_agrees(tr, res)


def test_network_disagreement_detected():
    class Const:
        bits = 8

        def __call__(self, codes, actions):
            return np.zeros_like(codes)

    plan = PlanResult("x", PlanStatus.SOLVED, (3,), ((5,), (7,)), None, 0.1)
    assert not network_agrees(Const(), plan)


def test_examples_run_end_to_end(run, tmp_path):
    env_run, probs = str(run / "run"), run / "problems"
    problem = sorted(probs.glob("*.json"))[0]
    cmds = [
        [sys.executable, "examples/generate_domain.py", "--run", env_run, "--data", str(run / "data"),
         "--out", str(tmp_path / "pddl"), "--pddl-fidelity-cases", "20"],
        [sys.executable, "examples/call_planners.py", "--run", env_run, "--problem", str(problem), "--timeout", "20"],
        [sys.executable, "examples/compare_planners.py", "--run", env_run, "--problems", str(probs),
         "--out", str(tmp_path / "cmp"), "--planners", "astar,fast-downward,pyperplan", "--timeout", "20"],
    ]
    outs = []
    for cmd in cmds:
        r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, r.stderr[-1500:]
        outs.append(r.stdout)
    assert "(define (domain" in outs[0]
    assert "fast-downward" in outs[1] and "astar" in outs[1]
    bench = json.loads((tmp_path / "cmp" / "benchmark.json").read_text())
    assert set(bench["summary"]) == {"astar", "fast-downward", "pyperplan"}
    assert (tmp_path / "cmp" / "comparison.png").stat().st_size > 0
