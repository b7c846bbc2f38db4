"""Location bits: back-projected crop centres, the bits read from them, and m(z) trained on codes that end with them."""
from __future__ import annotations

import dataclasses
import json
import shutil

import numpy as np
import pytest

from conftest import cli, cli_json, recomputed_transition_accuracy, write_config
from pddl_export.location_codec import UNSEEN
from pddl_export.symbolic import bits_from_codes
from symlearn.sim.camera import CameraConfig, crop_centres_xy, crop_tops_z
from symlearn.symbolic.locations import location_bits
from symlearn.world import LOCATIONS, TABLE_TOP_Z, ObjectState, ObjectType, Scene

CUBE_Z = TABLE_TOP_Z + 0.05


def test_location_bits_name_the_nearest_location_and_the_off_field():
    # 1 cm on; 10 cm off toward +y; unseen; 3 cm on; 12 cm off in x; 8 cm off toward -y
    xy = np.float32([[0.80, 0.19], [0.50, -0.20], [np.nan, np.nan], [0.5, 0.33], [0.62, 0.0], [0.8, -0.26]])
    four, five = location_bits(xy, 4), location_bits(xy, 5)
    assert four.shape == (6, 4) and five.shape == (6, 5) and five.dtype == np.float32
    nearest = (five[:, :3] @ [4, 2, 1]).astype(int).tolist()
    assert nearest == [2, 3, UNSEEN, 5, 4, 0] and np.array_equal(four[:, :3], five[:, :3])
    assert four[:, 3].tolist() == [0, 1, 1, 0, 1, 1]  # off (or unseen)
    assert (five[:, 3:] @ [2, 1]).astype(int).tolist() == [0, 2, 3, 0, 3, 1]  # on, +y, unseen, on, x, -y
    six = location_bits(xy, 6)
    assert six.shape == (6, 6) and np.array_equal(six[:, :3], five[:, :3])
    assert (six[:, 3:] @ [4, 2, 1]).astype(int).tolist() == [0, 5, 7, 0, 7, 1]  # +y 9-15 cm, x, -y 5-9 cm
    far = location_bits(np.float32([[0.8, 0.36], [0.5, 0.18], [0.5, -0.366], [0.8, -0.315]]), 6)  # 18, 12, 6.6, 13.5
    assert (far[:, :3] @ [4, 2, 1]).astype(int).tolist() == [2, 5, 3, 0]
    assert (far[:, 3:] @ [4, 2, 1]).astype(int).tolist() == [6, 2, 1, 2]  # +y far, -y mid, -y near, -y mid
    top = TABLE_TOP_Z + np.float32([0.1, 0.2, np.nan, 0.051, 0.149, 0.4])  # layers 2, 4, unseen, 1, 3, over 7
    seven = location_bits(xy, 7, top)
    assert seven.shape == (6, 7) and np.array_equal(seven[:, :4], four)
    assert (seven[:, 4:] @ [4, 2, 1]).astype(int).tolist() == [2, 4, 7, 1, 3, 7]
    with pytest.raises(ValueError, match="top height"):
        location_bits(xy, 7)
    nine = location_bits(xy, 9, top)  # the place of 6 bits, then the height of 7
    assert nine.shape == (6, 9) and np.array_equal(nine[:, :6], six) and np.array_equal(nine[:, 6:], seven[:, 4:])
    with pytest.raises(ValueError, match="9 location bits need each object's top height"):
        location_bits(xy, 9)
    assert location_bits(np.zeros((2, 0, 2)), 4).shape == (2, 0, 4)
    with pytest.raises(ValueError, match="location bits must be one of"):
        location_bits(xy, 3)


def test_crop_centres_land_on_the_objects_and_name_their_locations(sim):
    """A cube on location 4, a cube 10 cm off location 2, a stick on location 3: centres within 2.5 cm, bits right."""
    scene = Scene((ObjectState(ObjectType.CUBE, (*LOCATIONS[4], CUBE_Z)),
                   ObjectState(ObjectType.CUBE, (LOCATIONS[2][0], LOCATIONS[2][1] + 0.10, CUBE_Z)),
                   ObjectState(ObjectType.STICK, (*LOCATIONS[3], TABLE_TOP_Z + 0.025))))
    sim.reset(scene)
    obs = sim.observe()
    xy = crop_centres_xy(np.asarray(obs.crops, np.float32), obs.origins, sim.cfg.camera)
    truth = np.array([o.position[:2] for o in sim.get_scene().objects])
    assert np.abs(xy - truth).max() < 0.025
    bits = location_bits(xy, 5)
    assert (bits[:, :3] @ [4, 2, 1]).astype(int).tolist() == [4, 2, 3]
    assert (bits[:, 3:] @ [2, 1]).astype(int).tolist() == [0, 2, 0]  # on, off toward +y, on
    empty = crop_centres_xy(np.zeros((1, 64, 64), np.float32), np.zeros((1, 2)), CameraConfig())
    assert np.isnan(empty).all()  # no visible pixel: no centre


def test_crop_tops_tell_a_stack_apart(sim):
    """Two cubes stacked on location 1 and a stick on location 3: tops within 5 mm, height layers 2, 4 and 1."""
    scene = Scene((ObjectState(ObjectType.CUBE, (*LOCATIONS[1], CUBE_Z)),
                   ObjectState(ObjectType.CUBE, (*LOCATIONS[1], CUBE_Z + 0.1)),
                   ObjectState(ObjectType.STICK, (*LOCATIONS[3], TABLE_TOP_Z + 0.025))))
    sim.reset(scene)
    obs = sim.observe()
    crops = np.asarray(obs.crops, np.float32)
    xy, top = crop_centres_xy(crops, obs.origins, sim.cfg.camera), crop_tops_z(crops, obs.origins, sim.cfg.camera)
    assert np.abs(top - (TABLE_TOP_Z + np.float32([0.1, 0.2, 0.05]))).max() < 0.005
    assert np.abs(xy[:2] - np.float32(LOCATIONS[1])).max() < 0.025  # the bottom cube's sides still show
    bits = location_bits(xy, 7, top)
    assert (bits[:, 4:] @ [4, 2, 1]).astype(int).tolist() == [2, 4, 1]
    assert (bits[:, :3] @ [4, 2, 1]).astype(int).tolist() == [1, 1, 3]


def test_train_transition_with_location_bits_plans_on_13_bit_codes(tiny_run, tiny_run_copy, sim, tmp_path):
    """location_bits = 5: m(z) on 13-bit codes whose last 5 bits are read from geometry, through export and planning."""
    from symlearn.learning.models import AttentiveDeepSym
    from symlearn.symbolic.scenes import scene_codes
    from symlearn.symbolic.learned_transition import LearnedTransition, planning_models
    from symlearn.symbolic.transition_data import SymbolReader

    run = tiny_run_copy
    config = write_config(tmp_path / "loc5.toml", {"transition": {"location_bits": 5},
                                                   "export": {"pddl_fidelity_cases": 20}})
    out = cli_json("train-transition", "--run", run, "--data", tiny_run.data, "--preset", "quick", "--config", config,
                   "--quiet")
    want = recomputed_transition_accuracy(run, tiny_run.data)  # on 13-bit codes: the reader adds location bits
    assert out["test"]["bit_accuracy"] == pytest.approx(want["bit_accuracy"], abs=1e-5)
    assert out["test"]["scene_accuracy"] == pytest.approx(want["scene_accuracy"], abs=1e-5)
    meta = json.loads((run / "transition_metrics.json").read_text())
    assert meta["transition_config"]["location_bits"] == 5 and meta["transition_config"]["bits"] == 13
    assert CameraConfig.from_json(meta["location_camera"]) == CameraConfig()
    reader, transition = planning_models(run)
    assert reader.bits == transition.bits == 13
    scene = Scene((ObjectState(ObjectType.CUBE, (*LOCATIONS[1], CUBE_Z)),
                   ObjectState(ObjectType.CUBE, (*LOCATIONS[5], CUBE_Z))))
    codes = scene_codes(sim, reader, scene)
    tail = bits_from_codes(codes, 13)[:, 8:]
    assert (tail[:, :3] @ [4, 2, 1]).tolist() == [1, 5] and tail[:, 3:].sum() == 0
    plain = scene_codes(sim, reader.model, scene)  # the learned codes are the first 8 bits, unchanged
    assert (codes >> 5).tolist() == plain.tolist()
    stacked = Scene((ObjectState(ObjectType.CUBE, (*LOCATIONS[1], CUBE_Z)),
                     ObjectState(ObjectType.CUBE, (*LOCATIONS[1], CUBE_Z + 0.1))))
    high = scene_codes(sim, SymbolReader(reader.model, reader.camera, 7), stacked)  # 4 bits, then the height
    assert (high & 7).tolist() == [2, 4] and ((high >> 3) & 15).tolist() == [2, 2] and (high >> 7).tolist() == \
        scene_codes(sim, reader.model, stacked).tolist()
    placed = scene_codes(sim, SymbolReader(reader.model, reader.camera, 9), stacked)  # place (on: 0), then height
    assert (placed & 7).tolist() == [2, 4] and ((placed >> 3) & 63).tolist() == [1 << 3, 1 << 3]
    assert (placed >> 9).tolist() == (high >> 7).tolist()

    rc, _ = cli("export-pddl", "--run", run, "--data", tiny_run.data, "--rules", "--config", config)
    rules = json.loads((run / "pddl" / "rules.json").read_text())
    rep = json.loads((run / "pddl" / "report.json").read_text())
    assert rc == 0 and rules["bits"] == 13 and rep["fidelity"] == 1.0 and rep["pddl_fidelity"] == 1.0

    assert LearnedTransition.from_run(tiny_run.path).reader(reader.model).bits == 8  # the run without them
    with pytest.raises(ValueError, match="with the camera the crops were rendered with"):
        SymbolReader(reader.model, None, 5)
    with pytest.raises(ValueError, match="cannot give this transition's 13-bit codes"):
        transition.reader(AttentiveDeepSym(dataclasses.replace(reader.model.cfg, bits=6)))


def test_location_bits_refuse_data_sets_of_different_cameras(tiny_data, tiny_k45, tmp_path):
    from symlearn.data.dataset import DataError
    from symlearn.symbolic.transition_training import data_camera

    assert data_camera(tiny_data.path, (tiny_k45,)) == CameraConfig()
    other = tmp_path / "k45"
    shutil.copytree(tiny_k45, other)
    m = json.loads((other / "manifest.json").read_text())
    m["settings"]["sim"]["camera"]["fov_deg"] = 50.0
    (other / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(DataError, match="different cameras"):
        data_camera(tiny_data.path, (other,))
