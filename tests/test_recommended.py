"""The recommended recipe as users meet it: the planners listed by family in `--help`, the recommended planner as
the default, and the shipped run of the recipe building goals in simulation with m(z) and with stock Fast
Downward on its lifted domain."""
import json
import shutil
from pathlib import Path

import pytest

from conftest import cli

RECOMMENDED = Path(__file__).resolve().parents[1] / "pretrained" / "recommended"


def test_the_families_cover_the_registry_exactly():
    from symlearn.planning.planner_catalogue import DEFAULT_PLANNER, by_family
    from symlearn.planning.planners import PLANNERS
    listed = [e.name for _, _, entries in by_family() for e in entries]
    assert listed == list(PLANNERS), "every planner in exactly one family, in the registry's order"
    assert DEFAULT_PLANNER == "astar-outcomes" and listed[0] == DEFAULT_PLANNER


@pytest.mark.parametrize("command", ["plan", "benchmark"])
def test_help_lists_every_planner_and_the_default(command):
    import contextlib
    import io
    from symlearn.cli.main import main
    from symlearn.planning.planners import PLANNERS
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as info:
        main([command, "--help"])
    assert info.value.code == 0
    text = out.getvalue()
    listed = {line.split()[0] for line in text.split("planners, by family:")[1].splitlines()
              if line.startswith("    ") and not line.startswith("     ")}
    assert listed == set(PLANNERS)
    assert "(default astar-outcomes)" in " ".join(text.split())


def test_the_default_planner_is_the_recommended_one():
    from symlearn.cli.main import build_parser
    p = build_parser()
    assert p.parse_args(["plan", "--run", "r", "--problem", "f.json"]).planner == "astar-outcomes"
    assert p.parse_args(["benchmark", "--run", "r", "--problems", "d", "--out", "o"]).planners == ["astar-outcomes"]


def test_the_recommended_run_is_small_and_consistent():
    from pddl_export.files import sha256_file
    from pddl_export.lifted_domain import domain_pddl
    from pddl_export.lifted_rules_io import load_lifted
    from symlearn.symbolic.learned_transition import LearnedTransition
    size = sum(p.stat().st_size for p in RECOMMENDED.rglob("*") if p.is_file())
    assert size <= 10e6, size
    transition = LearnedTransition.from_run(RECOMMENDED)  # refuses an m(z) of another effect model
    assert transition.bits == 17  # 8 learned bits + 9 location bits
    lifted = load_lifted(RECOMMENDED / "pddl" / "lifted.json")
    assert lifted.model_hash == sha256_file(RECOMMENDED / "transition.pt")[:16]  # the export is not stale
    domain = (RECOMMENDED / "pddl" / "lifted" / "domain.pddl").read_text()
    assert f"(define (domain symlearn-{lifted.model_hash})" in domain and len(domain) <= 100_000  # issue 33's size
    assert domain == domain_pddl(lifted)  # the shipped file is what the writer makes of the shipped rules
    ev = json.loads((RECOMMENDED / "eval.json").read_text())
    assert ev["effect_model_sha256"] == sha256_file(RECOMMENDED / "best.pt")[:16]
    assert all(ev["effect_mae_mm"][a] < lim for a, lim in zip("xyz", (8.6, 15, 6)))  # the paper's errors


def test_the_recommended_run_builds_its_goals_in_simulation(tmp_path):
    """A 4-object goal whose shortest plan is 5 actions, by astar-outcomes closed loop, and a tower of two by stock
    Fast Downward on the lifted domain: read from the benchmark's JSON rows, not from printed text."""
    run = RECOMMENDED  # planning only reads the run: the shipped folder as it is
    problems = tmp_path / "problems"
    problems.mkdir()
    for name in ("four_objects_five_actions", "tower_of_two"):
        shutil.copy(RECOMMENDED / "problems" / f"{name}.json", problems)
    out = tmp_path / "bench.json"
    rc, text = cli("benchmark", "--run", run, "--problems", problems, "--planners",
                   "astar-outcomes,fast-downward-lifted", "--timeout", "60", "--out", out)
    assert rc == 0, text
    rows = {(r["problem"], r["planner"], r["closed_loop"]): r for r in json.loads(out.read_text())["rows"]}
    deep = rows[("k4_opt5-6_0000", "astar-outcomes", True)]
    assert deep["success"] and deep["optimal_length"] == 5 and deep["executed_length"] == 5, deep
    assert deep["max_distance_m"] < 0.02
    tower = rows[("tower_of_two", "fast-downward-lifted", True)]
    assert tower["success"] and tower["plan_length"] == tower["optimal_length"] == 2, tower


def test_pddlgym_parses_the_shipped_domain():
    """pddlgym's own parser reads the shipped lifted domain, every action schema of it, including the far-row stick
    moves whose layer parameter stands for a neighbour's top (a hyphen in a parameter's name broke its parser)."""
    import warnings
    with warnings.catch_warnings():  # gym 0.26 warns on import that it is unmaintained
        warnings.simplefilter("ignore")
        from pddlgym.parser import PDDLDomainParser
    path = RECOMMENDED / "pddl" / "lifted" / "domain.pddl"
    text = path.read_text()
    assert "?top_l" in text  # the case that broke it is in the file
    parsed = PDDLDomainParser(str(path), expect_action_preds=False, operators_as_actions=True)
    assert len(parsed.operators) == text.count("(:action ")
    assert {"at", "level", "stands", "height", "rests"} <= {str(p) for p in parsed.predicates}
