"""bench/depth_speed.py's summary: medians against a chosen baseline, overall and per cell of objects x length."""
import importlib.util
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "bench"


def _module():
    spec = importlib.util.spec_from_file_location("depth_speed", BENCH / "depth_speed.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _record(k, shortest, times):
    return {"problem": f"k{k}", "n_objects": k, "reference_length": 9, "shortest_length": shortest,
            "planners": {name: {"status": "solved" if t < 10 else "timeout", "time_s": t} for name, t in times.items()}}


def test_medians_per_cell_show_where_the_baseline_falls_behind():
    ds = _module()
    records = [_record(2, 1, {"astar-outcomes": 0.01, "fd": 0.2}), _record(2, 2, {"astar-outcomes": 0.03, "fd": 0.2}),
               _record(7, 6, {"astar-outcomes": 10.0, "fd": 0.8}), _record(7, 7, {"astar-outcomes": 6.0, "fd": 1.2})]
    out = ds.summarize(records, ["astar-outcomes", "fd"], baseline="astar-outcomes", by="shortest")
    assert out["baseline"] == "astar-outcomes" and out["fastest_other_planner"] == "fd"
    assert set(out["by_cell"]) == {"k2 1-2", "k7 5-6", "k7 7-8"}
    small, big = out["by_cell"]["k2 1-2"]["fd"], out["by_cell"]["k7 5-6"]["fd"]
    assert abs(small["baseline_over_planner"] - 0.1) < 1e-9 and small["solved"] == 2
    assert abs(big["baseline_over_planner"] - 12.5) < 1e-9
    assert out["by_cell"]["k7 5-6"]["astar-outcomes"]["solved"] == 0  # a time-out counts with its time, unsolved
    # placed by the reference length instead, every record falls in the 9-12 cell of its object count
    assert set(ds.summarize(records, ["astar-outcomes", "fd"], "astar-outcomes", "reference")["by_cell"]) == \
        {"k2 9-12", "k7 9-12"}
