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
