"""The lever benches: the run summary (bench/levers_summary.py) and the symbol purity (bench/symbol_purity.py)."""
import importlib.util
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

BENCH = Path(__file__).resolve().parent.parent / "bench"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, BENCH / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_majority_share_counts_the_most_common_value_per_key():
    sp = _load("symbol_purity")
    keys, values = np.array([1, 1, 1, 2, 2]), np.array([7, 7, 8, 9, 9])
    assert sp.majority_share(keys, values) == pytest.approx(4 / 5)  # key 1: 2 of 3 agree; key 2: both
    assert sp.majority_share(values, keys) == 1.0  # each value has one key


def test_symbol_purity_on_a_trained_run(tiny_run):
    sp = _load("symbol_purity")
    r = sp.purity(tiny_run.path, tiny_run.data, n_shift=8)
    assert r["objects"] > 0 and 1 <= r["distinct_codes"] <= r["objects"]
    for k in ("type_purity", "location_purity", "level_purity", "arrangement_purity", "arrangement_determinism"):
        assert 0 < r[k] <= 1, k
    # a property refining another cannot be purer: (type, location, level) is at most as pure as type alone
    assert r["arrangement_purity"] <= r["type_purity"] + 1e-9
    assert set(r["codes_changed_by_pixel_shift"]) == {f"{a},{b}" for a, b in sp.SHIFTS}


def test_levers_summary_reads_runs_and_refuses_an_empty_folder(tiny_run, tmp_path, capsys):
    ls = _load("levers_summary")
    runs = tmp_path / "runs"
    shutil.copytree(tiny_run.path, runs / "quick_s0", ignore=shutil.ignore_patterns("*.pt", "pddl"))
    out = tmp_path / "sum.json"
    assert ls.main([str(runs), "--out", str(out)]) == 0
    d = json.loads(out.read_text())
    row = d["runs"][0]
    assert row["run"] == "quick_s0" and row["preset"] == "quick" and row["epochs_done"] == row["epochs"] == 1
    want = json.loads((tiny_run.path / "transition_metrics.json").read_text())["test"]["rollout"]["1"]["scene_accuracy"]
    assert row["rollout_scene_accuracy"]["1"] == want
    assert d["over_seeds"]["quick"]["runs"] == ["quick_s0"]
    assert "| quick_s0 | 1/1 |" in out.with_suffix(".md").read_text()
    (tmp_path / "empty").mkdir()
    assert ls.main([str(tmp_path / "empty"), "--out", str(tmp_path / "x.json")]) == 2
    assert "no run folders" in capsys.readouterr().err


def test_calibration_of_perfect_and_of_uninformative_probabilities():
    tc = _load("transition_calibration")
    right = np.array([True] * 6 + [False] * 4)
    # right predictions said to be certain, wrong ones impossible: separated and calibrated
    sure = tc.calibration(np.where(right, 1.0, 0.0), right)
    assert sure["auc"] == 1.0 and sure["expected_calibration_error"] == 0.0
    assert sure["accuracy_most_probable_half"] == 1.0 and sure["accuracy_least_probable_half"] == 0.2
    # one probability for all: no ranking (AUC 0.5), off by |0.9 - 0.6| on average
    flat = tc.calibration(np.full(10, 0.9), right)
    assert flat["auc"] == 0.5 and flat["expected_calibration_error"] == pytest.approx(0.3)
    assert flat["reliability"] == [{"p": [0.9, 1.0], "n": 10, "mean_p": 0.9, "accuracy": 0.6}]
    assert tc.calibration(np.full(3, 0.5), np.ones(3, bool))["auc"] is None  # one class: no AUC


def test_rollout_scores_on_a_trained_run(tiny_run):
    from symlearn.data.dataset import load_split
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE, load_transition
    from symlearn.symbolic.transition_data import build_transition_data
    from symlearn.symbolic.transition_metrics import rollout_accuracy

    tc = _load("transition_calibration")
    encoder, _ = load_effect_model(tiny_run.path)
    net, _ = load_transition(tiny_run.path / TRANSITION_FILE)
    data = build_transition_data(encoder, load_split(tiny_run.data, "test"), 64)
    for n in (1, 2):
        p, right = tc.rollout_scores(net, data, n)
        assert p.shape == right.shape and len(p) > 0 and ((p > 0) & (p <= 1)).all()
        # the same rollouts as the rollout accuracy m(z) reports
        assert right.mean() == pytest.approx(rollout_accuracy(net, data, n)["scene_accuracy"], abs=1e-5)


def test_goal_placement_split_by_objects_and_placement():
    gp = _load("goal_placement")
    def row(p, k, loop, ok, cause=None):  # a benchmark JSON row, as bench.benchmark writes them
        return {"problem": p, "planner": "astar", "found": True, "status": "solved", "plan_length": 1,
                "planning_time_s": 0.01, "expansions": 1, "success": ok, "symbolic_match": ok,
                "max_distance_m": 0.0, "closed_loop": loop, "replans": 0,
                "failure_stage": None if ok else "execution", "generator_length": 1, "n_objects": k,
                "failure_cause": cause}

    rows = [row("a", 2, False, True), row("a", 2, True, True),
            row("b", 3, False, False, "departure"), row("b", 3, True, False, "symbol_aliasing"),
            row("c", 5, False, False, "timeout"), row("c", 5, True, True)]
    out = gp.split(rows, {"a": 0, "b": 1, "c": 0})["astar"]
    assert out["1-3 objects"]["on_locations"] == {"n_problems": 1, "success_rate": 1.0,
                                                  "success_rate_closed_loop": 1.0, "closed_loop_failure_causes": {}}
    assert out["1-3 objects"]["off_locations"]["closed_loop_failure_causes"] == {"symbol_aliasing": 1}
    assert out["4-5 objects"]["on_locations"]["success_rate"] == 0.0
    assert out["4-5 objects"]["off_locations"]["n_problems"] == 0


class _Coin:
    """One object, 2 bits: action 0 sets the low bit with P 0.3 (the likeliest outcome keeps it clear),
    action 1 surely sets the high bit; nothing else changes."""

    bits = 2

    def bit_probabilities(self, codes, actions):
        out = ((np.asarray(codes)[..., None] >> np.array([1, 0])) & 1).astype(float)
        out[np.asarray(actions) == 0, 0, 1] = np.where(out[np.asarray(actions) == 0, 0, 1] == 1, 1.0, 0.3)
        out[np.asarray(actions) == 1, 0, 0] = 1.0
        return out

    def __call__(self, codes, actions):
        return ((self.bit_probabilities(codes, actions) >= 0.5) * np.array([2, 1])).sum(-1)


def test_outcome_reach_tells_the_likeliest_chain_from_the_likely_outcomes():
    orr = _load("outcome_reach")
    # the goal 3 needs the unlikely low bit: not on the likeliest chain, second in the beam (P 0.3 < 0.7)
    assert orr.reach(_Coin(), (0,), (0, 1), {0: 3}, beam=4, max_outcomes=4, min_ratio=0.05) == (False, 1)
    assert orr.reach(_Coin(), (0,), (0, 1), {0: 2}, beam=4, max_outcomes=4, min_ratio=0.05) == (True, 0)
    # outcomes below the ratio, or a beam of one chain, leave only the likeliest
    assert orr.reach(_Coin(), (0,), (0, 1), {0: 3}, beam=4, max_outcomes=4, min_ratio=0.5) == (False, None)
    assert orr.reach(_Coin(), (0,), (0, 1), {0: 3}, beam=1, max_outcomes=4, min_ratio=0.05) == (False, None)


def test_transition_volume_counts_rollouts_per_object_count():
    """A copying m(z) on two episodes: 2 objects that never change, 4 objects of which one changes at step 1."""
    import torch

    from symlearn.symbolic.transition_data import TransitionData
    from symlearn.symbolic.transition_model import TransitionConfig, TransitionNet

    tv = _load("transition_volume")
    cfg = TransitionConfig.from_preset("quick", code_bits=8, copy_prior=3.0)
    net = TransitionNet(cfg).eval()
    torch.nn.init.zeros_(net.post[-1].weight)
    torch.nn.init.zeros_(net.post[-1].bias)
    rng = np.random.default_rng(0)
    a = (rng.random((4, 8)) < 0.5).astype(np.float32)
    b = a.copy()
    b[2] = 1 - b[2]  # the third object's code changes at step 1 of the second episode
    c2 = (rng.random((4, 8)) < 0.5).astype(np.float32)
    c2[2:] = 0
    states = [c2, c2, c2, c2, a, a, b, b]  # episode 0: s0..s3; episode 1: s0..s3
    before = np.stack([states[0], states[1], states[2], states[4], states[5], states[6]])
    after = np.stack([states[1], states[2], states[3], states[5], states[6], states[7]])
    mask = np.zeros((6, 4), bool)
    mask[:3, :2] = True
    mask[3:] = True
    data = TransitionData(before=before, action=np.zeros(6, np.int64), after=after, mask=mask,
                          episode=np.array([0, 0, 0, 1, 1, 1], np.int32), step=np.array([0, 1, 2, 0, 1, 2]))
    one, two, three = (tv.rollout_by_objects(net, data, n) for n in (1, 2, 3))
    assert one["2"] == {"n": 3, "scene_accuracy": 1.0} and one["4"] == {"n": 3, "scene_accuracy": round(2 / 3, 4)}
    assert one["all"] == {"n": 6, "scene_accuracy": round(5 / 6, 4)}
    assert two["2"]["scene_accuracy"] == 1.0 and two["4"] == {"n": 2, "scene_accuracy": 0.0}
    assert three["all"] == {"n": 2, "scene_accuracy": 0.5}


def test_aliasing_misses_bins_each_aliased_goal_and_names_where_its_objects_stand(tmp_path):
    am = _load("aliasing_misses")
    def row(p, loop, ok, cause=None, miss=0.0):
        return {"problem": p, "planner": "astar", "closed_loop": loop, "success": ok, "failure_cause": cause,
                "max_distance_m": miss, "n_objects": 2, "goal_off_locations": 1}

    def problem(stick_xy):
        objects = [{"type": "cube", "position": [0.5, 0.3, 0.45]}, {"type": "stick", "position": [*stick_xy, 0.425]}]
        return {"goal": {"objects": objects}}

    (tmp_path / "walks").mkdir()
    (tmp_path / "walks" / "a.json").write_text(json.dumps(problem([0.5, -0.12])))  # 12 cm off location 4 toward -y
    (tmp_path / "walks" / "b.json").write_text(json.dumps(problem([0.8, 0.2])))  # 2 cm off location 2: on it
    bench = {"planners": ["astar"], "rows": [
        row("walks/a", True, False, "symbol_aliasing", 0.021), row("walks/a", False, False, "symbol_aliasing", 0.021),
        row("walks/b", True, False, "symbol_aliasing", 0.044), row("walks/c", True, False, "departure", 0.3),
        row("walks/d", True, True)]}
    out = am.summarize(bench, tmp_path)["astar"]
    assert (out["n_problems"], out["n_failures"], out["n_aliasing"]) == (4, 3, 2)  # the open-loop row is not counted
    assert out["aliasing_share"] == pytest.approx(2 / 3, abs=1e-4)
    assert out["misses_by_bin"] == {"up to 2.5 cm": 1, "2.5-5 cm": 1, "over 5 cm": 0}
    a, b = out["rows"]
    assert [g["place"] for g in a["goal"]] == ["on", "-y mid"] and a["goal"][1]["nearest_location"] == 4
    assert a["goal"][1]["distance_m"] == pytest.approx(0.12, abs=1e-3)
    assert b["goal"][1] == {"type": "stick", "nearest_location": 2, "place": "on", "distance_m": pytest.approx(0.02, abs=1e-3)}


def test_the_baselines_of_the_speed_benches_answer_as_the_code_they_time():
    """bench/rule_successors_memo.py's dense comparison and bench/sas_body.py's brute-force cells are the
    baselines their speedups are measured against: they must give what the faster code gives."""
    import itertools

    from pddl_export.rule_successors import RuleSuccessors
    from pddl_export.sas_writer import satisfying_cells
    from tests.test_overrides import VOCAB, random_rules

    memo, body = _load("rule_successors_memo"), _load("sas_body")
    rules = random_rules(np.random.default_rng(1), n=25)
    succ = RuleSuccessors(rules)
    states = np.array(list(itertools.product(VOCAB, repeat=3)), np.int64)
    assert np.array_equal(memo.dense_successors(succ, states), succ(states))
    assert not np.array_equal(memo.dense_successors(succ, states), np.repeat(states[:, None], len(succ.actions), 1))
    for intervals, k in [(((0, 1), (1, 3)), 3), (((2, 9),), 2), ((), 2), (((0, 0),), 1)]:
        assert body.brute_force_cells(intervals, k) == satisfying_cells(intervals, k)


def test_the_rules_load_baseline_builds_and_checks_groups_as_ruleset_does():
    """bench/rules_load.py times RuleSet's group arrays and exclusivity check against the earlier per-entry
    arrays and every-pair comparison: on random rules both must give the same arrays, and the same verdicts on
    exclusive groups and on a group made to overlap."""
    from pddl_export.rules import _dense_group, _first_overlap
    from tests.test_overrides import random_rules

    load = _load("rules_load")
    rules = random_rules(np.random.default_rng(4), n=40)
    new = load.groups_step(rules, _dense_group, _first_overlap)
    base = load.groups_step(rules, load.baseline_dense_group, load.baseline_first_overlap)
    assert load.same_arrays(new[1], base[1]) and new[2] == base[2]
    assert any(len(rules.rules_for(*k)) > 1 for k in rules.dense_groups) and set(new[2]) == {None}
    _, lo, hi, _ = max(new[1].values(), key=lambda g: len(g[1]))
    hi = hi.copy()
    hi[:] = lo + 1  # each box a single count vector ...
    hi[1:] = hi[0]
    lo[1:] = lo[0]  # ... and all of them the same one
    assert _first_overlap(lo, hi) == load.baseline_first_overlap(lo, hi) == (0, 1)


def test_aliasing_offsets_say_which_axis_carries_the_miss():
    am = _load("aliasing_misses")
    final = np.float64([[0.508, 0.120, 0.50], [0.80, 0.18, 0.425], [0.5, 0.0, 0.45]])
    goal = np.float64([[0.528, 0.121, 0.50], [0.807, 0.139, 0.425], [0.1, 0.1, 0.45]])
    a, b, free = am.object_offsets(final, goal, [True, True, False])
    assert a == {"dx_cm": -2.0, "dy_cm": -0.1, "dz_cm": 0.0, "miss_cm": pytest.approx(2.0, abs=0.01), "axis": "x"}
    assert b["axis"] == "y" and b["dy_cm"] == pytest.approx(4.1) and b["miss_cm"] == pytest.approx(4.16, abs=0.01)
    assert free is None


def test_aliasing_replay_runs_the_problem_again_and_refuses_another_model(tiny_run_copy, tmp_path):
    """The replay plans and executes each problem again (closed loop, the benchmark's settings); its per-object
    misses must give the executor's own largest distance, and a benchmark of another transition model is refused."""
    from symlearn.planning.problem_generation import generate_problems
    from symlearn.provenance import sha256_file

    am = _load("aliasing_misses")
    root = tmp_path / "problems"
    paths = generate_problems(root / "walks", 2, objects=(2, 2), length=(1, 2), seed=3)
    names = [f"walks/{p.stem}" for p in paths]
    bench = {"timeout_s": 5.0, "max_replans": 1, "risk_weight": 1.0,
             "transition_sha256": sha256_file(tiny_run_copy / "transition.pt")[:16]}
    out = am.replay(tiny_run_copy, bench, "astar", names, root)
    assert set(out) == set(names)
    for name, r in out.items():
        assert isinstance(r["success"], bool) and len(r["objects"]) == 2
        if r["max_distance_m"] is not None:  # something was executed
            assert max(o["miss_cm"] for o in r["objects"]) == pytest.approx(100 * r["max_distance_m"], abs=0.02)
            assert r["success"] == (r["max_distance_m"] <= 0.02)
    with pytest.raises(SystemExit, match="is not the transition model the benchmark planned with"):
        am.replay(tiny_run_copy, {**bench, "transition_sha256": "0" * 16}, "astar", names, root)
