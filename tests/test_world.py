import numpy as np
import pytest

from symlearn.world import (N_ACTIONS, Action, ObjectState, ObjectType, Scene, action_id, decode_action,
                            one_hot_actions)


def test_action_ids_round_trip_pick_major():
    ids = [action_id(p, r) for p in range(6) for r in range(6)]
    assert ids == list(range(N_ACTIONS))
    assert all(decode_action(i).id == i for i in ids)
    assert decode_action(7) == Action(1, 1)  # pick == release is legal


@pytest.mark.parametrize("bad", [-1, 36, 100, 2.5, "3"])
def test_unknown_action_id_refused(bad):
    with pytest.raises(ValueError, match="unknown action id"):
        decode_action(bad)


@pytest.mark.parametrize("pick,release", [(6, 0), (0, -1), (0, 6)])
def test_location_out_of_range_refused(pick, release):
    with pytest.raises(ValueError, match="location"):
        Action(pick, release)


def test_one_hot():
    oh = one_hot_actions(np.array([0, 35, 7]))
    assert oh.shape == (3, 36) and oh.sum() == 3 and oh[1, 35] == 1 and oh[2, 7] == 1
    with pytest.raises(ValueError, match="unknown action id"):
        one_hot_actions(np.array([36]))


def test_scene_json_round_trip_and_validation():
    s = Scene((ObjectState(ObjectType.CUBE, (0.5, 0.0, 0.45)), ObjectState(ObjectType.STICK, (0.8, 0.0, 0.425))))
    assert Scene.from_json(s.to_json()) == s
    np.testing.assert_allclose(s.positions(), [[0.5, 0, 0.45], [0.8, 0, 0.425]])
    with pytest.raises(ValueError, match="at most one stick"):
        Scene((ObjectState(ObjectType.STICK, (0.5, 0, 0.4)), ObjectState(ObjectType.STICK, (0.8, 0, 0.4))))
    with pytest.raises(ValueError, match="malformed scene"):
        Scene.from_json({"objects": [{"type": "sphere", "position": [0, 0, 0]}]})
    with pytest.raises(ValueError, match="position needs 3"):
        ObjectState(ObjectType.CUBE, (0.5, 0.0))
