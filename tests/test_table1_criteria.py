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


def test_attention_maps_are_row_stochastic_and_follow_the_objects():
    """Each object's weights over the real objects sum to 1, padded slots get none, and reordering the objects
    reorders the maps the same way (the transformer has no notion of slot order); no maps without attention."""
    import torch

    from symlearn.learning.models import AttentiveDeepSym, ModelConfig
    torch.manual_seed(0)
    model = AttentiveDeepSym(ModelConfig(n_layers=2)).eval()
    codes = (torch.rand(2, 4, 8) > 0.5).float()
    mask = torch.tensor([[True, True, True, True], [True, True, True, False]])
    actions = torch.tensor([3, 17])
    maps = model.attention_maps(codes, mask, actions)
    assert maps.shape == (2, 2, 4, 4)
    torch.testing.assert_close(maps[:, 0].sum(-1), torch.ones(2, 4))
    torch.testing.assert_close(maps[:, 1, :3].sum(-1), torch.ones(2, 3))
    assert float(maps[:, 1, :, 3].abs().max()) == 0.0  # nobody attends to the padded slot
    perm = torch.tensor([2, 0, 3, 1])
    again = model.attention_maps(codes[:, perm], mask[:1].expand(2, 4), actions)[:, 0]
    torch.testing.assert_close(again, maps[:, 0][:, perm][:, :, perm])
    assert AttentiveDeepSym(ModelConfig(attention=False)).attention_maps(codes, mask, actions) is None


def test_rider_attention_reads_the_riders_weight_on_the_stick():
    from symlearn.learning.table1 import rider_attention
    case = {"objects": [{"type": "stick", "truth_mm": [0, 180, 0]}, {"type": "cube", "truth_mm": [0, 1, 0]},
                        {"type": "cube", "truth_mm": [-1, 176, 0]}],
            "attention": [[[0.5, 0.25, 0.25], [0.2, 0.6, 0.2], [0.7, 0.1, 0.2]],
                          [[1, 0, 0], [0, 1, 0], [0.05, 0.05, 0.9]]]}
    assert rider_attention(case) == [{"object": 2, "on_stick": [0.7, 0.05], "on_itself": [0.2, 0.9]}]
    assert rider_attention({"objects": case["objects"]}) == []  # the no-attention baseline: nothing to read
