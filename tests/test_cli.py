"""Every `symlearn` command end to end on the session's tiny data set and run: what it prints and writes.

The commands run in this process through symlearn.cli.main.main (the fixtures in conftest.py built the
data set and the run with collect, train, train-transition and export-pddl); one test starts the real
`python -m symlearn.cli.main` in a subprocess to check the exit code and the one-line error it prints.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from conftest import TINY_TRANSITION_ARGS, cli, cli_json, recomputed_transition_accuracy, write_config

ROOT = Path(__file__).resolve().parents[1]
N_ACTIONS = 36
FAILURE_STAGES = {None, "no_plan", "timeout", "execution", "goal_mismatch", "rules_vs_net"}
PLAN_LINE = re.compile(r"^(?P<name>\S+) \[(?P<planner>[^\],]+)(?P<closed>, closed loop)?\]: found (?P<found>True|False) "
                       r"\((?P<status>\w+)\), length (?P<length>\S+) \(generator (?P<gen>\d+)\).*success (?P<success>True|False)"
                       r".*replans (?P<replans>\d+), failure (?P<failure>\S+)$", re.M)


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and math.isfinite(x)


def _plan(run: Path, problem: Path, planner: str, *extra) -> dict:
    """`symlearn plan`, its summary line parsed into a dict."""
    rc, out = cli("plan", "--run", run, "--problem", problem, "--planner", planner, "--timeout", "20", *extra)
    assert rc == 0, out
    m = PLAN_LINE.search(out)
    assert m, out
    d = m.groupdict()
    d["failure"] = None if d["failure"] == "None" else d["failure"]
    d["length"] = None if d["length"] == "None" else int(d["length"])
    return d


@pytest.fixture(scope="module")
def problems(tmp_path_factory) -> Path:
    """Three problems of 1-2 objects, 1-2 generator actions."""
    out = tmp_path_factory.mktemp("cli_problems") / "p"
    rc, text = cli("problems", "--kind", "walks", "--out", out, "--n", 3, "--objects", "1-2", "--length", "1-2",
                   "--seed", 0)
    assert rc == 0 and f"wrote 3 problems to {out}" in text
    return out


# ------------------------------------------------------------------------------- data and effect model


def test_collect_summary_counts_what_was_asked(tiny_data):
    from symlearn.data.dataset import load_split

    s = tiny_data.summary
    assert s["samples"] == sum(s["counts"].values()) == 48 and s["counts"] == {"train": 40, "val": 4, "test": 4}
    assert s["shards"] == 12 and s["dropped_samples"] == 0  # 48 samples in shards of 4
    d = load_split(tiny_data.path, "all")
    assert len(d.action) == 48 and s["objects"] == int(d.mask.sum())
    assert s["objects_per_sample"] == pytest.approx(s["objects"] / 48, abs=1e-3) and 1 <= s["objects_per_sample"] <= 3
    assert 0 < s["moved_fraction"] <= 1 and 0 < s["grasp_fraction"] <= 1
    want = np.abs(d.effect[d.mask]).mean(0) * 1000
    np.testing.assert_allclose([s["mean_abs_effect_mm"][a] for a in "xyz"], want, atol=0.06)
    assert 10 < s["mean_abs_effect_mm"]["x"] < 600 and d.action.min() >= 0 and d.action.max() < N_ACTIONS


def test_scenarios_json_effects_follow_the_actions():
    from symlearn.world import LOCATIONS

    rc, out = cli("scenarios", "--json", "p1_lone_move", "p4_empty_pick")
    assert rc == 0
    lone, empty = json.loads(out)
    assert (lone["name"], empty["name"]) == ("p1_lone_move", "p4_empty_pick")
    pick, release = lone["action"]
    want = (np.subtract(LOCATIONS[release], LOCATIONS[pick]) * 1000).tolist() + [0.0]
    np.testing.assert_allclose(lone["objects"][0]["effect_mm"], want, atol=10)  # the cube travels pick -> release
    assert all(max(map(abs, o["effect_mm"])) < 5 for o in empty["objects"])  # picking nothing moves nothing


def test_train_output_matches_run_files(tiny_run):
    t = tiny_run.train
    last = t["last_epoch"]
    assert last["epoch"] == 1 and last["lr"] == 0.001  # the quick preset's rate (no decay over a single epoch)
    assert t["best_val_loss"] == pytest.approx(last["val_loss"], abs=1e-5) and 0 < last["val_loss"] < 100
    assert _finite(last["train_loss"]) and all(0 < v < 2000 for v in last["val_mae_mm"].values())
    m = json.loads((tiny_run.path / "metrics.json").read_text())
    assert m["history"] == [last] and m["best_val_loss"] == t["best_val_loss"]


def test_train_bf16_path(tiny_data, tiny_run, tmp_path):
    """bf16 autocast (the default without bf16 = false): finite falling loss, float32 weights, a loadable checkpoint."""
    from symlearn.learning.checkpoint import load_checkpoint

    run = tmp_path / "bf16"
    (tmp_path / "b8.toml").write_text("[train]\nbatch_size = 8\n")
    out = cli_json("train", "--data", tiny_data.path, "--out", run, "--preset", "quick", "--epochs", 3,
                   "--config", tmp_path / "b8.toml", "--quiet")
    cfg = json.loads((run / "config.json").read_text())["train_config"]
    assert cfg["bf16"] is True
    hist = json.loads((run / "metrics.json").read_text())["history"]
    assert [h["epoch"] for h in hist] == [1, 2, 3] and out["last_epoch"] == hist[-1]
    assert all(_finite(h["train_loss"]) and _finite(h["val_loss"]) for h in hist)
    assert hist[-1]["train_loss"] < hist[0]["train_loss"]
    # epoch 1 runs at the same rate as the float32 tiny run: only the bf16 rounding makes it differ, a little
    fp32 = tiny_run.train["last_epoch"]["train_loss"]
    assert hist[0]["train_loss"] != fp32 and hist[0]["train_loss"] == pytest.approx(fp32, rel=0.1)
    ck = load_checkpoint(run / "last.pt")
    floats = [v for v in ck.model_state.values() if v.is_floating_point()]
    assert ck.epoch == 2 and floats and all(v.dtype == torch.float32 and torch.isfinite(v).all() for v in floats)
    rc, text = cli("evaluate", "--run", run, "--data", tiny_data.path)
    assert rc == 0 and "attentive" in text
    ev = json.loads((run / "eval.json").read_text())
    assert all(0 < v < 2000 for v in ev["effect_mae_mm"].values()) and ev["trained_on"] == ev["data_fingerprint"]


def test_other_code_length_runs_through_the_pipeline(tiny_data, tmp_path):
    """--bits 4: 4-bit codes from the encoder through m(z) to the exported rules (at most 16 symbols)."""
    from symlearn.export.rules_export import training_codes

    run = tmp_path / "b4"
    bits4 = write_config(tmp_path / "bits4.toml", {"train": {"model": {"bits": 4}}, "export": {"pddl_fidelity_cases": 20}})
    cli_json("train", "--data", tiny_data.path, "--out", run, "--preset", "quick", "--epochs", 1, "--config", bits4,
             "--quiet")
    assert json.loads((run / "config.json").read_text())["train_config"]["model"]["bits"] == 4
    pre, post = training_codes(run, tiny_data.path)
    assert pre.max() < 16 and post.max() < 16 and (pre >= 0).sum() > 0
    t = cli_json("train-transition", "--run", run, "--data", tiny_data.path, *TINY_TRANSITION_ARGS, "--quiet")
    want = recomputed_transition_accuracy(run, tiny_data.path)
    assert t["test"]["bit_accuracy"] == pytest.approx(want["bit_accuracy"], abs=1e-5)
    assert t["test"]["scene_accuracy"] == pytest.approx(want["scene_accuracy"], abs=1e-5)
    rc, _ = cli("export-pddl", "--run", run, "--data", tiny_data.path, "--rules", "--config", bits4)
    rules = json.loads((run / "pddl" / "rules.json").read_text())
    rep = json.loads((run / "pddl" / "report.json").read_text())
    assert rc == 0 and rules["bits"] == 4 and rep["fidelity"] == 1.0 and rep["pddl_fidelity"] == 1.0
    assert all(len(c) == 4 for c in rules["vocabulary"]) and set(rules["vocabulary"]) <= {
        format(c, "04b") for c in np.unique(np.concatenate([pre[pre >= 0], post[post >= 0]]))}


def test_evaluate_table1_symbols(tiny_data, tiny_run, tiny_run_copy):
    run = tiny_run_copy
    rc, text = cli("evaluate", "--run", run, "--data", tiny_data.path)
    assert rc == 0 and f"wrote {run / 'eval.json'}" in text
    ev = json.loads((run / "eval.json").read_text())
    assert ev["n_test_samples"] == tiny_data.summary["counts"]["test"]
    assert ev["trained_on"] == ev["data_fingerprint"] and set(ev["ablations"]) == {"mean_effect"}
    for line, row in (("attentive", ev), ("mean_effect", ev["ablations"]["mean_effect"])):
        printed = next(ln for ln in text.splitlines() if ln.startswith(line)).split()[1:4]
        np.testing.assert_allclose(list(map(float, printed)), [row["effect_mae_mm"][a] for a in "xyz"], atol=0.051)

    rc, text = cli("table1", "--run", run)
    t1 = json.loads((run / "table1.json").read_text())
    assert rc == 0 and len(t1["cases"]) == 3 and f"mean absolute error mm {t1['mean_abs_error_mm']}" in text
    assert all(len(o["truth_mm"]) == 3 and all(map(_finite, o["predicted_mm"]))
               for c in t1["cases"] for o in c["objects"])

    rc, text = cli("symbols", "--run", run, "--data", tiny_data.path, "--min-count", 1)
    sy = json.loads((run / "symbols.json").read_text())
    assert rc == 0 and text.startswith(f"{sy['n_objects']} training objects, {sy['n_distinct']} distinct symbols")
    assert sum(r["count"] for r in sy["symbols"]) == sy["n_objects"] and sy["n_distinct"] == len(sy["symbols"])
    # the exporter's vocabulary counts the same training objects' codes, before and after each action
    counts = tiny_run.export_report["vocabulary_counts"]
    assert sum(counts.values()) == 2 * sy["n_objects"]
    assert {r["code"] for r in sy["symbols"]} <= set(counts)
    rc, _ = cli("symbols", "--run", run, "--data", tiny_data.path, "--symbol", "0101")
    assert rc == 2  # not an 8-bit string: refused


# ------------------------------------------------------------------------------- transition model and export


def test_train_transition_output(tiny_run):
    """The printed test accuracies are m(z)'s on the test split, as recomputed from the data and transition.pt."""
    t = tiny_run.transition
    acc = t["test"]
    want = recomputed_transition_accuracy(tiny_run.path, tiny_run.data)
    m = json.loads((tiny_run.path / "transition_metrics.json").read_text())
    assert want["n"] == m["test"]["n"] == m["n_samples"]["test"] == 4  # the tiny data set's 4 test samples
    assert m["test"]["copy_baseline"]["scene_accuracy"] == pytest.approx(want["copy_scene_accuracy"], abs=1e-5)
    for k in ("bit_accuracy", "object_accuracy", "scene_accuracy"):
        assert acc[k] == pytest.approx(want[k], abs=1e-5), k  # the report rounds to 5 decimals
    assert acc["bit_accuracy"] >= acc["object_accuracy"]  # a right object has all its bits right
    assert list(t["rollout_scene_accuracy"]) == [str(n) for n in range(1, 9)]
    assert t["rollout_scene_accuracy"]["1"] == acc["scene_accuracy"]
    assert m["best_val_loss"] == t["best_val_loss"] and m["test"]["bit_accuracy"] == acc["bit_accuracy"]
    assert 0 < t["best_val_loss"] < 5 and len(m["history"]) == 3


def test_export_pddl_report(tiny_run):
    rep = tiny_run.export_report
    rules = json.loads((tiny_run.path / "pddl" / "rules.json").read_text())
    model_hash = hashlib.sha256((tiny_run.path / "transition.pt").read_bytes()).hexdigest()[:16]
    assert rep["model_hash"] == rules["model_hash"] == model_hash
    assert model_hash in (tiny_run.path / "pddl" / "domain.pddl").read_text()
    assert rep["fidelity"] == 1.0 and rep["pddl_fidelity"] == 1.0  # the rules are exact on every enumerated case
    assert rep["pddl_fidelity_cases"] == min(60, rep["n_enumerated_cases"])
    assert rep["n_enumerated_cases"] == N_ACTIONS * rep["n_enumerated_scenes"]
    assert rep["n_rules"] == len(rules["rules"]) <= rep["n_rules_before_generalization"]
    assert rep["vocabulary_size"] == len(rules["vocabulary"]) == len(rep["vocabulary_counts"]) >= 1
    assert rules["max_objects"] == 2 and rep["config"]["scenes"] == "observed"


def test_export_pddl_all_scenes(tiny_data, tiny_run, tmp_path):
    out = tmp_path / "all"
    config = write_config(tmp_path / "all.toml", {"export": {"scenes": "all", "pddl_fidelity_cases": 20}})
    rc, text = cli("export-pddl", "--run", tiny_run.path, "--data", tiny_data.path, "--out", out, "--rules", "--config",
                   config)
    assert rc == 0 and f"wrote {out / 'domain.pddl'}" in text
    rep = json.loads((out / "report.json").read_text())
    v = rep["vocabulary_size"]
    assert v == tiny_run.export_report["vocabulary_size"]
    assert rep["n_enumerated_scenes"] == v + v * (v + 1) // 2  # every multiset of 1 or 2 vocabulary codes
    assert rep["n_enumerated_cases"] == N_ACTIONS * rep["n_enumerated_scenes"]
    assert rep["n_enumerated_scenes"] >= tiny_run.export_report["n_enumerated_scenes"]
    assert rep["fidelity"] == 1.0 and rep["pddl_fidelity"] == 1.0 and rep["pddl_fidelity_cases"] == 20
    # settings left unset keep ExportConfig's defaults; the given ones are recorded
    from symlearn.export.rules_export import ExportConfig
    want = dataclasses.asdict(ExportConfig(scenes="all", max_objects=2, pddl_fidelity_cases=20))
    assert rep["config"] == want


# ------------------------------------------------------------------------------- problems, plan, benchmark


def test_problems_files(problems, tmp_path):
    files = sorted(problems.glob("*.json"))
    assert [f.name for f in files] == ["problem_0000.json", "problem_0001.json", "problem_0002.json"]
    for f in files:
        p = json.loads(f.read_text())
        assert p["name"] == f.stem and 1 <= len(p["spec"]) <= 2 and 1 <= len(p["actions"]) <= 2
        assert len(p["initial"]["objects"]) == len(p["goal"]["objects"]) == len(p["spec"])
        assert all(0 <= a < N_ACTIONS for a in p["actions"])
        moved = np.abs(np.array([o["position"] for o in p["goal"]["objects"]])
                       - np.array([o["position"] for o in p["initial"]["objects"]])).max()
        assert moved > 0.01  # every generator action changes something
    rc, _ = cli("problems", "--kind", "walks", "--out", tmp_path / "again", "--n", 3, "--objects", "1-2", "--length",
                "1-2", "--seed", 0)
    assert rc == 0 and all(f.read_bytes() == (tmp_path / "again" / f.name).read_bytes() for f in files)  # seeded


def test_plan_with_astar_and_a_pddl_planner(tiny_run_copy, problems, tmp_path):
    problem = problems / "problem_0000.json"
    gen = len(json.loads(problem.read_text())["actions"])
    row = _plan(tiny_run_copy, problem, "astar")
    assert row["planner"] == "astar" and int(row["gen"]) == gen and row["failure"] in FAILURE_STAGES
    assert (row["success"] == "True") == (row["failure"] is None)
    assert (row["found"] == "True") == (row["length"] is not None) == (row["failure"] not in ("no_plan", "timeout"))
    one_replan = write_config(tmp_path / "replan1.toml", {"execution": {"max_replans": 1}})
    row = _plan(tiny_run_copy, problem, "fast-downward", "--config", one_replan, "--record", tmp_path / "plan.gif")
    assert row["closed"] and int(row["replans"]) <= 1 and row["failure"] != "rules_vs_net"  # the rules are exact
    written = tmp_path / "plan_tasks"  # beside the recording, not in the run
    assert not (tiny_run_copy / "pddl" / "problems").exists()
    model_hash = json.loads((tiny_run_copy / "pddl" / "rules.json").read_text())["model_hash"]
    assert model_hash in (written / "problem.pddl").read_text()


def test_benchmark_rows_and_summary(tiny_run_copy, problems, tmp_path):
    out = tmp_path / "bench.json"
    one_replan = write_config(tmp_path / "replan1.toml", {"execution": {"max_replans": 1}})
    rc, text = cli("benchmark", "--run", tiny_run_copy, "--problems", problems, "--planners", "astar,rules-bfs",
                   "--config", one_replan, "--timeout", 10, "--out", out)
    assert rc == 0 and f"wrote {out}" in text
    b = json.loads(out.read_text())
    files = sorted(problems.glob("*.json"))
    assert b["n_problems"] == 3 and len(b["rows"]) == 3 * 2 * 2
    assert b["transition_sha256"] == json.loads((tiny_run_copy / "pddl" / "rules.json").read_text())["model_hash"]
    digest = hashlib.sha256(b"".join(hashlib.sha256(f.read_bytes()).hexdigest().encode() for f in files)).hexdigest()
    assert b["problems_sha256"] == digest[:16]
    for name in ("astar", "rules-bfs"):
        rows = [r for r in b["rows"] if r["planner"] == name and not r["closed_loop"]]
        s = b["summary"][name]
        assert s["n_problems"] == len(rows) == 3
        assert s["success_rate"] == pytest.approx(np.mean([r["success"] for r in rows]), abs=1e-4)
        assert s["found_rate"] == pytest.approx(np.mean([r["found"] for r in rows]), abs=1e-4)
        assert sum(s["failure_stages"].values()) == sum(not r["success"] for r in rows)
        assert name in text
    for r in b["rows"]:
        assert r["failure_stage"] in FAILURE_STAGES and r["failure_stage"] != "rules_vs_net"
        assert r["replans"] <= (1 if r["closed_loop"] else 0) and r["n_objects"] in (1, 2)
        assert (r["plan_length"] is None) == (not r["found"]) == (r["max_distance_m"] is None)


def _bit_flip_rules(rules_file: Path, problem: Path) -> None:
    """Rewrite rules.json with rules no network learned: each of 8 actions that pick at an empty location (so
    nothing moves) flips one bit of the object's code. A planner then reaches any goal code on paper."""
    from symlearn.world import LOCATIONS, action_id

    d = json.loads(rules_file.read_text())
    pos = np.array([o["position"][:2] for o in json.loads(problem.read_text())["initial"]["objects"]])
    free = [i for i, xy in enumerate(LOCATIONS) if np.min(np.abs(pos - xy).max(1)) > 0.25]
    actions = [action_id(p, r) for p in free for r in free][:8]
    bits = d["bits"]
    assert len(actions) == bits == 8
    code = lambda c: format(c, f"0{bits}b")  # noqa: E731
    rules = [{"action": a, "pick": a // 6, "release": a % 6, "from": code(c), "to": code(c ^ (1 << i)),
              "requires": [], "forbids": [], "at_least": [], "fewer_than": []}
             for i, a in enumerate(actions) for c in range(1 << bits)]
    d.update(vocabulary=[code(c) for c in range(1 << bits)], max_objects=1, rules=rules,
             n_rules_before_generalization=len(rules))
    rules_file.write_text(json.dumps(d))


def test_plan_from_tampered_rules_fails_at_rules_vs_net(tiny_run_copy, tmp_path):
    rc, _ = cli("problems", "--kind", "walks", "--out", tmp_path / "p", "--n", 2, "--objects", "1-1", "--length", "1-2",
                "--seed", 0)
    assert rc == 0
    stages = []
    for problem in sorted((tmp_path / "p").glob("*.json")):
        _bit_flip_rules(tiny_run_copy / "pddl" / "rules.json", problem)
        row = _plan(tiny_run_copy, problem, "rules-bfs")
        assert row["found"] == "True" and row["success"] == "False"
        # a plan of flips is executed, moves nothing and departs from the network's predictions: rules_vs_net;
        # an empty plan (start codes already the goal's) cannot disagree with the network
        assert row["failure"] == ("rules_vs_net" if row["length"] else "goal_mismatch"), row
        stages.append(row["failure"])
    assert "rules_vs_net" in stages


# ------------------------------------------------------------------------------- refusals


@pytest.mark.parametrize("args, message", [
    (["plan", "--run", "{run}", "--problem", "{problem}", "--planner", "nope"], "unknown planner 'nope'; known: "),
    (["export-pddl", "--run", "{run}", "--data", "{data}", "--rules", "--config", "{max9}"],
     "max_objects=9 must lie in 1..5"),
    (["export-pddl", "--run", "{run}", "--data", "{data}", "--rules", "--config", "{ratio0}"],
     "outcome_min_ratio=0.0 must lie in (0, 1]"),
    (["export-pddl", "--run", "{run}", "--data", "{data}", "--config", "{typo}"],
     "typo.toml: [lifted] has no setting 'min_cont'; settings: source, min_count, rider_min_count, pair_min_count, pool_min_count, pool_classes, pool_structure_min, end_min_count, end_case_min, min_gain, min_info"),
    (["plan", "--run", "{run}", "--problem", "{problem}", "--config", "{wrongtype}"],
     "wrongtype.toml: [execution] closed_loop must be a bool, not 'yes'"),
    (["train", "--data", "{data}", "--out", "{empty}/r", "--config", "{table}"],
     "table.toml: unknown table [planners]; tables: collect, train, transition, export, lifted, problems, execution, "
     "planner"),
    (["benchmark", "--run", "{empty}", "--problems", "{problems}", "--planners", "rules-outcomes", "--out", "{empty}/b.json"],
     "no exported rules at"),
    (["benchmark", "--run", "{empty}", "--problems", "{problems}", "--planners", "fast-downward", "--out", "{empty}/b.json"],
     "no exported rules at"),
])
def test_refusals_exit_2_with_one_line(args, message, tiny_data, tiny_run, problems, tmp_path, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    files = {"max9": "[export]\nmax_objects = 9\n", "ratio0": "[export]\noutcome_min_ratio = 0\n",
             "typo": "[lifted]\nmin_cont = 3\n", "wrongtype": "[execution]\nclosed_loop = 'yes'\n",
             "table": "[planners]\nname = 'astar'\n"}
    for name, text in files.items():
        (tmp_path / f"{name}.toml").write_text(text)
    fill = dict(run=tiny_run.path, data=tiny_data.path, problems=problems, problem=problems / "problem_0000.json",
                empty=empty, **{name: tmp_path / f"{name}.toml" for name in files})
    rc, out = cli(*[a.format(**fill) for a in args])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and out == ""
    assert err.startswith(f"symlearn {args[0]}: error: ") and message in err and "\n" not in err, err
    assert not (empty / "b.json").exists()


def test_cli_process_exit_codes(tmp_path):
    """The installed entry point: a bad range is an argparse error (exit 2), a bad scenario name a one-line error."""
    run = [sys.executable, "-m", "symlearn.cli.main"]
    r = subprocess.run(run + ["problems", "--out", str(tmp_path / "p"), "--objects", "3-1"], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "range '3-1' is empty" in r.stderr and not (tmp_path / "p").exists()
    r = subprocess.run(run + ["scenarios", "no_such_scenario"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0
    assert r.stderr.startswith("symlearn scenarios: error: unknown scenario 'no_such_scenario'; known: p1_lone_move")
    for cmd in ("export-pddl", "train-transition"):  # --threads: a positive count, refused before any work
        r = subprocess.run(run + [cmd, "--run", str(tmp_path / "r"), "--data", str(tmp_path / "d"), "--threads", "0"],
                           cwd=ROOT, capture_output=True, text=True, timeout=120)
        assert r.returncode == 2 and "argument --threads: '0' must be a positive integer" in r.stderr, r.stderr


def test_plan_and_benchmark_say_when_they_load_big_rule_files(tmp_path, capsys):
    from symlearn.cli.planning import note_rule_loading

    pddl = tmp_path / "run" / "pddl"
    pddl.mkdir(parents=True)
    for name, size in (("rules.json", 40_000_000), ("outcomes.json", 30_000_000)):
        with open(pddl / name, "wb") as f:
            f.truncate(size)  # sparse: the size is what is judged
    note_rule_loading(tmp_path / "run", ["astar", "astar-outcomes"])
    assert capsys.readouterr().err == ""  # no rule planner: nothing is read
    note_rule_loading(tmp_path / "run", ["rules-bfs"])
    assert capsys.readouterr().err == ""  # 40 MB: not worth a line
    note_rule_loading(tmp_path / "run", ["astar", "rules-outcomes"])
    err = capsys.readouterr().err
    assert err.startswith("loading ") and "rules.json and " in err and "outcomes.json (70 MB)" in err
    with pytest.raises(ValueError, match="rules-magic"):
        note_rule_loading(tmp_path / "run", ["rules-magic"])
