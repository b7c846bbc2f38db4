"""Data statistics on hand-made samples: riders, stacked objects, stick shares."""
import numpy as np

from symlearn.data.dataset import ARRAY_NAMES, InteractionData
from symlearn.data.statistics import arrangement_labels, object_shares, rider_mask, stacked_mask
from symlearn.world import LOCATIONS


def _data(effect, grasped, obj_type, z):
    """Samples of 3 object slots from effects (N, 3, 3), held index, types and start heights."""
    n, k = len(grasped), 3
    arr = {name: np.zeros((n, k) if name in ("pre_pixels", "post_pixels") else (n,), np.int32)
           for name in ARRAY_NAMES}
    arr.update(pre_depth=np.zeros((n, k, 4, 4), np.float16), post_depth=np.zeros((n, k, 4, 4), np.float16),
               pre_origin=np.zeros((n, k, 2), np.int16), post_origin=np.zeros((n, k, 2), np.int16),
               effect=np.asarray(effect, np.float32), n_objects=(np.asarray(obj_type) >= 0).sum(1).astype(np.int8),
               obj_type=np.asarray(obj_type, np.int8), grasped=np.asarray(grasped, np.int8),
               pre_pose=np.zeros((n, k, 7), np.float32), post_pose=np.zeros((n, k, 7), np.float32))
    arr["pre_pose"][..., 2] = z
    return InteractionData(**arr)


def test_riders_are_unheld_objects_carried_along():
    d = _data(effect=[[[0, .18, 0], [0, .18, 0], [0, 0, 0]],    # stick held, cube on it rides, cube elsewhere
                      [[0, .30, .1], [0, .01, 0], [0, 0, 0]],    # a cube moved, another only jostled
                      [[0, 0, 0], [0, .20, 0], [0, 0, 0]]],      # nothing held: a moved object is no rider
              grasped=[0, 0, -1], obj_type=[[1, 0, 0], [0, 0, -1], [0, 0, 0]],
              z=[[.425, .50, .45], [.45, .45, 0], [.45, .55, .45]])
    np.testing.assert_array_equal(rider_mask(d), [[0, 1, 0], [0, 0, 0], [0, 0, 0]])
    np.testing.assert_array_equal(stacked_mask(d), [[0, 1, 0], [0, 0, 0], [0, 1, 0]])
    s = object_shares(d)
    assert (s["objects"], s["sticks"], s["riders"], s["riders_on_stick"], s["stacked"]) == (8, 1, 1, 1, 2)
    assert s["scenes_with_stick_by_objects"] == {"2": 0.0, "3": 0.5}


def test_arrangement_labels_name_type_location_and_level():
    d = _data(effect=np.zeros((1, 3, 3)), grasped=[-1], obj_type=[[1, 0, 0]], z=[[.425, .50, .55]])
    d.pre_pose[0, :, :2] = [LOCATIONS[4], np.add(LOCATIONS[4], .01), np.add(LOCATIONS[2], -.02)]
    d.post_pose[0, :, :2] = [LOCATIONS[1]] * 3
    d.post_pose[0, :, 2] = [.425, .50, .45]
    # a stick on the table at 4, a cube on it (one level up), a cube two levels up near 2
    np.testing.assert_array_equal(arrangement_labels(d), [[1040, 41, 22]])
    np.testing.assert_array_equal(arrangement_labels(d, after=True), [[1010, 11, 10]])
    pad = _data(effect=np.zeros((1, 3, 3)), grasped=[-1], obj_type=[[0, -1, -1]], z=[[.45, 0, 0]])
    assert arrangement_labels(pad)[0, 1:].tolist() == [-1, -1]
