"""export-pddl on a real (tiny) run, PDDL planners in the benchmark registry, and the examples."""
import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import cli
from pddl_export.pddl_writer import action_name, code_from_predicate, conditional_domain, object_name, problem_pddl
from pddl_export.rules_io import load_rules, rules_from_json, rules_to_json
from pddl_export.symbolic import N_ACTIONS
from search.result import PlanResult, PlanStatus
from symlearn.export.rules_export import ExportConfig, export_pddl
from symlearn.planning.planners import make_pddl_planner, network_agrees
from symlearn.symbolic.learned_transition import LearnedTransition

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def run(tmp_path_factory, tiny_data, tiny_run):
    """ROOT/data: the session's tiny data set; ROOT/run: a copy of the tiny run; ROOT/problems: two problems."""
    root = tmp_path_factory.mktemp("pddl_pipeline")
    (root / "data").symlink_to(tiny_data.path, target_is_directory=True)
    shutil.copytree(tiny_run.path, root / "run")
    rc, _ = cli("problems", "--kind", "walks", "--out", root / "problems", "--n", 2, "--objects", "1-2", "--length",
                "1-2", "--seed", 0)
    assert rc == 0
    return root


def _parse_domain(text: str):
    """The domain as read by the independent `pddl` package (its parser leaves sys.tracebacklimit at 0 on errors)."""
    from pddl.parser.domain import DomainParser

    old = getattr(sys, "tracebacklimit", None)
    try:
        return DomainParser()(text)
    finally:
        if old is None and hasattr(sys, "tracebacklimit"):
            del sys.tracebacklimit


def _check_domain(text: str, rules) -> None:
    """The domain declares one action per real action with rules, named by it, and one predicate per code."""
    d = _parse_domain(text)
    names = sorted(str(a.name) for a in d.actions)
    assert names == sorted(action_name(a) for a in rules.actions) and len(names) <= N_ACTIONS
    assert sorted(code_from_predicate(str(p.name)) for p in d.predicates) == list(rules.codes)


def test_export_writes_domain_rules_and_exact_report(run):
    rep = export_pddl(run / "run", run / "data", ExportConfig(max_objects=2, pddl_fidelity_cases=60))
    out = run / "run" / "pddl"
    assert rep["fidelity"] == 1.0 and rep["pddl_fidelity"] == 1.0 and rep["pddl_fidelity_cases"] >= 1
    assert rep["n_rules"] <= rep["n_rules_before_generalization"]
    assert json.loads((out / "report.json").read_text()) == json.loads(json.dumps(rep))
    rules, model_hash = load_rules(run / "run")
    assert rules.n_rules == rep["n_rules"] and len(rules.vocabulary) == rep["vocabulary_size"] >= 1
    assert rules_to_json(rules_from_json(rules_to_json(rules))) == rules_to_json(rules) and len(model_hash) == 16
    domain = (out / "domain.pddl").read_text()
    assert f";; model-hash: {model_hash}" in domain.splitlines()
    _check_domain(domain, rules)


def test_observed_scenes_take_sub_scenes_of_larger_scenes_on_request():
    from symlearn.export.rules_export import observed_scenes

    codes = np.array([[1, 2, 3, 4], [1, 1, -1, -1], [1, 4, -1, -1]])  # 4 lies outside the vocabulary
    assert observed_scenes({1, 2, 3}, 2, codes) == [(1,), (1, 1)]
    assert observed_scenes({1, 2, 3}, 2, codes, larger=True) == [(1,), (1, 1), (1, 2), (1, 3), (2,), (2, 3), (3,)]


def test_export_with_extra_data_and_larger_scenes(run, tiny_k45, tmp_path):
    from symlearn.data.dataset import data_fingerprint
    from symlearn.export.rules_export import code_counts, observed_scenes, training_codes

    cfg = ExportConfig(max_objects=2, pddl_fidelity_cases=0, larger_scenes=True)
    rep = export_pddl(run / "run", run / "data", cfg, tmp_path / "pddl", extra_data=(tiny_k45,))
    assert rep["extra_data"] == [{"data": str(tiny_k45), "data_fingerprint": data_fingerprint(tiny_k45)}]
    assert rep["config"]["larger_scenes"] is True and rep["fidelity"] == 1.0
    arrays = [*training_codes(run / "run", run / "data"), *training_codes(run / "run", tiny_k45)]
    assert max((a >= 0).sum(1).max() for a in arrays) == 5
    assert rep["vocabulary_size"] == len(code_counts(*arrays))
    vocab = set(code_counts(*arrays))
    with_larger = observed_scenes(vocab, 2, *arrays, larger=True)
    assert rep["n_enumerated_scenes"] == len(with_larger) > len(observed_scenes(vocab, 2, *arrays))
    rules = rules_from_json(json.loads((tmp_path / "pddl" / "rules.json").read_text()))
    assert rules.max_objects == 2 and set(rules.vocabulary) == vocab
    with pytest.raises(ValueError, match="must differ"):
        export_pddl(run / "run", run / "data", cfg, tmp_path / "again", extra_data=(run / "data",))
    assert not (tmp_path / "again").exists()
    with pytest.raises(ValueError, match="needs scenes='observed'"):
        ExportConfig(scenes="all", larger_scenes=True)


def test_malformed_rules_refused(tmp_path):
    with pytest.raises(ValueError, match="malformed rules file"):
        rules_from_json({"bits": 8, "rules": [{"action": 1}]})
    with pytest.raises(ValueError, match="no exported rules"):
        load_rules(tmp_path)


def _one_step_task(run: Path, rules) -> tuple[np.ndarray, int, np.ndarray]:
    """A start scene the export enumerated, an action and the successor the rules give it, which differs from it.

    Every rule was distilled from a changing case of an enumerated (observed) scene, so some such scene and
    action exist whenever the export wrote a rule; the scene with the most objects is taken first, so the
    planners meet other objects (the rules' contexts) too. The successor is one action away: a goal made of it
    is provably reachable, and every planner must return a plan.
    """
    from pddl_export.rules import apply_rules
    from symlearn.export.rules_export import observed_scenes, training_codes

    assert rules.n_rules >= 1, "the tiny run exported no rule: nothing to plan on"
    scenes = observed_scenes(set(rules.vocabulary), rules.max_objects, *training_codes(run / "run", run / "data"))
    report = json.loads((run / "run" / "pddl" / "report.json").read_text())
    assert len(scenes) == report["n_enumerated_scenes"]  # the very scenes the rules are exact on
    for scene in sorted(scenes, key=lambda s: (-len(s), s)):
        start = np.array(scene, np.int64)
        for action in rules.actions:
            nxt = apply_rules(rules, start, action)
            if (nxt != start).any():
                return start, int(action), nxt
    raise AssertionError("no rule fires on any enumerated scene, though every rule came from one")


# planner -> whether it returns shortest plans (the goal is one action away: then exactly one action)
PDDL_PLANNERS = {"fast-downward": False, "pyperplan": False}


def test_pddl_planner_plans_on_exported_rules_and_agrees_with_net(run):
    """Fast Downward and pyperplan (through unified-planning) plan to a goal one rule step from an enumerated scene.

    Each plan reaches the goal under the rules, its predicted states are the network's (the rules are exact on
    the enumerated scenes), and unified-planning's validator finds it valid on the conditional PDDL problem,
    while it refuses the empty plan (the start is not the goal).
    """
    from pddl_export.rules import apply_rules
    from pddl_export.symbolic import SymbolicGoal

    rules, model_hash = load_rules(run / "run")
    tr = LearnedTransition.from_run(run / "run")
    start, action, successor = _one_step_task(run, rules)
    assert tr(start[None], np.array([action]))[0].tolist() == successor.tolist()  # rules == network here
    goal = SymbolicGoal(tuple(int(c) for c in successor))
    assert _validate(rules, model_hash, start.tolist(), goal, ()) == "INVALID"
    assert _validate(rules, model_hash, start.tolist(), goal, (action,)) == "VALID"
    for name, shortest in PDDL_PLANNERS.items():
        res = make_pddl_planner(rules, model_hash, name)(tr, start, goal, 30.0)
        assert res.status is PlanStatus.SOLVED, (name, res.message)
        assert (len(res.plan) == 1) if shortest else (len(res.plan) >= 1), (name, res.plan)
        assert "pddl_write_time_s" in res.extra and res.extra["rules_vs_net"] is False
        state = start
        for a in res.plan:
            state = apply_rules(rules, state, a)
        assert state.tolist() == successor.tolist(), name  # the plan reaches the goal under the rules
        assert res.predicted_states[0] == tuple(start.tolist()) and res.predicted_states[-1] == goal.codes
        assert network_agrees(tr, res), name
        assert _validate(rules, model_hash, start.tolist(), goal, res.plan) == "VALID", name


def _validate(rules, model_hash: str, init: list[int], goal, plan: tuple[int, ...]) -> str:
    """unified-planning's verdict (VALID / INVALID) on the plan in the conditional PDDL problem, whose objects
    must be the scene's."""
    from unified_planning.io import PDDLReader
    from unified_planning.plans import ActionInstance, SequentialPlan
    from unified_planning.shortcuts import PlanValidator

    problem = PDDLReader().parse_problem_string(conditional_domain(rules, model_hash),
                                                problem_pddl(rules, init, goal, model_hash))
    assert sorted(o.name for o in problem.all_objects if o.type.name == "obj") == [object_name(i) for i in range(len(init))]
    up_plan = SequentialPlan([ActionInstance(problem.action(action_name(a))) for a in plan])
    with PlanValidator(problem_kind=problem.kind, plan_kind=up_plan.kind) as validator:
        return validator.validate(problem, up_plan).status.name


def test_network_disagreement_detected():
    class Const:
        bits = 8

        def __call__(self, codes, actions):
            return np.zeros_like(codes)

    plan = PlanResult("x", PlanStatus.SOLVED, (3,), ((5,), (7,)), None, 0.1)
    assert not network_agrees(Const(), plan)


def test_export_writes_second_outcomes_and_rules_outcomes_plans_on_them(run):
    """outcomes.json reproduces the network's second outcomes; the planner reaches a state only they lead to."""
    from pddl_export.enumeration import enumerate_scenes
    from pddl_export.fidelity import rule_fidelity
    from pddl_export.outcome_rules import SecondOutcome, load_outcomes
    from pddl_export.rules import apply_rules
    from pddl_export.symbolic import SymbolicGoal
    from symlearn.planning.planners import OUTCOME_RULES_PLANNER, PlannerContext, make_planner

    rep = export_pddl(run / "run", run / "data", ExportConfig(max_objects=2, pddl_fidelity_cases=0))
    outcomes, outcomes_hash = load_outcomes(run / "run")
    rules, model_hash = load_rules(run / "run")
    assert outcomes_hash == model_hash and rep["outcomes"]["fidelity"] == 1.0
    assert rep["outcomes"]["n_rules"] == outcomes.rules.n_rules and rep["outcomes"]["min_ratio"] == 0.05
    tr = LearnedTransition.from_run(run / "run")
    second = SecondOutcome(tr, 0.05)
    from symlearn.export.rules_export import observed_scenes, training_codes

    scenes = [s for s in observed_scenes(set(rules.vocabulary), 2, *training_codes(run / "run", run / "data"))
              if len(s) == 1]
    enum = enumerate_scenes(second, rules.vocabulary, scenes, 1)
    assert rule_fidelity(outcomes.rules, enum).fraction == 1.0  # exact on the one-object scenes it was distilled on
    main, alt, extra = second.outcomes(enum.blocks[0].states, enum.blocks[0].actions)
    rows = np.flatnonzero((alt != main)[:, 0] & (alt[:, 0] != enum.blocks[0].states[:, 0]))
    assert len(rows) and rep["outcomes"]["n_alternatives"] == len(outcomes.costs) >= 1
    start, action = enum.blocks[0].states[rows[0]], int(enum.blocks[0].actions[rows[0]])
    goal = SymbolicGoal((int(alt[rows[0], 0]),))
    context = PlannerContext.for_run(run / "run", [OUTCOME_RULES_PLANNER])
    res = make_planner(OUTCOME_RULES_PLANNER, context)(tr, start, goal, 10.0)
    assert res.found and res.predicted_states[-1] == goal.codes, res.message
    for s, a, t in zip(res.predicted_states, res.plan, res.predicted_states[1:]):  # each step: the rules' or a second outcome
        likeliest = tuple(apply_rules(rules, np.array(s), a).tolist())
        assert t == likeliest or tuple(apply_rules(outcomes.rules, np.array(s), a).tolist()) == t
    assert res.extra["cost"] >= len(res.plan) and (res.plan != (action,) or res.extra["cost"] > 1)
    path = run / "run" / "pddl" / "outcomes.json"
    stale = dict(json.loads(path.read_text()), model_hash="0" * 16)
    path.write_text(json.dumps(stale))
    with pytest.raises(ValueError, match="rules.json and outcomes.json of different transition models"):
        PlannerContext.for_run(run / "run", [OUTCOME_RULES_PLANNER])
    path.unlink()
    with pytest.raises(ValueError, match="no exported outcome rules"):
        PlannerContext.for_run(run / "run", ["rules-bfs", OUTCOME_RULES_PLANNER])
    assert PlannerContext.for_run(run / "run", ["rules-bfs"]).outcomes is None
