"""evaluate, table1 and symbols on a tiny run: the files they promise, with sane numbers."""
import json
import shutil

import numpy as np
import pytest

from symlearn.learning.evaluation import evaluate, format_table
from symlearn.symbolic.symbols import analyse_symbols, picked_objects
from symlearn.data.dataset import load_split
from symlearn.data.statistics import rider_mask
from symlearn.learning.table1 import CASES, format_table1, table1
from conftest import TINY_TRAIN_ARGS, cli_json


@pytest.fixture(scope="module")
def run(tmp_path_factory, tiny_data, tiny_run):
    """ROOT/data: the session's tiny data set; ROOT/run: a copy of the tiny run; ROOT/base: a no-attention run."""
    root = tmp_path_factory.mktemp("analysis")
    (root / "data").symlink_to(tiny_data.path, target_is_directory=True)
    shutil.copytree(tiny_run.path, root / "run")
    cli_json("train", "--data", root / "data", "--out", root / "base", *TINY_TRAIN_ARGS, "--no-attention", "--quiet")
    return root


def _png_size(path) -> tuple[int, int]:
    """Width and height from a PNG file's header (refusing anything that is not a PNG)."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR", path
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def test_evaluate_writes_rows_with_ablations(run):
    res = evaluate(run / "run", run / "data", baseline_run=run / "base")
    saved = json.loads((run / "run" / "eval.json").read_text())
    assert saved["effect_mae_mm"] == res["effect_mae_mm"] and set(res["effect_mae_mm"]) == {"x", "y", "z"}
    assert set(res["ablations"]) == {"no_attention", "mean_effect"}
    assert res["n_test_samples"] == 4 and res["trained_on"] == res["data_fingerprint"]
    # the mean-effect row is the training split's mean effect scored on the test split, recomputed here
    tr, te = load_split(run / "data", "train"), load_split(run / "data", "test")
    want = np.abs(tr.effect[tr.mask].astype(np.float64).mean(0) - te.effect[te.mask]).mean(0) * 1000
    got = res["ablations"]["mean_effect"]["effect_mae_mm"]
    np.testing.assert_allclose([got[a] for a in "xyz"], want, atol=0.02)
    np.testing.assert_allclose([res["mean_abs_effect_mm"][a] for a in "xyz"],
                               np.abs(te.effect[te.mask]).mean(0) * 1000, atol=0.02)
    counts = {str(k): int(te.mask[te.n_objects == k].sum()) for k in np.unique(te.n_objects)}
    for row in (res, res["ablations"]["mean_effect"], res["ablations"]["no_attention"]):
        assert set(row["by_objects"]) == set(counts)  # the overall error is the object-weighted mean of the rows
        for a in "xyz":
            by = sum(counts[k] * row["by_objects"][k][a] for k in counts) / sum(counts.values())
            assert row["effect_mae_mm"][a] == pytest.approx(by, abs=0.02) and row["effect_mae_mm"][a] > 0
    assert res["effect_mae_mm"] != res["ablations"]["no_attention"]["effect_mae_mm"]  # two different models
    # rider rows: the count is the rider mask's, and the mean-effect row's rider error is recomputed here
    riders = rider_mask(te)
    assert res["riders"]["count"] == int(riders.sum())
    if riders.any():
        want = np.abs(tr.effect[tr.mask].astype(np.float64).mean(0) - te.effect[riders]).mean(0) * 1000
        got = res["ablations"]["mean_effect"]["riders"]["effect_mae_mm"]
        np.testing.assert_allclose([got[a] for a in "xyz"], want, atol=0.02)
    else:
        assert res["riders"]["effect_mae_mm"] is None
    assert "attentive" in format_table(res) and "mean_effect" in format_table(res)


def test_table1_runs_three_cases_against_simulator(run):
    res = table1(run / "run")
    assert [c["name"] for c in res["cases"]] == list(CASES)
    case2 = res["cases"][1]["objects"]
    assert case2[0]["type"] == "stick" and abs(case2[0]["truth_mm"][1] - 180) < 10
    assert abs(case2[2]["truth_mm"][1] - 180) < 15 and abs(case2[1]["truth_mm"][1]) < 5
    assert json.loads((run / "run" / "table1.json").read_text()) == res and "Ground truth" in format_table1(res)


def test_symbols_counts_cover_all_objects_and_write_figures(run):
    res = analyse_symbols(run / "run", run / "data", min_count=1)
    assert sum(r["count"] for r in res["symbols"]) == res["n_objects"]
    assert 1 <= res["n_symbols_for_95pct"] <= res["n_distinct"] <= 256
    assert all(len(r["code"]) == 8 and 0.5 <= r["type_purity"] <= 1 for r in res["symbols"])
    assert json.loads((run / "run" / "symbols.json").read_text()) == json.loads(json.dumps(res))
    for f in ("symbols.png", "symbol_examples.png"):
        w, h = _png_size(run / "run" / f)
        assert w >= 200 and h >= 200, (f, w, h)
    with pytest.raises(ValueError, match="8-bit string"):
        analyse_symbols(run / "run", run / "data", symbol="0101")


def test_picked_objects_marks_the_object_under_the_pick_location(run):
    d = load_split(run / "data", "all")
    p = picked_objects(d)
    assert not p[~d.mask].any()
    # an object the suction tool held was, by construction, under the pick location
    held = d.grasped >= 0
    assert p[np.flatnonzero(held), d.grasped[held]].mean() > 0.95


def test_code_stability_counts_still_objects_and_scenes_with_a_shared_code():
    import torch

    from symlearn.learning.evaluation import code_stability

    # codes before (by scene, object) and after; scene 1 has one object, scene 3 a padded third slot
    before = torch.tensor([[[0, 1], [0, 1], [1, 1]], [[1, 0], [0, 0], [0, 0]], [[0, 0], [1, 0], [0, 1]],
                           [[1, 1], [0, 1], [1, 1]]], dtype=torch.float32)
    after = before.clone()
    after[2, 1] = torch.tensor([0, 1.0])  # a still object whose code changed
    mask = torch.tensor([[True, True, True], [True, False, False], [True, True, True], [True, True, False]])

    class Split:
        def __len__(self):
            return 4

        def batch(self, idx):
            return before[idx], mask[idx], None, None  # the stub encoder reads the codes from the "crops"

        def post_crops(self, idx):
            return after[idx]

    class Model(torch.nn.Module):
        def __init__(self):
            super().__init__()
            self.w = torch.nn.Parameter(torch.zeros(1))

        def encode(self, crops, m):
            return crops, None

    still = mask.numpy().copy()
    still[0, 2] = False
    out = code_stability(Model(), Split(), still, batch_size=3)  # two batches
    assert out["still_objects"] == int(still.sum()) == 8
    assert out["code_unchanged"] == pytest.approx(7 / 8, abs=1e-4)
    assert out["scenes_all_unchanged"] == pytest.approx(3 / 4)
    # scenes of 2+ objects: 0 (objects 0 and 1 share a code), 2 (all apart), 3 (padding equals object 0: ignored)
    assert out["multi_object_scenes"] == 3 and out["scenes_with_shared_code"] == pytest.approx(1 / 3, abs=1e-4)
    assert out["shared_code_by_objects"] == {"2": 0.0, "3": 0.5}
    assert "shared codes: in 0.333 of 3 scenes" in format_table({
        "by_objects": {}, "effect_mae_mm": {"x": 1, "y": 1, "z": 1}, "ablations": {},
        "mean_abs_effect_mm": {"x": 1, "y": 1, "z": 1}, "code_stability": out})
