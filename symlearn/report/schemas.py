"""What the report reads from each of a run's files: one schema per file kind (symlearn.report.gather applies them).

A schema names the fields the report uses, with their types, ranges and list lengths; other fields
the stages write are let through (extra=True). A file that does not fit is refused by the bounded
reader (pddl_export.bounded_json) in one line naming the file and the field, and its section says
"not run" with that line instead of a traceback. Impossible values are refused the same way (an error or
a time below zero, a rate or share outside 0..1), so they never reach the scorecard as "met": its marks
for a refused file read "invalid".
"""
from __future__ import annotations

from pddl_export.bounded_json import Bool, Int, List, Map, Num, Obj, OneOf, Opt, Str

MAX_ITEMS = 100_000  # epochs of a history, symbols of a run, cases, planners: far fewer in practice
NUMBER = Opt(Num())
NON_NEGATIVE = Opt(Num(0))  # an error, a mean absolute value, a time, a length
RATE = Opt(Num(0, 1))  # a success rate, a share, a purity
COUNT = Opt(Int(0))
SCALAR = Opt(OneOf((Num(), Str(1000), Bool())))  # a cell of a table
XYZ = Obj(optional={a: NON_NEGATIVE for a in "xyz"})  # per-axis mean absolute millimetres; a missing axis is '-'
VECTOR = Opt(List(Num(), 16))  # one object's (x, y, z) effect

EVAL = Obj(optional={
    "n_test_samples": COUNT, "effect_mae_mm": Opt(XYZ), "mean_abs_effect_mm": Opt(XYZ),
    "ablations": Opt(Map(Obj(optional={"effect_mae_mm": Opt(XYZ)}), 1000)),
    "riders": Opt(Obj(optional={"count": COUNT, "effect_mae_mm": Opt(OneOf((Num(0), XYZ)))}))})

TABLE1 = Obj(optional={
    "cases": List(Obj(optional={"objects": List(Obj({"predicted_mm": VECTOR, "truth_mm": VECTOR}), 16)}), 100),
    "paper": Opt(Obj(optional={k: Opt(List(List(VECTOR, 16), 100)) for k in ("predicted_mm", "truth_mm")})),
    "criteria": Opt(Obj(optional={"motion_right": Bool(), "riders_within_50mm": Bool(),
                                  "objects_motion_right": SCALAR, "riders_right": SCALAR})),
    "mean_abs_error_mm": Opt(OneOf((Num(0), XYZ)))})

SYMBOLS = Obj(optional={
    **{k: COUNT for k in ("n_objects", "n_distinct", "n_symbols_for_95pct")},
    **{k: RATE for k in ("weighted_type_purity", "weighted_moved_purity")}, "example_symbol": SCALAR,
    "symbols": Opt(List(Obj(optional={"code": SCALAR, "count": COUNT, "times_picked": COUNT,
                                      "cube_fraction": RATE, "moved_when_picked": RATE}), MAX_ITEMS))})

EPOCH = Obj(optional={"epoch": Int(0), "train_loss": NUMBER, "val_loss": NUMBER,
                      "val_mae_mm": Opt(Obj({a: NON_NEGATIVE for a in "xyz"}))})  # the curves plot all three axes
HISTORY = List(EPOCH, MAX_ITEMS)
METRICS = Obj(optional={"history": HISTORY})
TRANSITION_METRICS = Obj(optional={"history": HISTORY})

CONFIG = Obj(optional={"data": Opt(Str(4096))})

_RATES = {**{k: RATE for k in ("success_rate", "found_rate", "success_rate_closed_loop")},
          **{k: NON_NEGATIVE for k in ("median_time_s", "mean_plan_length")}}
BENCHMARK = Obj(optional={
    "summary": Opt(Map(Obj(optional={"n_problems": COUNT, **_RATES}), 1000)),
    "n_problems": COUNT, "timeout_s": NON_NEGATIVE,
    "problems": Opt(OneOf((Str(4096), List(Str(4096), 1000)))),
    "goal_placement": Opt(Map(Map(Obj(optional={"n_problems": COUNT, "success_rate": RATE,
                                                "success_rate_closed_loop": RATE}), 100), 1000))})

# file name in RUN -> schema (the benchmark JSON may also be given by path: BENCHMARK)
RUN_FILES = {"eval.json": EVAL, "table1.json": TABLE1, "symbols.json": SYMBOLS, "metrics.json": METRICS,
             "transition_metrics.json": TRANSITION_METRICS, "config.json": CONFIG, "benchmark.json": BENCHMARK}
