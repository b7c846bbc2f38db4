"""The Table I criteria on hand-made rows: motion right, riders within 50 mm, and the paper's own row passing."""
import pytest

from symlearn.learning.table1 import PAPER_TABLE1, format_table1, judge_object, summarize_criteria


@pytest.mark.parametrize("typ,pred,truth,motion,rider", [
    ("stick", (0, 150, 0), (0, 180, 0), True, None),      # moved, predicted moved
    ("stick", (0, 90, 0), (0, 180, 0), False, None),      # too short a move
    ("cube", (5, 10, 5), (0, 0, 0), True, None),          # still, predicted within 20 mm
    ("cube", (0, 30, 0), (0, 0, 0), False, None),         # still, predicted 30 mm away
    ("cube", (0, 131, 0), (0, 176, 0), True, True),       # a rider within 50 mm
    ("cube", (0, 110, 0), (0, 176, 0), True, False),      # a rider 66 mm short
    ("cube", (0, -150, 0), (0, 176, 0), False, False),    # the wrong direction
])
def test_judge_object(typ, pred, truth, motion, rider):
    j = judge_object({"type": typ, "predicted_mm": pred, "truth_mm": truth})
    assert j["motion_right"] is motion and j.get("rider_y_within_50mm") == rider


def _cases(key):
    types = ("stick", "cube", "cube")
    return [{"objects": [{"type": t, "predicted_mm": p, "truth_mm": g} for t, p, g in zip(types, pr, tr)]}
            for pr, tr in zip(PAPER_TABLE1[key], PAPER_TABLE1["truth_mm"])]


def test_paper_predictions_meet_the_criteria_and_truth_trivially():
    for key in ("predicted_mm", "truth_mm"):
        cases = _cases(key)
        for c in cases:
            for o in c["objects"]:
                o["criteria"] = judge_object(o)
        s = summarize_criteria(cases)
        assert s["motion_right"] and s["riders_within_50mm"], (key, s)
        assert s["objects_motion_right"] == "9/9" and s["riders_right"] == "3/3"
    text = format_table1({"cases": cases, "criteria": s})
    assert "(102, 177, -75)" in text and "met" in text and text.count("Case 3") == 2
