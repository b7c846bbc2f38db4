"""bench/ holds speed benchmarks on public names only; experiments/ the studies that chose settings. Here: the
baselines of the speed benches, the symbol purity analysis (experiments/symbol_purity.py) and the held-out check."""
import ast
import importlib.util
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
BENCH, EXPERIMENTS = ROOT / "bench", ROOT / "experiments"


def _load(name, folder=BENCH):
    spec = importlib.util.spec_from_file_location(name, folder / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def import_problems(script: Path) -> list[str]:
    """What in a script's imports bench/ does not allow: a private name, a sibling script, or sys.path edited."""
    siblings = {p.stem for p in script.parent.glob("*.py")}
    out = []
    for node in ast.walk(ast.parse(script.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            out += [f"private name {node.module}.{a.name}" for a in node.names if a.name.startswith("_")
                    and a.name != "annotations"]
            modules = [node.module or ""]
        elif isinstance(node, ast.Import):
            modules = [a.name for a in node.names]
        else:
            modules = []
        out += [f"sibling script {m}" for m in modules if m.split(".")[0] in siblings]
        if isinstance(node, ast.Attribute) and node.attr == "path" and getattr(node.value, "id", "") == "sys":
            out.append(f"sys.path at line {node.lineno}")
    return out


def test_bench_holds_speed_benchmarks_importing_public_names_only():
    scripts = sorted(BENCH.glob("*.py"))
    assert len(scripts) >= 10 and not list(BENCH.glob("*.sh"))
    assert {p.name: import_problems(p) for p in scripts if import_problems(p)} == {}
    # the studies that chose settings live in experiments/, one line each in its README
    readme = (EXPERIMENTS / "README.md").read_text(encoding="utf-8")
    studies = sorted(p.name for p in EXPERIMENTS.iterdir() if p.suffix in (".py", ".sh"))
    assert studies and all(f"`{name}`" in readme for name in studies), studies
    assert not set(studies) & {p.name for p in scripts}


def test_the_import_check_finds_what_it_forbids(tmp_path):
    (tmp_path / "helper.py").write_text("")
    bad = tmp_path / "bad.py"
    bad.write_text("import sys\nsys.path.insert(0, '.')\nfrom helper import x\nfrom pddl_export.rules import _first_overlap\n")
    assert sorted(import_problems(bad)) == ["private name pddl_export.rules._first_overlap", "sibling script helper",
                                            "sys.path at line 2"]


def test_majority_share_counts_the_most_common_value_per_key():
    sp = _load("symbol_purity", EXPERIMENTS)
    keys, values = np.array([1, 1, 1, 2, 2]), np.array([7, 7, 8, 9, 9])
    assert sp.majority_share(keys, values) == pytest.approx(4 / 5)  # key 1: 2 of 3 agree; key 2: both
    assert sp.majority_share(values, keys) == 1.0  # each value has one key


def test_symbol_purity_on_a_trained_run(tiny_run):
    sp = _load("symbol_purity", EXPERIMENTS)
    r = sp.purity(tiny_run.path, tiny_run.data, n_shift=8)
    assert r["objects"] > 0 and 1 <= r["distinct_codes"] <= r["objects"]
    for k in ("type_purity", "location_purity", "level_purity", "arrangement_purity", "arrangement_determinism"):
        assert 0 < r[k] <= 1, k
    # a property refining another cannot be purer: (type, location, level) is at most as pure as type alone
    assert r["arrangement_purity"] <= r["type_purity"] + 1e-9
    assert set(r["codes_changed_by_pixel_shift"]) == {f"{a},{b}" for a, b in sp.SHIFTS}


def test_the_baselines_of_the_speed_benches_answer_as_the_code_they_time():
    """bench/rule_successors_memo.py's dense comparison is the baseline its speedup is measured against: it must
    give what the faster code gives."""
    import itertools

    from pddl_export.rule_successors import RuleSuccessors
    from tests.test_overrides import VOCAB, random_rules

    memo = _load("rule_successors_memo")
    rules = random_rules(np.random.default_rng(1), n=25)
    succ = RuleSuccessors(rules)
    states = np.array(list(itertools.product(VOCAB, repeat=3)), np.int64)
    assert np.array_equal(memo.dense_successors(succ, states), succ(states))
    assert not np.array_equal(memo.dense_successors(succ, states), np.repeat(states[:, None], len(succ.actions), 1))


def test_the_rules_load_baseline_builds_and_checks_groups_as_ruleset_does():
    """bench/rules_load.py times RuleSet's group arrays and exclusivity check against the earlier per-entry
    arrays and every-pair comparison: on random rules both must give the same arrays, and the same verdicts on
    exclusive groups and on a group made to overlap."""
    from pddl_export.rules import _first_overlap
    from tests.test_overrides import random_rules

    load = _load("rules_load")
    rules = random_rules(np.random.default_rng(4), n=40)
    new = load.ruleset_step(rules)
    base = load.groups_step(rules, load.baseline_dense_group, load.baseline_first_overlap)
    assert load.same_arrays(new[1], base[1]) and new[2] == base[2]
    assert any(len(rules.rules_for(*k)) > 1 for k in rules.dense_groups) and set(new[2]) == {None}
    _, lo, hi, _ = max(new[1].values(), key=lambda g: len(g[1]))
    hi = hi.copy()
    hi[:] = lo + 1  # each box a single count vector ...
    hi[1:] = hi[0]
    lo[1:] = lo[0]  # ... and all of them the same one
    assert _first_overlap(lo, hi) == load.baseline_first_overlap(lo, hi) == (0, 1)


def test_heldout_accuracy_interval_and_refusals(tmp_path, monkeypatch):
    """experiments/heldout_accuracy.py: the paired interval brackets the mean difference and narrows with more steps;
    a held-out set that made the rules (the same folder, or a copy of it) or no data set at all is refused in
    one line before any model is read."""
    monkeypatch.syspath_prepend(str(EXPERIMENTS))  # as `python experiments/heldout_accuracy.py` has it
    ho = _load("heldout_accuracy", EXPERIMENTS)
    rng = np.random.default_rng(0)
    net = rng.random(4000) < 0.7
    mine = np.where(rng.random(4000) < 0.1, ~net, net)  # flips a tenth of the steps either way
    d = mine.mean() - net.mean()
    lo, hi = ho.paired_interval(mine, net, seed=1)
    assert lo <= d <= hi and 0 < hi - lo < 0.03
    lo_s, hi_s = ho.paired_interval(mine[:400], net[:400], seed=1)
    assert hi_s - lo_s > 2 * (hi - lo)  # ten times fewer steps: about three times as wide
    assert ho.paired_interval(net, net, seed=1) == [0.0, 0.0]

    a, copy = tmp_path / "a", tmp_path / "copy"
    a.mkdir()
    (a / "manifest.json").write_text('{"samples": 1}')
    shutil.copytree(a, copy)
    base = ["--run", str(tmp_path / "run"), "--data", str(a), "--setting", "fast=", "--out", str(tmp_path / "o.json")]
    for heldout, message in [(a, "is one of --data"), (copy, "is a copy of"), (tmp_path / "none", "no manifest.json")]:
        with pytest.raises(SystemExit, match=message):
            ho.main([*base, "--heldout", str(heldout)])
    assert not (tmp_path / "o.json").exists()
