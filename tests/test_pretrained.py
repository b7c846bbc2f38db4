"""The shipped pretrained run: small, safely loadable, and it solves its problem in simulation right away."""
import json
import shutil
from pathlib import Path

import pytest

from conftest import cli
from pddl_export.files import sha256_file
from pddl_export.rules_io import load_rules

PRETRAINED = Path(__file__).resolve().parents[1] / "pretrained" / "quick-authors12k"
PROBLEM = PRETRAINED / "problems" / "three_objects_two_actions.json"


def test_pretrained_run_is_small_and_consistent():
    size = sum(p.stat().st_size for p in PRETRAINED.rglob("*") if p.is_file())
    assert size <= 10.5e6, size
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.symbolic.learned_transition import LearnedTransition
    model, ck = load_effect_model(PRETRAINED)
    assert ck.config.crop == 32 and ck.config.bits == 8  # the quick preset
    LearnedTransition.from_run(PRETRAINED)  # refuses a transition network of another effect model
    rules, model_hash = load_rules(PRETRAINED)
    assert model_hash == sha256_file(PRETRAINED / "transition.pt")[:16]  # the export is not stale
    assert len(rules.rules) > 100 and len(rules.codes) > 20
    ev = json.loads((PRETRAINED / "eval.json").read_text())
    assert ev["effect_model_sha256"] == sha256_file(PRETRAINED / "best.pt")[:16]
    assert all(ev["effect_mae_mm"][a] < lim for a, lim in zip("xyz", (8.6, 15, 6)))  # the paper's errors


@pytest.mark.parametrize("planner", ["astar", "fast-downward-sas-opt"])
def test_pretrained_run_solves_its_problem_in_simulation(tmp_path, planner):
    run = tmp_path / "run"  # planning writes its task files into the run: use a copy, not the repository
    shutil.copytree(PRETRAINED, run)
    rc, text = cli("plan", "--run", run, "--problem", PROBLEM, "--planner", planner, "--record", tmp_path / "p.gif")
    assert rc == 0, text
    line = [ln for ln in text.splitlines() if ln.startswith("problem_0008")][-1]
    assert "success True" in line and "length 2" in line, line
    from PIL import Image
    with Image.open(tmp_path / "p.gif") as gif:
        assert gif.n_frames == 3  # the start and one frame per action


@pytest.mark.parametrize("name", ["tower_of_two", "cube_on_carried_stick"])
def test_pretrained_run_builds_structures_in_simulation(tmp_path, name):
    """Structure goals (a tower of two cubes; a cube standing on a stick carried to another location), built by a
    plan that Fast Downward finds on the shipped rules and the simulated arm executes."""
    run = tmp_path / "run"
    shutil.copytree(PRETRAINED, run)
    problem = PRETRAINED / "problems" / f"{name}.json"
    rc, text = cli("plan", "--run", run, "--problem", problem, "--planner", "fast-downward-sas-opt", "--closed-loop")
    assert rc == 0, text
    line = [ln for ln in text.splitlines() if ln.startswith(name)][-1]
    assert "success True" in line and "failure None" in line, line


def test_plan_sets_torch_threads_one_by_default(tmp_path):
    """Search-time inference runs on one thread unless --threads asks for more (small batches on 2 busy cores crawl)."""
    import torch
    run = tmp_path / "run"
    shutil.copytree(PRETRAINED, run)
    before = torch.get_num_threads()
    try:
        assert cli("plan", "--run", run, "--problem", PROBLEM, "--threads", "2")[0] == 0
        assert torch.get_num_threads() == 2
        assert cli("plan", "--run", run, "--problem", PROBLEM)[0] == 0
        assert torch.get_num_threads() == 1
    finally:
        torch.set_num_threads(before)


STABLE = PRETRAINED.parent / "quick-stab12k"


def test_stability_run_is_small_consistent_and_steadier():
    """The second shipped run (quick preset trained with the code-stability loss): hashes tie its files together,
    its effect error is within the paper's and its still objects keep their codes more often than the first run's."""
    size = sum(p.stat().st_size for p in STABLE.rglob("*") if p.is_file())
    assert size <= 6e6, size
    from symlearn.learning.checkpoint import load_checkpoint
    from symlearn.symbolic.learned_transition import LearnedTransition
    ck = load_checkpoint(STABLE / "best.pt")
    assert ck.meta["train_config"]["stability_weight"] == 0.1 and ck.meta["train_config"]["rider_weight"] == 1.0
    LearnedTransition.from_run(STABLE)
    rules, model_hash = load_rules(STABLE)
    assert model_hash == sha256_file(STABLE / "transition.pt")[:16]
    ev = json.loads((STABLE / "eval.json").read_text())
    assert ev["effect_model_sha256"] == sha256_file(STABLE / "best.pt")[:16]
    assert all(ev["effect_mae_mm"][a] < lim for a, lim in zip("xyz", (8.6, 15, 6)))
    assert ev["code_stability"]["code_unchanged"] > 0.8  # the first run: 0.781 (docs/RESULTS.md)


@pytest.mark.parametrize("name", ["tower_of_two", "cube_on_carried_stick"])
def test_stability_run_builds_structures_with_the_in_process_rule_search(tmp_path, name):
    run = tmp_path / "run"
    shutil.copytree(STABLE, run)
    rc, text = cli("plan", "--run", run, "--problem", PRETRAINED / "problems" / f"{name}.json", "--planner", "rules-bfs",
                   "--closed-loop")
    assert rc == 0, text
    line = [ln for ln in text.splitlines() if ln.startswith(name)][-1]
    assert "success True" in line and "failure None" in line, line


LOCATED = PRETRAINED.parent / "quick-stab12k-located"


def test_located_run_shares_the_effect_model_and_reads_12_bit_codes(sim):
    """The third shipped run: the second run's effect model, byte for byte, with an m(z) on codes that end with 4
    location bits; the live codes of a scene end with each object's location, and the rules are its m(z)'s."""
    from symlearn.planning.scenes import scene_codes
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.world import LOCATIONS, TABLE_TOP_Z, ObjectState, ObjectType, Scene

    size = sum(p.stat().st_size for p in LOCATED.rglob("*") if p.is_file())
    assert size <= 6e6, size
    assert sha256_file(LOCATED / "best.pt") == sha256_file(STABLE / "best.pt")
    reader, transition = planning_models(LOCATED)
    assert reader.bits == transition.bits == 12 and transition.net.cfg.location_bits == 4
    rules, model_hash = load_rules(LOCATED)
    assert model_hash == sha256_file(LOCATED / "transition.pt")[:16] and rules.bits == 12
    scene = Scene((ObjectState(ObjectType.CUBE, (*LOCATIONS[0], TABLE_TOP_Z + 0.05)),
                   ObjectState(ObjectType.CUBE, (*LOCATIONS[4], TABLE_TOP_Z + 0.05))))
    codes = scene_codes(sim, reader, scene)
    assert ((codes >> 1) & 7).tolist() == [0, 4] and (codes & 1).tolist() == [0, 0]  # locations 0 and 4, on them


@pytest.mark.parametrize("planner", ["astar-outcomes", "rules-outcomes"])
def test_located_run_builds_a_structure_in_simulation(tmp_path, planner):
    run = tmp_path / "run"
    shutil.copytree(LOCATED, run)
    rc, text = cli("plan", "--run", run, "--problem", PRETRAINED / "problems" / "cube_on_carried_stick.json",
                   "--planner", planner, "--closed-loop")
    assert rc == 0, text
    line = [ln for ln in text.splitlines() if ln.startswith("cube_on_carried_stick")][-1]
    assert "success True" in line and "failure None" in line, line
