"""evaluate, table1 and symbols on a tiny run: the files they promise, with sane numbers."""
import json

import numpy as np
import pytest

from symlearn.sim.collect import CollectConfig, collect
from symlearn.learning.evaluation import evaluate, format_table
from symlearn.symbolic.symbols import analyse_symbols, picked_objects
from symlearn.data.dataset import load_split
from symlearn.learning.table1 import CASES, format_table1, table1
from symlearn.learning.training import TrainConfig, train


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    root = tmp_path_factory.mktemp("analysis")
    collect(root / "data", CollectConfig(n=48, seed=9, shard_size=4), show_progress=False)
    cfg = dict(epochs=1, batch_size=8, bf16=False)
    train(root / "data", root / "run", TrainConfig.from_preset("quick", **cfg), show_progress=False)
    train(root / "data", root / "base", TrainConfig.from_preset("quick", attention=False, **cfg), show_progress=False)
    return root


def test_evaluate_writes_rows_with_ablations(run):
    res = evaluate(run / "run", run / "data", baseline_run=run / "base")
    saved = json.loads((run / "run" / "eval.json").read_text())
    assert saved["effect_mae_mm"] == res["effect_mae_mm"] and set(res["effect_mae_mm"]) == {"x", "y", "z"}
    assert set(res["ablations"]) == {"no_attention", "mean_effect"}
    assert res["n_test_samples"] == 4 and res["trained_on"] == res["data_fingerprint"]
    for row in (res, res["ablations"]["mean_effect"], res["ablations"]["no_attention"]):
        assert all(0 <= v < 2000 for v in row["effect_mae_mm"].values())
    assert "attentive" in format_table(res) and "mean_effect" in format_table(res)


def test_table1_runs_three_cases_against_simulator(run):
    res = table1(run / "run")
    assert [c["name"] for c in res["cases"]] == list(CASES)
    case2 = res["cases"][1]["objects"]
    assert case2[0]["type"] == "stick" and abs(case2[0]["truth_mm"][1] - 180) < 10
    assert abs(case2[2]["truth_mm"][1] - 180) < 15 and abs(case2[1]["truth_mm"][1]) < 5
    assert (run / "run" / "table1.json").exists() and "Ground truth" in format_table1(res)


def test_symbols_counts_cover_all_objects_and_write_figures(run):
    res = analyse_symbols(run / "run", run / "data", min_count=1)
    assert sum(r["count"] for r in res["symbols"]) == res["n_objects"]
    assert 1 <= res["n_symbols_for_95pct"] <= res["n_distinct"] <= 256
    assert all(len(r["code"]) == 8 and 0.5 <= r["type_purity"] <= 1 for r in res["symbols"])
    for f in ("symbols.json", "symbols.png", "symbol_examples.png"):
        assert (run / "run" / f).stat().st_size > 0
    with pytest.raises(ValueError, match="8-bit string"):
        analyse_symbols(run / "run", run / "data", symbol="0101")


def test_picked_objects_marks_the_object_under_the_pick_location(run):
    d = load_split(run / "data", "all")
    p = picked_objects(d)
    assert not p[~d.mask].any()
    # an object the suction tool held was, by construction, under the pick location
    held = d.grasped >= 0
    assert p[np.flatnonzero(held), d.grasped[held]].mean() > 0.95
