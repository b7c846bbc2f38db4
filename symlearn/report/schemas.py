"""What the report reads from each of a run's files: one schema per file kind (symlearn.report.gather applies them).

A schema names the fields the report uses, with their types, ranges and list lengths; other fields
the stages write are let through (extra=True). A file that does not fit is refused by the bounded
reader (pddl_export.bounded_json) in one line naming the file and the field, and its section says
"not run" with that line instead of a traceback.
"""
from __future__ import annotations

from pddl_export.bounded_json import Bool, Int, List, Map, Num, Obj, OneOf, Opt, Str

MAX_ITEMS = 100_000  # epochs of a history, symbols of a run, cases, planners: far fewer in practice
NUMBER = Opt(Num())
COUNT = Opt(Int(0))
SCALAR = Opt(OneOf((Num(), Str(1000), Bool())))  # a cell of a table
XYZ = Obj(optional={a: NUMBER for a in "xyz"})  # per-axis millimetres; a missing axis is shown as '-'
VECTOR = Opt(List(Num(), 16))  # one object's (x, y, z) effect

EVAL = Obj(optional={
    "n_test_samples": COUNT, "effect_mae_mm": Opt(XYZ), "mean_abs_effect_mm": Opt(XYZ),
    "ablations": Opt(Map(Obj(optional={"effect_mae_mm": Opt(XYZ)}), 1000)),
    "riders": Opt(Obj(optional={"count": COUNT, "effect_mae_mm": Opt(OneOf((Num(), XYZ)))}))})

TABLE1 = Obj(optional={
    "cases": List(Obj(optional={"objects": List(Obj({"predicted_mm": VECTOR, "truth_mm": VECTOR}), 16)}), 100),
    "paper": Opt(Obj(optional={k: Opt(List(List(VECTOR, 16), 100)) for k in ("predicted_mm", "truth_mm")})),
    "criteria": Opt(Obj(optional={"motion_right": Bool(), "riders_within_50mm": Bool(),
                                  "objects_motion_right": SCALAR, "riders_right": SCALAR})),
    "mean_abs_error_mm": Opt(OneOf((Num(), XYZ)))})

SYMBOLS = Obj(optional={
    **{k: COUNT for k in ("n_objects", "n_distinct", "n_symbols_for_95pct")},
    **{k: NUMBER for k in ("weighted_type_purity", "weighted_moved_purity")}, "example_symbol": SCALAR,
    "symbols": Opt(List(Obj(optional={k: SCALAR for k in ("code", "count", "cube_fraction", "times_picked",
                                                           "moved_when_picked")}), MAX_ITEMS))})

EPOCH = Obj(optional={"epoch": Int(0), "train_loss": NUMBER, "val_loss": NUMBER,
                      "val_mae_mm": Opt(Obj({a: NUMBER for a in "xyz"}))})  # the curves plot all three axes
HISTORY = List(EPOCH, MAX_ITEMS)
METRICS = Obj(optional={"history": HISTORY})
TRANSITION_METRICS = Obj(optional={"history": HISTORY})

CONFIG = Obj(optional={"data": Opt(Str(4096))})

_RATES = {k: NUMBER for k in ("success_rate", "found_rate", "median_time_s", "success_rate_closed_loop",
                              "mean_plan_length")}
BENCHMARK = Obj(optional={
    "summary": Opt(Map(Obj(optional={"n_problems": COUNT, **_RATES}), 1000)),
    "n_problems": COUNT, "timeout_s": NUMBER,
    "problems": Opt(OneOf((Str(4096), List(Str(4096), 1000)))),
    "goal_placement": Opt(Map(Map(Obj(optional={"n_problems": COUNT, "success_rate": NUMBER,
                                                "success_rate_closed_loop": NUMBER}), 100), 1000))})

# file name in RUN -> schema (the benchmark JSON may also be given by path: BENCHMARK)
RUN_FILES = {"eval.json": EVAL, "table1.json": TABLE1, "symbols.json": SYMBOLS, "metrics.json": METRICS,
             "transition_metrics.json": TRANSITION_METRICS, "config.json": CONFIG, "benchmark.json": BENCHMARK}
