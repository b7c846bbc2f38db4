import numpy as np
import pytest

from symlearn.sim.simulator import SimConfig, TabletopSimulator
from symlearn.world import Action, ObjectType, TABLE_TOP_Z


def test_step_refuses_non_actions(sim):
    sim.build([(ObjectType.CUBE, 4)])
    with pytest.raises(TypeError, match="Action"):
        sim.step(10)


def test_bad_crop_size_refused():
    with pytest.raises(ValueError, match="crop size"):
        SimConfig(crop=0)


def test_observation_crops_follow_object_identity(sim):
    sim.build([(ObjectType.CUBE, 3), (ObjectType.STICK, 5)])
    obs = sim.observe()
    assert obs.crops.shape == (2, 64, 64) and obs.origins.shape == (2, 2)
    assert obs.depth.shape == (256, 256) and np.all(obs.pixels > 50)
    on = obs.crops[obs.crops > 0]
    assert 0.9 < on.min() and on.max() < 1.8  # metric depth of the table-top objects
    assert obs.pixels[1] > 2 * obs.pixels[0]  # the stick shows more pixels than the cube's top
    sim.step(Action(3, 1))  # move the cube to the far middle
    after = sim.observe()
    assert np.abs(after.origins[1] - obs.origins[1]).max() <= 1  # the stick's window stays
    assert np.abs(after.origins[0] - obs.origins[0]).max() > 20  # the cube's window follows it


def test_effect_is_pose_difference_and_occupancy(sim):
    sim.build([(ObjectType.CUBE, 4)])
    assert sim.occupied().tolist() == [False, False, False, False, True, False]
    res = sim.step(Action(4, 2))
    np.testing.assert_allclose(res.effect, res.after.positions() - res.before.positions(), atol=1e-6)
    assert res.grasped == 0 and not res.off_table
    assert sim.occupied().tolist() == [False, False, True, False, False, False]
    assert abs(res.after.positions()[0, 2] - (TABLE_TOP_Z + 0.05)) < 2e-3


def test_urdf_temp_file_never_outlives_loading(tmp_path, monkeypatch):
    """The UR10's URDF goes through a temp file; it is gone after loading, and after a failed load too."""
    import tempfile

    import pytest

    from symlearn.sim import simulator as simmod
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    with simmod.TabletopSimulator():
        pass
    assert list(tmp_path.iterdir()) == []

    def broken(*args, **kwargs):
        raise RuntimeError("cannot parse")
    monkeypatch.setattr(simmod.pb, "loadURDF", broken)
    with pytest.raises(RuntimeError, match="cannot parse"):
        simmod._load_urdf_text("<robot/>", (0, 0, 0), 0)
    assert list(tmp_path.iterdir()) == []
