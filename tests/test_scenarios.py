"""The physical phenomena the symbols must capture, asserted on recorded effects (metres)."""
import numpy as np
import pytest

from symlearn.sim.scenarios import SCENARIO_BY_NAME, SCENARIOS, run_scenario
from symlearn.world import LOCATIONS, ObjectType

CM = 0.01


def offset(a: int, b: int) -> np.ndarray:
    return np.array([LOCATIONS[b][0] - LOCATIONS[a][0], LOCATIONS[b][1] - LOCATIONS[a][1], 0.0])


@pytest.fixture(scope="module")
def effects(sim):
    return {s.name: run_scenario(sim, s) for s in SCENARIOS}


def test_p1_lone_object_moves_by_location_offset(effects):
    e = effects["p1_lone_move"].effect
    np.testing.assert_allclose(e[0], offset(4, 0), atol=1 * CM)


def test_p2_object_on_stick_moves_with_it(effects):
    e = effects["p2_rides_on_stick"].effect
    np.testing.assert_allclose(e[0], offset(1, 0), atol=1 * CM)  # the stick
    np.testing.assert_allclose(e[1], offset(1, 0), atol=1.5 * CM)  # the cube on its far end


def test_p3_lower_object_not_grasped(effects):
    e = effects["p3_under_not_grasped"].effect
    assert np.abs(e[0]).max() < 0.5 * CM
    np.testing.assert_allclose(e[1], offset(4, 5) + [0, 0, -0.10], atol=1 * CM)  # top cube to the table


def test_p4_empty_pick_changes_nothing(effects):
    assert np.abs(effects["p4_empty_pick"].effect).max() < 0.5 * CM


@pytest.mark.parametrize("name,height", [("p5_stack", 0.10), ("p5_stack_on_stick", 0.05)])
def test_p5_release_on_occupied_location_stacks(effects, name, height):
    e = effects[name].effect
    moved = int(np.argmax(np.linalg.norm(e, axis=1)))
    np.testing.assert_allclose(e[moved], offset(3, 4) + [0, 0, height], atol=1 * CM)
    assert np.abs(np.delete(e, moved, axis=0)).max() < 0.5 * CM


def test_table1_case1_only_stick_moves(effects):
    r = effects["table1_case1"]
    assert r.types[0] == ObjectType.STICK
    np.testing.assert_allclose(r.effect[0], [0, 0.18, 0], atol=1 * CM)
    assert np.abs(r.effect[1:]).max() < 0.5 * CM


def test_table1_case2_cube_on_stick_moves_too(effects):
    e = effects["table1_case2"].effect
    np.testing.assert_allclose(e[0], [0, 0.18, 0], atol=1 * CM)
    assert np.abs(e[1]).max() < 0.5 * CM  # the cube elsewhere
    np.testing.assert_allclose(e[2], [0, 0.18, 0], atol=1.5 * CM)  # the cube on the stick


@pytest.mark.parametrize("name", ["table1_case3", "table1_case3_stacked"])
def test_table1_case3_both_cubes_ride_with_stick(effects, name):
    """Paper's case 3 (a cube near each end) and the extra stacked variant: both cubes ride +180 mm."""
    e = effects[name].effect
    np.testing.assert_allclose(e[0], [0, 0.18, 0], atol=1 * CM)
    assert np.all(np.abs(e[1:, 1] - 0.18) < 3 * CM), e


def test_table1_case3_cubes_stand_near_opposite_ends():
    spec = SCENARIO_BY_NAME["table1_case3"].spec
    assert [loc for _, loc in spec] == [1, 0, 2]  # stick centred at far-middle, cubes at its two neighbours


def test_scenarios_are_deterministic(sim, effects):
    again = run_scenario(sim, SCENARIO_BY_NAME["table1_case2"])
    np.testing.assert_allclose(again.effect, effects["table1_case2"].effect, atol=1e-6)


def test_scenario_json_lists_stick_first(effects):
    j = effects["table1_case3"].to_json()
    assert j["action"] == [1, 2] and j["objects"][0]["type"] == "stick"
    assert len(j["objects"]) == 3 and abs(j["objects"][0]["effect_mm"][1] - 180) < 10
