"""The planner registry as users meet it: at most 10 planners, each with its reason in `--help`, README's planner
table written from the registry, and the planners' own settings (risk_weight) in a `[planner]` table that the
registry builds planners from."""
import contextlib
import io
import re
from pathlib import Path

import numpy as np
import pytest

from conftest import cli
from test_search import Sticky  # one object, 2 bits: action 0 sets the low bit with P 0.3

ROOT = Path(__file__).resolve().parents[1]
RETIRED = ("astar-likely", "symk", "fast-downward-opt", "fast-downward-blind", "fast-downward-sas",
           "fast-downward-sas-opt", "symk-sas", "symk-sas-topk", "fast-downward-sas-ms", "fast-downward-sas-lama",
           "rules-astar")


def _help(command: str) -> str:
    from symlearn.cli.main import main
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as info:
        main([command, "--help"])
    assert info.value.code == 0
    return out.getvalue()


@pytest.mark.parametrize("command", ["plan", "benchmark"])
def test_help_lists_at_most_ten_planners_each_with_its_reason(command):
    from symlearn.planning.planner_catalogue import PLANNERS
    epilog = _help(command).split("planners, by family:")[1]
    # a planner's first line: four spaces, its name, its purpose; its reason follows on the wrapped lines
    blocks = re.split(r"\n    (?=\S)", "\n" + epilog)
    entries = {b.split()[0]: " ".join(b.split()) for b in blocks if b.strip()}
    listed = {name: text for name, text in entries.items() if name in PLANNERS}
    assert set(listed) == set(PLANNERS) and 5 <= len(listed) <= 10
    for name, text in listed.items():
        entry = PLANNERS[name]
        assert f"Why: {entry.reason}." in text, (name, text)
        assert f"Reads {', '.join(entry.needs)}." in text
    assert not set(RETIRED) & set(entries)


def test_the_readme_table_is_the_registry():
    from symlearn.planning.planner_catalogue import PLANNERS, planners_markdown
    readme = (ROOT / "README.md").read_text()
    assert planners_markdown() in readme
    rows = [line for line in readme.splitlines() if re.match(r"^\| `[a-z-]+` \|", line)]
    names = [re.match(r"^\| `([a-z-]+)` \|", line).group(1) for line in rows]
    assert names == list(PLANNERS)  # every planner once, no other row
    for row, name in zip(rows, names):
        cells = [c.strip() for c in row.strip("|").split("|")]
        entry = PLANNERS[name]
        assert cells[1:4] == [entry.family, entry.purpose, entry.reason], row
        assert all(f"`{need}`" in cells[4] for need in entry.needs)


def test_every_entry_says_what_it_needs_and_builds():
    from symlearn.planning.planner_catalogue import DEFAULT_PLANNER, FAMILIES, MADE_BY, PLANNERS
    from symlearn.planning.planners import PlannerContext
    assert DEFAULT_PLANNER in PLANNERS and {e.family for e in PLANNERS.values()} == {f for f, _ in FAMILIES}
    for name, entry in PLANNERS.items():
        assert entry.name == name and entry.purpose and entry.reason and entry.needs
        assert all(need in MADE_BY for need in entry.needs)
        assert callable(entry.builder())
        if entry.needs_rules or entry.needs_lifted:  # a context without those files is refused in one line
            with pytest.raises(ValueError, match=f"planner '{name}' plans on the .*export-pddl"):
                entry.builder()(PlannerContext())


@pytest.mark.parametrize("name", ["astar-likely", "fast-downward-sas", "symk-sas-topk", "rules-astar"])
def test_retired_planners_are_refused_by_name(name, tmp_path):
    from symlearn.planning.planners import make_planners
    with pytest.raises(ValueError, match=f"unknown planner '{name}'; known: astar-outcomes, astar, "):
        make_planners([name], tmp_path)


def test_the_planner_config_reaches_the_risk_planner(tmp_path):
    from pddl_export.symbolic import SymbolicGoal
    from symlearn.planning.planners import PlannerConfig, make_planners
    goal = SymbolicGoal((1,))
    for weight in (1.0, 2.5):
        plan = make_planners(["astar-outcomes"], tmp_path, config=PlannerConfig(risk_weight=weight))["astar-outcomes"]
        res = plan(Sticky(), np.array([0]), goal, 5.0)
        # only the unlikely outcome of action 0 reaches the goal: planned for, at the config's weight
        assert res.found and res.plan == (0,) and res.extra["risk_weight"] == weight
        assert res.extra["log_p"] == pytest.approx(np.log(0.3), abs=1e-5)


def test_the_planner_table_sets_risk_weight_and_execution_no_longer_has_it(tmp_path, capsys):
    from symlearn.cli.main import build_parser
    from symlearn.cli.planning import execution_config, planner_config
    from symlearn.planning.execution import ExecutionConfig
    from symlearn.planning.planner_catalogue import PlannerConfig
    config = tmp_path / "w.toml"
    config.write_text("[planner]\nrisk_weight = 2.5\n[execution]\ntimeout_s = 7\n")
    args = build_parser().parse_args(["plan", "--run", "r", "--problem", "p.json", "--config", str(config)])
    assert planner_config(args) == PlannerConfig(risk_weight=2.5)
    assert execution_config(args).timeout_s == 7 and "risk_weight" not in ExecutionConfig.__dataclass_fields__
    for text, message in (("[planner]\nrisk_weight = 0\n", "[planner] risk_weight: risk_weight=0.0 must be a finite number in (0, 1e+06]"),
                          ("[execution]\nrisk_weight = 2\n", "[execution] has no setting 'risk_weight'")):
        config.write_text(text)
        rc, out = cli("plan", "--run", tmp_path / "none", "--problem", tmp_path / "p.json", "--config", config)
        err = capsys.readouterr().err.strip()
        assert rc == 2 and out == "" and message in err and "\n" not in err and str(config) in err, err


def test_benchmark_records_the_planner_config_only_for_risk_planners():
    import dataclasses
    from symlearn.planning.benchmark_runner import _planner_config
    from symlearn.planning.planner_catalogue import RISK_PLANNERS, PlannerConfig
    assert set(RISK_PLANNERS) == {"astar-outcomes", "rules-outcomes"}
    settings = {"planners": ["astar-outcomes"], **dataclasses.asdict(PlannerConfig(risk_weight=3.0))}
    assert _planner_config(settings) == PlannerConfig(risk_weight=3.0)  # what a Ray task builds its planners with
    assert _planner_config({"planners": ["astar"]}) == PlannerConfig()


class _Reached(Exception):
    """Raised by an intercepted library call: the planner config reached it."""


@pytest.mark.parametrize("command, target, extra", [
    ("plan", "symlearn.planning.plan_one.plan_problem", ("--problem", "{tmp}/p.json")),
    ("benchmark", "symlearn.planning.benchmark.benchmark", ("--problems", "{tmp}/problems", "--out", "{tmp}/b.json")),
])
def test_the_planner_table_reaches_plan_and_benchmark(tmp_path, monkeypatch, command, target, extra):
    import importlib
    from symlearn.planning.planner_catalogue import PlannerConfig
    module, _, name = target.rpartition(".")
    got = []

    def intercepted(*args, **kwargs):
        got.append(kwargs["planner_config"])
        raise _Reached

    monkeypatch.setattr(importlib.import_module(module), name, intercepted)
    config = tmp_path / "w.toml"
    config.write_text("[planner]\nrisk_weight = 0.25\n")
    with pytest.raises(_Reached):
        cli(command, "--run", tmp_path / "run", *(a.format(tmp=tmp_path) for a in extra), "--config", config)
    assert got == [PlannerConfig(risk_weight=0.25)]


def test_a_ray_task_builds_its_planners_with_the_benchmarks_planner_config(tmp_path, monkeypatch):
    """_ray_pair, the body of a Ray task, reads the planner config from the settings it is sent (the resume key):
    no second copy travels beside the execution config."""
    import dataclasses
    import json

    import symlearn.planning.benchmark_runner as bench
    from symlearn.planning.execution import ExecutionConfig
    from symlearn.planning.planner_catalogue import PlannerConfig

    got = []

    def intercepted(names, run_dir, write_dir=None, config=PlannerConfig()):
        got.append(config)
        raise _Reached

    monkeypatch.setattr(bench, "make_planners", intercepted)
    settings = {"planners": ["astar-outcomes"], **dataclasses.asdict(PlannerConfig(risk_weight=4.0))}
    with pytest.raises(_Reached):
        bench._ray_pair(json.dumps(settings), str(tmp_path), ["astar-outcomes"], None, "astar-outcomes", [False],
                        ExecutionConfig(), None)
    bench._worker_state.clear()
    assert got == [PlannerConfig(risk_weight=4.0)]
