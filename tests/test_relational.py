"""The relational model: location entities, learned unary and relational bits, its training and its probes."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from symlearn.learning.carrying import CARRY_PROBES, judge
from symlearn.learning.entities import location_crops, location_windows, project_to_pixels
from symlearn.learning.relational import RelationalConfig, RelationalDeepSym
from symlearn.learning.relation_probe import oracle_at, oracle_on, unary_properties
from symlearn.sim.camera import CameraConfig
from symlearn.world import LOCATIONS, ObjectType

from conftest import cli

C, S = ObjectType.CUBE, ObjectType.STICK


def _scene(sim, spec):
    sim.build(spec)
    obs = sim.observe()
    return obs, sim.get_scene()


def test_location_windows_sit_where_the_camera_sees_objects_at_the_locations(sim):
    # a cube dropped at each location: its crop (centred on its visible pixels) lies within 4 px of the window
    windows = location_windows(CameraConfig(), 64)
    for loc in range(6):
        obs, _ = _scene(sim, ((C, loc),))
        assert np.abs(obs.origins[0].astype(int) - windows[loc]).max() <= 4, (loc, obs.origins[0], windows[loc])


def test_projection_inverts_the_crop_rays():
    cam = CameraConfig()
    px = project_to_pixels(np.array([cam.target]), cam)[0]
    assert np.allclose(px, [cam.size / 2 - 0.5] * 2, atol=1e-6)  # the target is seen at the image centre


def test_location_crop_shows_what_stands_there(sim):
    obs, _ = _scene(sim, ((C, 4), (C, 0)))
    windows = location_windows(CameraConfig(), 64)
    crops = location_crops(obs.crops[None].astype(np.float16), obs.origins[None], np.array([2]), windows)[0]
    seen = (crops > 0).sum((1, 2))
    assert seen[4] > 200 and seen[0] > 200, seen
    assert seen[5] == 0 and seen[2] == 0, seen  # the far cells beside no object stay empty
    # the pasted pixels are the objects' own depths
    assert np.isclose(crops[4][crops[4] > 0].astype(np.float32).min(), obs.crops[0][obs.crops[0] > 0].min(), atol=2e-3)


def _model():
    torch.manual_seed(0)
    return RelationalDeepSym(RelationalConfig(conv_channels=(8, 8, 8, 8), feature_dim=16, hidden=16,
                                              decoder_hidden=(16,))).eval()


def test_symbols_at_evaluation_are_bits_and_at_is_one_location_per_object():
    m = _model()
    obj, loc = torch.rand(2, 4, 3, 64, 64), torch.rand(2, 6, 3, 64, 64)
    mask = torch.tensor([[1, 1, 1, 0], [1, 0, 0, 0]]).bool()
    out = m(obj, mask, loc, torch.tensor([3, 20]))
    assert set(out.relations.unique().tolist()) <= {0.0, 1.0}
    at = out.relations[:, 0, :4, 4:]
    assert at.sum(-1).tolist() == [[1, 1, 1, 0], [1, 0, 0, 0]]  # exactly one location per real object
    assert out.relations[1, :, 1:4].abs().sum() == 0 and out.relations[1, :, :, 1:4].abs().sum() == 0  # padding
    assert out.relations[:, 1:, torch.arange(4), torch.arange(4)].abs().sum() == 0  # no object relates to itself
    assert out.effect[1, 1:].abs().sum() == 0


def test_the_model_is_equivariant_to_the_order_of_objects():
    m = _model()
    obj, loc = torch.rand(1, 3, 3, 64, 64), torch.rand(1, 6, 3, 64, 64)
    mask, act = torch.ones(1, 3, dtype=torch.bool), torch.tensor([7])
    a = m(obj, mask, loc, act)
    perm = torch.tensor([2, 0, 1])
    b = m(obj[:, perm], mask, loc, act)
    assert torch.allclose(a.effect[:, perm], b.effect, atol=1e-5)
    assert torch.equal(a.codes[:, perm], b.codes)
    ent = torch.cat([perm, torch.arange(3, 9)])
    assert torch.equal(a.relations[:, :, ent][:, :, :, ent], b.relations)


def test_object_codes_do_not_see_where_an_object_is():
    # the same depth crop at another image position and 20 cm further from the camera: the unary code is the same
    # (it reads depth relative to the crop's nearest pixel only); the location relation may change
    m = _model()
    depth = torch.zeros(1, 1, 64, 64)
    depth[..., 20:40, 25:35] = 1.0 + torch.linspace(0, 0.05, 20)[:, None]
    pos = torch.stack(torch.meshgrid(torch.linspace(0, 0.25, 64), torch.linspace(0, 0.25, 64), indexing="xy"))
    a = torch.cat([depth, pos[None]], 1)[:, None]
    b = torch.cat([depth + 0.2 * (depth > 0), pos[None] + 0.5], 1)[:, None]
    loc = torch.rand(1, 6, 3, 64, 64)
    mask = torch.ones(1, 1, dtype=torch.bool)
    ca = m.symbols(a, mask, loc)[0]
    cb = m.symbols(b, mask, loc)[0]
    assert torch.equal(ca, cb)
    fa, fb = m.features(a, mask, loc), m.features(b, mask, loc)
    assert not torch.allclose(fa[:, 0], fb[:, 0])  # the relation heads do see it


def test_oracle_relations_of_the_probe_read_a_stack_and_a_rider(sim):
    _, scene = _scene(sim, ((S, 1), (C, 0), (C, 0)))  # two cubes stacked on the stick's left end
    pose = np.array([[list(o.position) + list(o.orientation) for o in scene.objects]], np.float32)
    types = np.array([[int(o.type) for o in scene.objects]])
    mask = np.ones((1, 3), bool)
    on = oracle_on(pose, types, mask)[0]
    assert on.tolist() == [[False, False, False], [True, False, False], [False, True, False]]
    at = oracle_at(pose, mask)[0]
    assert at[0].tolist() == [i == 1 for i in range(6)]
    assert at[1, 0] and at[2, 0]
    props = {name: v[0].tolist() for name, v in unary_properties(pose, types, mask).items()}
    assert props == {"stick": [True, False, False], "spans": [True, False, False], "on_object": [False, True, True],
                     "supports": [True, True, False], "far_row": [True, True, True]}


def test_carrying_verdicts():
    assert judge(np.array([0.0, 178.0, 0.0]), np.array([0.0, 180.0, 0.0]))["right"]
    assert not judge(np.array([0.0, 100.0, 0.0]), np.array([0.0, 180.0, 0.0]))["right"]  # a rider 80 mm short
    assert not judge(np.array([0.0, 266.0, 0.0]), np.array([0.0, 0.0, 0.0]))["right"]  # a false rider
    assert judge(np.array([5.0, -8.0, 40.0]), np.array([0.0, 0.0, 0.0]))["right"]  # still: horizontal only
    names = [p.name for p in CARRY_PROBES]
    assert len(set(names)) == len(names) and {"table1_case1", "table1_case2", "table1_case3"} <= set(names)
    for p in CARRY_PROBES:
        assert p.order is None or sorted(p.order) == list(range(len(p.spec)))
        assert all(0 <= loc < len(LOCATIONS) for _, loc in p.spec)


def test_probe_scenes_show_the_physics_they_name(sim):
    # the truth each probe relies on: riders move with the stick, the stack beside it does not
    from symlearn.learning.carrying import CARRY_PROBES as P

    want = {"table1_case2": [True, False, True], "stack_beside_near": [True, False, False],
            "stack_beside_far": [True, False, False], "stacked_on_end": [True, True, True]}
    for p in P:
        if p.name in want:
            sim.build(p.spec)
            eff = sim.step(p.action).effect
            assert [bool(np.linalg.norm(e[:2]) >= 0.1) for e in eff] == want[p.name], (p.name, eff)


def test_train_relations_trains_resumes_and_refuses_other_settings(tiny_data, tmp_path, capsys):
    out = tmp_path / "rel"
    rc, text = cli("train-relations", "--data", tiny_data.path, "--out", out, "--epochs", "1", "--threads", "1", "--quiet")
    assert rc == 0, text
    blob = torch.load(out / "relations.pt", map_location="cpu", weights_only=True)
    assert blob["epoch"] == 1 and blob["windows"].shape == (6, 2)
    metrics = json.loads((out / "relations_metrics.json").read_text())
    assert len(metrics["history"]) == 1 and np.isfinite(metrics["history"][0]["mae_mm"])
    rc, text = cli("train-relations", "--data", tiny_data.path, "--out", out, "--epochs", "2", "--threads", "1", "--quiet")
    assert rc == 0, text  # resumed: one more epoch
    assert [h["epoch"] for h in json.loads((out / "relations_metrics.json").read_text())["history"]] == [1, 2]
    rc, text = cli("train-relations", "--data", tiny_data.path, "--out", out, "--epochs", "2", "--seed", "3",
                   "--threads", "1", "--quiet")
    assert rc == 2 and "other settings" in capsys.readouterr().err
    rc, text = cli("train-relations", "--data", tmp_path / "nowhere", "--out", tmp_path / "r2", "--quiet")
    assert rc == 2 and "not a data set folder" in capsys.readouterr().err and not (tmp_path / "r2").exists()


def test_an_effect_only_run_fits_the_decoder_and_leaves_every_symbol_weight_as_it_was(tiny_data, tmp_path, capsys):
    from symlearn.learning.relational_training import RelationalTrainConfig

    base = tmp_path / "cover"
    rc, text = cli("train-relations", "--preset", "cover", "--data", tiny_data.path, "--out", base, "--epochs", "1",
                   "--threads", "1", "--quiet")
    assert rc == 0, text
    out = tmp_path / "effect"
    rc, text = cli("train-relations", "--preset", "effect", "--init", base, "--data", tiny_data.path, "--out", out,
                   "--epochs", "2", "--threads", "1", "--quiet")
    assert rc == 0, text
    before = torch.load(base / "relations.pt", map_location="cpu", weights_only=True)
    after = torch.load(out / "relations_last.pt", map_location="cpu", weights_only=True)
    effect = ("token.", "values.", "updates.", "norms.", "decoder.")
    changed = {n for n, w in before["model"].items() if not torch.equal(w, after["model"][n])}
    assert changed and all(n.startswith(effect) for n in changed), sorted(changed)
    # batch norm statistics too: the symbols a planner reads are computed by the same weights
    assert all(torch.equal(before["model"][n], after["model"][n]) for n in before["model"] if "running" in n)
    # no effect-only run without a model to start from, none that also shapes symbols
    rc, text = cli("train-relations", "--preset", "effect", "--data", tiny_data.path, "--out", tmp_path / "e2",
                   "--epochs", "1", "--threads", "1", "--quiet")
    assert rc == 2 and "give --init RUN" in capsys.readouterr().err and not (tmp_path / "e2").exists()
    with pytest.raises(ValueError, match="effect_only trains no symbol: grasp_weight must be 0"):
        RelationalTrainConfig.from_preset("effect", grasp_weight=1.0)


def test_the_stable_carry_preset_adds_the_code_stability_hinge_to_the_loss_and_the_cli_lists_every_preset(
        tiny_data, tmp_path):
    from symlearn.cli.relations import TRAIN_PRESET_NAMES
    from symlearn.learning.relational_training import TRAIN_PRESETS

    assert sorted(TRAIN_PRESET_NAMES) == sorted(TRAIN_PRESETS)
    base = tmp_path / "cover"
    rc, text = cli("train-relations", "--preset", "cover", "--data", tiny_data.path, "--out", base, "--epochs", "1",
                   "--threads", "1", "--quiet")
    assert rc == 0, text
    losses = {}
    for name in ("cover-carry", "cover-carry-stable"):  # the same start, seed and batches; only the hinge differs
        rc, text = cli("train-relations", "--preset", name, "--init", base, "--data", tiny_data.path, "--out",
                       tmp_path / name, "--epochs", "1", "--threads", "1", "--quiet")
        assert rc == 0, text
        metrics = json.loads((tmp_path / name / "relations_metrics.json").read_text())
        assert metrics["config"]["code_stability"] == (0.1 if name.endswith("stable") else 0.0)
        losses[name] = metrics["history"][0]["train_loss"]
    assert losses["cover-carry-stable"] > losses["cover-carry"]  # a hinge is never negative, and flips happen


def test_the_grasp_loss_pulls_the_held_object_to_the_pick_location_only():
    from symlearn.learning.relational_losses import grasp_loss

    k = 3
    logits = torch.zeros(2, 4, k + 6, k + 6, requires_grad=True)
    held, actions = torch.tensor([1, -1]), torch.tensor([4 * 6 + 2, 7])  # scene 0: object 1 held, picked at l4
    loss = grasp_loss(logits, held, actions, k)
    assert torch.isclose(loss, torch.log(torch.tensor(6.0)))  # uniform over 6 locations
    loss.backward()
    g = logits.grad
    assert g[0, 0, 1, k + 4] < 0 and (g[0, 0, 1, k:k + 4] > 0).all()  # raise l4, lower the others
    assert g[1].abs().sum() == 0 and g[0, 0, [0, 2]].abs().sum() == 0 and g[:, 1:].abs().sum() == 0
    assert grasp_loss(logits, torch.tensor([-1, -1]), actions, k) == 0


def test_the_cover_loss_marks_the_held_object_and_clears_an_empty_pick_and_says_nothing_else():
    from symlearn.learning.relational_losses import cover_loss

    k = 3
    logits = torch.zeros(3, 2, k + 6, k + 6, requires_grad=True)
    mask = torch.tensor([[1, 1, 1], [1, 1, 0], [1, 0, 0]]).bool()
    held, where = torch.tensor([1, -1, 0]), torch.tensor([4, 2, 0])  # scene 1: a pick at l2 lifted nothing
    loss = cover_loss(logits, held, where, mask)
    assert torch.isclose(loss, torch.log(torch.tensor(2.0)))  # every labelled pair at p = 0.5
    loss.backward()
    g = logits.grad
    assert g[0, 0, 1, k + 4] < 0 and g[2, 0, 0, k + 0] < 0  # the held object: raise at(o, where)
    assert (g[1, 0, :2, k + 2] > 0).all() and g[1, 0, 2].abs().sum() == 0  # empty pick: lower, padding untouched
    assert g[0, 0, [0, 2]].abs().sum() == 0 and g[0, 0, 1, k:k + 4].abs().sum() == 0  # nothing said of the rest
    assert g[:, 1].abs().sum() == 0
    assert cover_loss(logits, torch.tensor([-1, -1, -1]), where, torch.zeros(3, 3, dtype=torch.bool)) == 0


def test_a_cover_head_lets_an_object_hold_several_locations_and_starts_from_a_one_location_run():
    from symlearn.learning.relational import RelationalConfig, RelationalDeepSym
    from symlearn.symbolic.learned_state import atoms_of

    torch.manual_seed(0)
    model = RelationalDeepSym(RelationalConfig.from_preset("cover")).eval()
    with torch.no_grad():
        model.at_pair[-1].bias.fill_(50.0)  # every pair scores high: a cover says yes to all, a choice to one
    obj, loc, mask = torch.rand(1, 2, 3, 64, 64), torch.rand(1, 6, 3, 64, 64), torch.ones(1, 2, dtype=torch.bool)
    _, _, rel, _, _ = model.symbols(obj, mask, loc)
    assert rel[0, 0, :2, 2:].sum() == 12
    atoms = atoms_of(np.zeros((2, 8)), rel[0].numpy(), 2, support=True)
    assert {a for a in atoms if a[0] == "at" and a[1] == "o1"} == {("at", "o1", f"l{j}") for j in range(6)}
    one = RelationalDeepSym(RelationalConfig.from_preset("support")).eval()
    one.load_state_dict(model.state_dict())  # the same weights: a cover run may start from a one-location run
    _, _, rel1, _, _ = one.symbols(obj, mask, loc)
    assert (rel1[0, 0, :2, 2:].sum(-1) == 1).all()


def test_the_learned_route_end_to_end_exports_a_domain_and_benchmarks_closed_loop(tiny_data, tmp_path, capsys):
    import pddl

    run, problems = tmp_path / "rel", tmp_path / "problems"
    assert cli("train-relations", "--data", tiny_data.path, "--out", run, "--epochs", "1", "--threads", "1",
               "--quiet")[0] == 0
    rc, text = cli("export-learned", "--run", run, "--data", tiny_data.path, "--min-count", "1", "--threads", "1")
    assert rc == 0, capsys.readouterr().err
    report = json.loads((run / "learned" / "report.json").read_text())
    ops = json.loads((run / "learned" / "operators.json").read_text())
    assert report["operators"] == len(ops) and report["transitions"]["changed"] >= report["transitions"]["covered"]
    domain = pddl.parse_domain(run / "learned" / "domain.pddl")
    assert {a.name for a in domain.actions} == {o["name"] for o in ops}
    assert {p.name for p in domain.predicates} >= {"at"}
    assert cli("problems", "--out", problems, "--kind", "located-walks", "--n", "2", "--objects", "1-1",
               "--length", "1-1", "--seed", "3")[0] == 0
    out = tmp_path / "bench.json"
    rc, _ = cli("benchmark-learned", "--run", run, "--problems", problems, "--out", out, "--timeout", "5")
    assert rc == 0, capsys.readouterr().err
    res = json.loads(out.read_text())
    assert [r["k"] for r in res["results"]] == [1, 1]
    for r in res["results"]:
        assert isinstance(r["success"], bool) and r["stop"]
        assert r["success"] == (r["stop"] == "goal reached")
        assert len(r["plan_times_s"]) >= len(r["actions"])  # one planner call before every action
    assert res["summary"]["1-5"]["problems"] == 2
    before = out.read_bytes()
    assert cli("benchmark-learned", "--run", run, "--problems", problems, "--out", out, "--timeout", "5")[0] == 0
    assert json.loads(out.read_bytes())["results"] == json.loads(before)["results"]  # resumed: nothing rerun
    rc, _ = cli("benchmark-learned", "--run", run, "--problems", problems, "--out", out, "--timeout", "7")
    assert rc == 2 and "other settings" in capsys.readouterr().err and out.read_bytes() == before


def test_the_ride_loss_reads_r1_of_every_object_against_the_held_one():
    from symlearn.learning.relational_losses import ride_loss

    k = 3
    logits = torch.zeros(1, 4, k + 6, k + 6, requires_grad=True)
    mask = torch.tensor([[True, True, True]])
    rider = torch.tensor([[False, False, True]])  # object 2 rode on the held object 0; object 1 stayed
    ride_loss(logits, torch.tensor([0]), rider, mask).backward()
    g = logits.grad[0, 1]
    assert g[2, 0] < 0 and g[1, 0] > 0  # raise r1(2, 0), lower r1(1, 0)
    assert g[0, 0] == 0 and logits.grad.abs().sum() == g[1, 0].abs() + g[2, 0].abs()


def test_the_ride_loss_puts_what_stayed_at_the_pick_location_under_the_held_object():
    from symlearn.learning.relational_losses import ride_loss

    k = 3
    logits = torch.zeros(1, 4, k + 6, k + 6, requires_grad=True)
    at = torch.zeros(1, k + 6, k + 6)
    at[0, 0, k + 4] = at[0, 1, k + 4] = at[0, 2, k + 1] = 1  # objects 0 and 1 at l4, object 2 at l1
    mask, rider = torch.ones(1, 3, dtype=torch.bool), torch.zeros(1, 3, dtype=torch.bool)
    ride_loss(logits, torch.tensor([0]), rider, mask, at, torch.tensor([4 * 6 + 2])).backward()
    g = logits.grad[0, 1]
    assert g[0, 1] < 0  # object 0 was picked at l4 and object 1 stayed there: r1(0, 1), "0 rests on 1", raised
    assert g[0, 2] == 0  # object 2 stood elsewhere: no claim about r1(0, 2)
    assert g[1, 0] > 0 and g[2, 0] > 0  # neither rode along: r1(1, 0) and r1(2, 0) lowered


def test_the_exclusion_spares_an_object_seen_to_carry_two_riders_and_no_other():
    from symlearn.learning.relational_losses import support_exclusion
    from symlearn.learning.relational_training import carriers

    k = 3
    logits = torch.full((2, 2, k + 6, k + 6), -9.0)
    logits[:, 1, 1, 0] = logits[:, 1, 2, 0] = 9.0  # in both scenes objects 1 and 2 rest on object 0
    mask = torch.ones(2, k, dtype=torch.bool)
    held = torch.tensor([0, 0])
    rider = torch.tensor([[False, True, True], [False, True, False]])  # scene 0: both rode; scene 1: one did
    spared = carriers(held, rider)
    assert spared.tolist() == [[True, False, False], [False, False, False]]
    assert carriers(torch.tensor([-1]), torch.tensor([[False, True, True]])).sum() == 0  # nothing held
    whole = float(support_exclusion(logits, mask))
    assert whole == pytest.approx(2 * 1.0 / 6, abs=1e-3)  # (2 - 1)^2 per scene over 6 objects
    assert float(support_exclusion(logits, mask, spared)) == pytest.approx(whole / 2, abs=1e-3)


SHIPPED = Path(__file__).resolve().parents[1] / "pretrained" / "relations"


def test_the_shipped_model_places_a_cube_at_the_location_it_stands_at(sim):
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import observe_atoms

    model, blob = load_relational(SHIPPED)
    for loc in range(6):
        sim.build(((C, loc),))
        atoms = observe_atoms(sim, model, blob)
        assert ("at", "o1", f"l{loc}") in atoms, (loc, sorted(atoms))
        assert {a for a in atoms if a[0] == "empty"} == {("empty", f"l{j}") for j in range(6) if j != loc}
    sim.build(((C, 3), (C, 3)))  # a stack: both cubes at l3, nothing else
    atoms = observe_atoms(sim, model, blob)
    assert {a for a in atoms if a[0] == "at"} == {("at", "o1", "l3"), ("at", "o2", "l3")}


def test_a_problem_written_by_hand_from_the_docs_is_solved_by_stock_planners():
    # docs/RELATIONS.md: objects, their `at` facts, the empty locations and a goal of `at` facts; no static facts
    from search.classical import solve_pddl
    from search.stock_planners import solve_texts

    domain = (SHIPPED / "learned" / "domain.pddl").read_text()
    problem = """(define (problem swap) (:domain learned-relations)
  (:objects a b - item)
  (:init (at a l0) (at b l3) (empty l1) (empty l2) (empty l4) (empty l5))
  (:goal (and (at a l3) (at b l0))))"""
    plans = {p: solve_texts(domain, problem, p, 60.0) for p in ("fd-lama-first", "fd-lmcut")}
    plans["up-pyperplan"] = solve_pddl(domain, problem, "pyperplan", 60.0)  # stock pyperplan's parser has no `=`
    for name, res in plans.items():
        assert res.status.name == "SOLVED", (name, res.message)
    # the optimal plan uses move-12, a swap of two objects the data showed 63 times (docs/RELATIONS.md: an artefact of
    # the learned `at` when a stick's end covers a cell); lama may make room instead; neither is longer than 3 moves
    assert [s.split()[0] for s in plans["fd-lmcut"].steps] == ["(move-12"]
    assert all(len(r.steps) <= 3 for r in plans.values())
    up = solve_pddl(domain, problem, "fast-downward", 60.0)
    assert up.status.name == "SOLVED" and 1 <= len(up.steps) <= 3, up.message  # UP's validator accepted it


def test_the_learned_commands_refuse_bad_input_in_one_line(tmp_path, capsys):
    rc, _ = cli("benchmark-learned", "--run", SHIPPED, "--problems", tmp_path, "--out", tmp_path / "b.json",
                "--timeout", "-1")
    err = capsys.readouterr().err
    assert rc == 2 and "timeout_s=-1" in err and len(err.strip().splitlines()) == 1 and not (tmp_path / "b.json").exists()
    from symlearn.planning.learned_loop import LearnedLoopConfig

    with pytest.raises(ValueError, match="unknown planner 'lama'"):
        LearnedLoopConfig(planner="lama")
    with pytest.raises(ValueError, match="unary must be each, first or seen; got 'all'"):
        LearnedLoopConfig(unary="all")
    with pytest.raises(ValueError, match="shorten_s=-1"):
        LearnedLoopConfig(shorten_s=-1)
    rc, _ = cli("benchmark-learned", "--run", SHIPPED, "--problems", tmp_path, "--out", tmp_path / "b.json",
                "--planner", "lama")
    err = capsys.readouterr().err
    assert rc == 2 and "unknown planner 'lama'; known: fd-lama-first, fd-lmcut" in err and len(err.strip().splitlines()) == 1
    rc, _ = cli("export-learned", "--run", tmp_path, "--data", tmp_path)
    err = capsys.readouterr().err
    assert rc == 2 and "relations.pt" in err and not (tmp_path / "learned").exists()
    rc, _ = cli("benchmark-learned", "--run", tmp_path, "--problems", tmp_path, "--out", tmp_path / "b.json")
    assert rc == 2 and "export-learned" in capsys.readouterr().err
    (tmp_path / "relations.pt").write_bytes(b"not a checkpoint")
    rc, _ = cli("export-learned", "--run", tmp_path, "--data", tmp_path)
    err = capsys.readouterr().err
    assert rc == 2 and "relations.pt is not a readable checkpoint" in err and len(err.strip().splitlines()) == 1


def test_benchmark_learned_reads_its_loop_settings_from_the_file_and_the_flags_win(tmp_path, capsys):
    from symlearn.cli.main import build_parser
    from symlearn.cli.relations import loop_config
    from symlearn.planning.learned_loop import LearnedLoopConfig

    def parse(*flags):
        return build_parser().parse_args(["benchmark-learned", "--run", "R", "--problems", "P", "--out", "O",
                                          *map(str, flags)])

    assert loop_config(parse()) == LearnedLoopConfig()
    # the ablation's file (docs/RELATIONS.md), with the goal relations and the planner given as flags
    cfg = loop_config(parse("--config", "pretrained/relations_carry/drop_relations.toml", "--goal-relations", "on",
                            "--planner", "fd-lama-first"))
    assert (cfg.drop, cfg.goal_relations, cfg.relax_unreachable, cfg.planner, cfg.timeout_s, cfg.shorten_s) == (
        ("on", "clear", "on-table"), ("on",), True, "fd-lama-first", 10.0, 2.0)
    cfg = loop_config(parse("--config", "pretrained/relations_carry/drop_preconditions.toml"))
    assert (cfg.drop, cfg.drop_preconditions) == ((), ("at", "on", "clear", "on-table", "empty"))
    loop = tmp_path / "loop.toml"
    loop.write_text('[learned_loop]\nunary = "first"\nshorten_s = 0\ntimeout_s = 5\nplanner = "fd-lama-first"\n')
    cfg = loop_config(parse("--config", loop, "--timeout", "3"))  # the flag wins over the file's timeout_s
    assert (cfg.unary, cfg.shorten_s, cfg.timeout_s, cfg.planner, cfg.goal_relations) == ("first", 0.0, 3.0,
                                                                                          "fd-lama-first", ())
    for text, said in (("shorten = 1", "[learned_loop] has no setting 'shorten'"),
                       ('unary = "all"', "[learned_loop] unary: unary must be each, first or seen; got 'all'"),
                       ("shorten_s = -1", "[learned_loop] shorten_s: shorten_s=-1")):
        loop.write_text(f"[learned_loop]\n{text}\n")
        rc, _ = cli("benchmark-learned", "--run", SHIPPED, "--problems", tmp_path, "--out", tmp_path / "b.json",
                    "--config", loop)
        err = capsys.readouterr().err
        assert rc == 2 and said in err and str(loop) in err and len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / "b.json").exists()
    # an ablation of a predicate the domain lacks would change nothing: refused, naming the domain's file
    loop.write_text('[learned_loop]\ndrop_preconditions = ["at", "bogus"]\n')
    rc, _ = cli("benchmark-learned", "--run", SHIPPED_CARRY, "--problems", tmp_path, "--out", tmp_path / "b.json",
                "--config", loop)
    err = capsys.readouterr().err
    assert rc == 2 and "drop_preconditions names 'bogus'" in err and "relations_carry/learned/operators.json" in err, err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "b.json").exists()


def _support_model() -> RelationalDeepSym:
    torch.manual_seed(0)
    return RelationalDeepSym(RelationalConfig(conv_channels=(8, 8, 8, 8), feature_dim=16, hidden=16,
                                              decoder_hidden=(16,), n_relations=1, rounds=3, support=True)).eval()


def test_the_rests_on_head_picks_at_most_one_support_among_real_objects():
    m = _support_model()
    obj, loc = torch.rand(3, 4, 3, 64, 64), torch.rand(3, 6, 3, 64, 64)
    mask = torch.tensor([[1, 1, 1, 0], [1, 0, 0, 0], [1, 1, 1, 1]]).bool()
    with torch.no_grad():
        m.table.bias.fill_(-50.0)  # the table scores far below any object: every object rests on another one
        on = m(obj, mask, loc, torch.tensor([3, 20, 0])).relations[:, 1, :4, :4]
    assert on.sum(-1).tolist() == [[1, 1, 1, 0], [0, 0, 0, 0], [1, 1, 1, 1]]  # a lone object has only the table
    assert on[0, :, 3].sum() == 0 and on[:, torch.arange(4), torch.arange(4)].abs().sum() == 0
    with torch.no_grad():
        m.table.bias.fill_(50.0)
        on = m(obj, mask, loc, torch.tensor([3, 20, 0])).relations[:, 1]
    assert on.sum() == 0  # all on the table


def test_the_support_loss_reads_what_the_grasp_showed():
    from symlearn.learning.relational_losses import support_loss

    k = 4
    logits = torch.zeros(1, 2, k + 6, k + 6, requires_grad=True)
    at = torch.zeros(1, k + 6, k + 6)
    at[0, 0, k + 4] = at[0, 1, k + 4] = at[0, 2, k + 1] = at[0, 3, k + 1] = 1  # 0 and 1 at l4; 2 and 3 at l1
    mask = torch.ones(1, k, dtype=torch.bool)
    rider = torch.tensor([[False, False, True, False]])  # 0 held at l4; 2 rode along; 1 and 3 stayed
    support_loss(logits, torch.tensor([0]), rider, mask, at, torch.tensor([4 * 6 + 2])).backward()
    g = logits.grad[0, 1]
    assert g[0, 1] < 0 and g[0, 0] > 0 and g[0, 2] > 0  # the held object rests on what stayed at l4, not the table
    assert g[2, 0] < 0 and g[2, 2] > 0  # the rider rests on the held object, not on the table
    assert g[1, 0] > 0 and g[3, 2] > 0 and g[3, 0] > 0  # what did not ride rests on neither the held object nor a rider
    assert logits.grad[0, 0].abs().sum() == 0  # at(o, l) is not touched
    lone = torch.zeros(1, 2, k + 6, k + 6, requires_grad=True)  # nothing else at the pick location: the table
    at[0, 3, k + 1], at[0, 3, k + 5] = 0, 1  # 3 moved to l5: 2 stands alone at l1
    support_loss(lone, torch.tensor([2]), torch.zeros(1, k, dtype=torch.bool), mask, at, torch.tensor([1 * 6])).backward()
    assert lone.grad[0, 1, 2, 2] < 0 and (lone.grad[0, 1, 2, [0, 1]] > 0).all()


def test_a_rests_on_head_is_written_as_on_clear_and_on_table():
    from symlearn.symbolic.learned_state import atoms_of

    k = 3
    rel = np.zeros((2, k + 6, k + 6))
    rel[0, 0, k + 2] = rel[0, 1, k + 2] = rel[0, 2, k + 5] = 1  # o1 and o2 at l2, o3 at l5
    rel[1, 0, 1] = 1  # o1 rests on o2
    atoms = atoms_of(np.zeros((k, 8)), rel, k, support=True)
    assert {a for a in atoms if a[0] in ("on", "clear", "on-table")} == {
        ("on", "o1", "o2"), ("clear", "o1"), ("clear", "o3"), ("on-table", "o2"), ("on-table", "o3")}
    assert ("r1", "o1", "o2") in atoms_of(np.zeros((k, 8)), rel, k)  # a free head keeps its neutral name


def test_the_post_support_loss_puts_the_released_object_on_what_stood_there_and_keeps_the_rest():
    from symlearn.learning.relational_losses import post_support_loss

    k = 3
    pre = torch.zeros(1, 2, k + 6, k + 6)
    pre[0, 1, 1, 1] = 5.0  # before: object 1 surely on the table
    post = torch.zeros(1, 2, k + 6, k + 6, requires_grad=True)
    at = torch.zeros(1, k + 6, k + 6)
    at[0, 0, k + 2] = at[0, 2, k + 2] = at[0, 1, k + 0] = 1  # after: 0 and 2 at l2, 1 at l0
    mask, rider = torch.ones(1, k, dtype=torch.bool), torch.zeros(1, k, dtype=torch.bool)
    post_support_loss(pre, post, torch.tensor([0]), rider, mask, at, torch.tensor([4 * 6 + 2])).backward()
    g = post.grad[0, 1]
    assert g[0, 2] < 0 and g[0, 0] > 0 and g[0, 1] > 0  # released at l2 onto object 2, the one standing there
    assert g[1, 1] < 0  # object 1 stays on the table, as before
    nothing = torch.zeros(1, 2, k + 6, k + 6, requires_grad=True)  # nothing held: every support persists
    post_support_loss(pre, nothing, torch.tensor([-1]), rider, mask, at, torch.tensor([7])).backward()
    assert nothing.grad[0, 1, 1, 1] < 0 and nothing.grad[0, 1, 0].abs().sum() < 1e-6  # 0 stays as uncertain as it was


SHIPPED_ON = Path(__file__).resolve().parents[1] / "pretrained" / "relations_on"


def test_the_shipped_rests_on_model_orders_a_tower_and_finds_the_top(sim):
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import observe_atoms

    model, blob = load_relational(SHIPPED_ON)
    sim.build(((C, 3), (C, 3), (C, 3), (C, 0)))  # a tower of three at l3, a lone cube at l0
    atoms = observe_atoms(sim, model, blob)
    heights = [o.position[2] for o in sim.get_scene().objects]
    order = sorted(range(3), key=lambda i: heights[i])  # bottom, middle, top, as the simulator placed them
    o = [f"o{i + 1}" for i in order]
    assert {a for a in atoms if a[0] == "on"} == {("on", o[1], o[0]), ("on", o[2], o[1])}, sorted(atoms)
    assert {a for a in atoms if a[0] == "clear"} == {("clear", o[2]), ("clear", "o4")}
    assert {a for a in atoms if a[0] == "on-table"} == {("on-table", o[0]), ("on-table", "o4")}
    assert {a for a in atoms if a[0] == "at"} == {("at", x, "l3") for x in o} | {("at", "o4", "l0")}


def test_a_four_cube_tower_is_stated_and_built_by_stock_fast_downward_in_simulation(sim):
    from symlearn.export.learned_export import load_operators
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import LearnedLoopConfig, run_learned
    from symlearn.problems.problem import Problem

    model, blob = load_relational(SHIPPED_ON)
    spec = ((C, 0), (C, 1), (C, 2), (C, 4))
    sim.build(spec)
    initial = sim.get_scene()
    sim.build(((C, 5), (C, 5), (C, 5), (C, 5)))  # the goal: all four in one tower at l5, o1 at the bottom
    problem = Problem("tower4", 0, spec, initial, (0 * 6 + 5, 1 * 6 + 5, 2 * 6 + 5, 4 * 6 + 5), sim.get_scene(),
                      task="tower-4")
    # stated by hand, as docs/RELATIONS.md writes it (read from the goal scene, the rests-on head misreads a tower
    # of four, which the data hardly show: the top on the second)
    goal = frozenset({("at", "o1", "l5"), ("on", "o2", "o1"), ("on", "o3", "o2"), ("on", "o4", "o3")})
    res = run_learned(sim, model, blob, load_operators(SHIPPED_ON), problem, LearnedLoopConfig(), goal)
    assert res.success, (res.stop, res.actions)  # the simulator's verdict: every cube where the goal scene has it
    assert len(res.actions) == 4  # one pick-and-place a cube


def test_the_loop_keeps_a_plan_while_each_scene_is_the_one_it_predicted(sim):
    # execution monitoring (LearnedLoopConfig.monitor): the carry model builds the tower of four from one planner
    # call, each scene after a step read as the domain predicted; planning at every step calls the planner 4 times
    from symlearn.export.learned_export import load_operators
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import LearnedLoopConfig, run_learned
    from symlearn.problems.problem import Problem

    model, blob = load_relational(SHIPPED_CARRY)
    ops = load_operators(SHIPPED_CARRY)
    spec = ((C, 0), (C, 1), (C, 2), (C, 4))
    sim.build(spec)
    initial = sim.get_scene()
    sim.build(((C, 5), (C, 5), (C, 5), (C, 5)))
    problem = Problem("tower4", 0, spec, initial, (0 * 6 + 5, 1 * 6 + 5, 2 * 6 + 5, 4 * 6 + 5), sim.get_scene(),
                      task="tower-4")
    goal = frozenset({("at", "o1", "l5"), ("on", "o2", "o1"), ("on", "o3", "o2"), ("on", "o4", "o3")})
    kept = run_learned(sim, model, blob, ops, problem, LearnedLoopConfig(monitor=True), goal)
    assert kept.success and kept.actions == [5, 11, 17, 29], (kept.stop, kept.actions)
    assert len(kept.plan_times_s) == 1 and kept.kept_steps == 3
    every = run_learned(sim, model, blob, ops, problem, LearnedLoopConfig(monitor=False), goal)
    assert every.success and every.actions == kept.actions and len(every.plan_times_s) == 4 and every.kept_steps == 0


def test_a_tower_written_by_hand_for_the_rests_on_domain_is_solved_by_stock_planners():
    # docs/RELATIONS.md: items, where each stands, what rests on what, the empty locations, and the one unary bit the
    # domain's unstacking operators read: (u4 c), without which d cannot be taken off c
    from search.classical import solve_pddl
    from search.stock_planners import solve_texts

    domain = (SHIPPED_ON / "learned" / "domain.pddl").read_text()
    problem = """(define (problem tower) (:domain learned-relations)
  (:objects a b c d - item)
  (:init (at a l0) (at b l1) (at c l2) (at d l2) (on d c) (u4 c)
         (on-table a) (on-table b) (on-table c) (clear a) (clear b) (clear d) (empty l3) (empty l4) (empty l5))
  (:goal (and (at a l4) (on b a) (on c b) (on d c))))"""
    plans = {p: solve_texts(domain, problem, p, 60.0) for p in ("fd-lama-first", "fd-lmcut")}
    plans["up-pyperplan"] = solve_pddl(domain, problem, "pyperplan", 60.0)  # stock pyperplan's parser has no `=`
    for name, res in plans.items():
        assert res.status.name == "SOLVED", (name, res.message)
    # optimal: a to l4, b onto a, d off c, c onto b, d onto c
    assert len(plans["fd-lmcut"].steps) == 5 and all(len(r.steps) >= 5 for r in plans.values())
    up = solve_pddl(domain, problem, "fast-downward", 60.0)
    assert up.status.name == "SOLVED" and len(up.steps) >= 5, up.message  # UP's validator accepted it


def test_the_tower_docs_domain_md_writes_for_the_learned_domain_is_solved_as_it_says():
    # docs/DOMAIN.md, "writing a problem by hand": its problem text, read from the file, on the shipped carry domain
    import re

    from search.stock_planners import solve_texts

    doc = (Path(__file__).resolve().parents[1] / "docs" / "DOMAIN.md").read_text()
    problem = re.search(r"\(define \(problem tower4\).*?\n```", doc, re.S).group(0)[:-4]
    domain = (SHIPPED_CARRY / "learned" / "domain.pddl").read_text()
    for planner in ("fd-lama-first", "fd-lmcut"):
        res = solve_texts(domain, problem, planner, 60.0)
        assert res.status.name == "SOLVED", (planner, res.message)
        assert [step.strip("()").split()[0] for step in res.steps] == ["move-0", "move-1", "move-1", "move-1"]
        assert res.steps[0].strip("()").split()[1:] == ["l0", "a", "l5"]


def test_the_carry_domain_without_equality_is_read_by_stock_pyperplan_and_plans_as_with_it():
    # export-learned-problems --no-equality: docs/DOMAIN.md's tower in plain typed STRIPS, (differ ?a ?b) and
    # (same ?to l1) stated as static facts; stock pyperplan, whose parser takes no `=`, refuses the domain as shipped
    # and solves this one, and LM-cut finds the same shortest plan on both
    import re

    from pddl_export.learned_domain import domain_pddl, predicates_of, problem_pddl
    from search.stock_planners import solve_texts
    from symlearn.export.learned_export import load_operators

    doc = (Path(__file__).resolve().parents[1] / "docs" / "DOMAIN.md").read_text()
    problem = re.search(r"\(define \(problem tower4\).*?\n```", doc, re.S).group(0)[:-4]
    objects = re.search(r"\(:objects ([^-]+)- item\)", problem).group(1).split()
    init_text, goal_text = problem.split("(:goal")
    atoms = lambda text: [tuple(a.split()) for a in re.findall(r"\(([^():]+)\)", text) if a.split()[0] != "and"]  # noqa: E731
    ops = load_operators(SHIPPED_CARRY)
    domain = (SHIPPED_CARRY / "learned" / "domain.pddl").read_text()
    plain = domain_pddl(ops, equality=False)
    plain_problem = problem_pddl("tower4", objects, atoms(init_text.split("(:init")[1]), atoms(goal_text),
                                 predicates_of(ops), equality=False)
    assert "(= " not in plain and ":equality" not in plain and plain.count("(differ ?") > 50
    assert "(differ a b)" in plain_problem and "(differ l0 l5)" in plain_problem and "(same l3 l3)" in plain_problem
    assert "(differ a a)" not in plain_problem and "(same l0 l1)" not in plain_problem
    refused = solve_texts(domain, problem, "pyperplan", 60.0)
    assert refused.status.name == "ERROR", refused.status
    read = solve_texts(plain, plain_problem, "pyperplan", 120.0)
    assert read.status.name == "SOLVED" and len(read.steps) >= 4, read.message
    shortest = [solve_texts(d, p, "fd-lmcut", 60.0) for d, p in ((domain, problem), (plain, plain_problem))]
    assert all(r.status.name == "SOLVED" for r in shortest)
    assert shortest[0].steps == shortest[1].steps and len(shortest[0].steps) == 4
    import dataclasses

    clash = [dataclasses.replace(ops[0], precondition=(*ops[0].precondition, ("same", "?o1")))]
    with pytest.raises(ValueError, match="already name a predicate 'same'"):
        domain_pddl(clash, equality=False)


@pytest.mark.parametrize("run", ["relations_on", "relations_cover", "relations_carry"])
def test_exported_learned_problems_are_solvable_wherever_the_simulator_reaches_the_goal(run, tmp_path, capsys):
    # a sample of fresh located walks, read by a shipped model (rests-on, cover) and written as PDDL problems: every
    # goal the simulator reaches (its shortest plan is known) is solved by stock lama-first and LM-cut on the folder's
    # domain, LM-cut's plans no longer than the simulator's shortest but by a misread, the folder re-reads as it was
    # written, and a focus problem's plan is one of the whole problem
    import pddl as pddl_lib

    shipped = Path(__file__).resolve().parents[1] / "pretrained" / run

    from search.stock_planners import solve_files

    rc, _ = cli("problems", "--out", tmp_path / "walks", "--kind", "located-walks", "--n", "6", "--objects", "1-4",
                "--length", "1-3", "--seed", "11")
    assert rc == 0
    out = tmp_path / "lp"
    rc, printed = cli("export-learned-problems", "--run", shipped, "--problems", tmp_path / "walks", "--out", out,
                      "--goal-relations", "on", "--focus")
    assert rc == 0 and printed.startswith("6 problems written")
    man = json.loads((out / "problems.json").read_text())
    assert man["goal_relations"] == ["on"] and len(man["rows"]) == 6 and man["focus"] is True
    focused = [r for r in man["rows"] if "focus_file" in r]
    assert focused and sorted(p.name for p in (out / "focus").iterdir()) == sorted(
        Path(r["focus_file"]).name for r in focused)
    domain = pddl_lib.parse_domain(out / "domain.pddl")
    assert {p.name for p in domain.predicates} >= {"at", "on", "clear", "on-table", "empty"}
    for row in man["rows"]:
        problem = pddl_lib.parse_problem(out / row["file"])
        assert len(problem.objects) == row["k"]  # o1..ok, the locations are the domain's constants
        walks = json.loads((tmp_path / "walks" / f"{row['name']}.json").read_text())
        assert row["shortest"] is not None and row["shortest"] <= len(walks["actions"])
        for planner in ("fd-lama-first", "fd-lmcut"):
            res = solve_files(out / "domain.pddl", out / row["file"], planner, 60.0)
            assert res.status.name == "SOLVED", (row["name"], planner, res.message)
        assert 1 <= len(res.steps) <= row["shortest"] + 1, (row["name"], res.steps)
        if "focus_file" in row:  # fewer objects, and each plan of it a plan of the whole problem (UP's validator)
            few = pddl_lib.parse_problem(out / row["focus_file"])
            assert {o.name for o in few.objects} == set(row["focus_objects"]) and len(few.objects) < row["k"]
            plan = solve_files(out / "domain.pddl", out / row["focus_file"], "fd-lmcut", 60.0)
            assert plan.status.name == "SOLVED", (row["name"], plan.message)
            _assert_valid(out / "domain.pddl", out / row["file"], plan.steps)
    # --no-equality: the same problems in plain typed STRIPS, which stock pyperplan reads and solves
    plain = tmp_path / "plain"
    assert cli("export-learned-problems", "--run", shipped, "--problems", tmp_path / "walks", "--out", plain,
               "--goal-relations", "on", "--no-equality")[0] == 0
    assert json.loads((plain / "problems.json").read_text())["equality"] is False
    assert "(= " not in (plain / "domain.pddl").read_text() and "(differ ?" in (plain / "domain.pddl").read_text()
    for row in man["rows"]:
        res = solve_files(plain / "domain.pddl", plain / row["file"], "pyperplan", 60.0)
        assert res.status.name == "SOLVED", (row["name"], res.message)
    # never over an existing folder, and a relation no operator reads is refused, both in one line
    capsys.readouterr()
    rc, _ = cli("export-learned-problems", "--run", shipped, "--problems", tmp_path / "walks", "--out", out)
    err = capsys.readouterr().err
    assert rc == 2 and f"{out} exists" in err and len(err.strip().splitlines()) == 1
    rc, _ = cli("export-learned-problems", "--run", shipped, "--problems", tmp_path / "walks",
                "--out", tmp_path / "lp2", "--goal-relations", "r7")
    err = capsys.readouterr().err
    assert rc == 2 and "r7" in err and "operators.json" in err and not (tmp_path / "lp2").exists()


def _assert_valid(domain: Path, problem: Path, steps) -> None:
    """unified-planning's validator accepts the plan on the problem."""
    from unified_planning.engines import ValidationResultStatus
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import PlanValidator

    reader = PDDLReader()
    whole = reader.parse_problem(str(domain), str(problem))
    plan = reader.parse_plan_string(whole, "\n".join(steps))
    with PlanValidator(problem_kind=whole.kind, plan_kind=plan.kind) as validator:
        assert validator.validate(whole, plan).status == ValidationResultStatus.VALID, (problem, steps)


SHIPPED_COVER = Path(__file__).resolve().parents[1] / "pretrained" / "relations_cover"


def test_the_shipped_cover_model_reads_every_cell_a_stick_spans_and_one_for_a_cube(sim):
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import observe_atoms

    model, blob = load_relational(SHIPPED_COVER)
    spans = {0: {0, 1}, 1: {0, 1, 2}, 2: {1, 2}, 3: {3}, 4: {4}, 5: {5}}  # a 40 cm stick in the far row (18 cm apart)
    for loc, cells in spans.items():
        for kind, want in ((S, cells), (C, {loc})):
            sim.build(((kind, loc),))
            atoms = observe_atoms(sim, model, blob)
            assert {a for a in atoms if a[0] == "at"} == {("at", "o1", f"l{j}") for j in want}, (kind, loc)
            assert {a for a in atoms if a[0] == "empty"} == {("empty", f"l{j}") for j in range(6) if j not in want}
    sim.build(((S, 1), (C, 0)))  # a cube on the stick's end over l0: a pick there meets the cube, not the stick
    atoms = observe_atoms(sim, model, blob)
    assert {a for a in atoms if a[0] in ("at", "on")} == {("at", "o1", "l1"), ("at", "o1", "l2"), ("at", "o2", "l0"),
                                                          ("on", "o2", "o1")}


def test_the_cover_domain_moves_a_stick_into_the_far_row_in_simulation(sim):
    from symlearn.export.learned_export import load_operators
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import LearnedLoopConfig, run_learned
    from symlearn.problems.problem import Problem

    # the one-location model read a far-row stick one cell off (l1 as l0), so the goal named the wrong cell
    model, blob = load_relational(SHIPPED_COVER)
    for start, goal_at in ((3, 1), (5, 0)):
        sim.build(((S, start),))
        initial = sim.get_scene()
        sim.build(((S, goal_at),))
        problem = Problem(f"stick{start}{goal_at}", 0, ((S, start),), initial, (start * 6 + goal_at,), sim.get_scene(),
                          task="stick")
        res = run_learned(sim, model, blob, load_operators(SHIPPED_COVER), problem,
                          LearnedLoopConfig(goal_relations=("on",), relax_unreachable=True))
        assert res.success, (start, goal_at, res.stop, res.actions)  # the simulator's verdict: the stick's pose
        assert len(res.actions) <= 2


def test_a_cube_put_on_a_near_row_tower_is_built_though_its_top_reads_over_two_cells(sim):
    from symlearn.export.learned_export import load_operators
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import LearnedLoopConfig, goal_atoms, run_learned
    from symlearn.problems.problem import Problem
    from symlearn.world import Action

    # problem 3 of problems/rel_dev68: the cube on the stick at l5 goes on top of the three-cube tower at l4; the
    # goal scene reads that top at l4 and l5, and no release adds two cells: the tower's own cells fix it
    model, blob = load_relational(SHIPPED_COVER)
    spec = ((C, 4), (C, 3), (C, 5), (C, 4), (C, 4), (S, 5), (C, 3), (C, 5))
    sim.build(spec)
    initial = sim.get_scene()
    sim.step(Action(5, 4))
    problem = Problem("tower", 0, spec, initial, (34,), sim.get_scene(), task="tower")
    assert {("at", "o8", "l4"), ("at", "o8", "l5")} <= observe_atoms_of_goal(sim, model, blob, problem)
    goal = goal_atoms(sim, model, blob, problem, ("on",))
    assert {a for a in goal if a[1] == "o8"} == {("at", "o8", "l4"), ("on", "o8", "o5")}
    res = run_learned(sim, model, blob, load_operators(SHIPPED_COVER), problem,
                      LearnedLoopConfig(goal_relations=("on",), relax_unreachable=True))
    assert res.success and res.actions == [34], (res.stop, res.actions)


def test_a_cube_beside_a_far_row_stick_stays_on_the_table_in_simulation(sim):
    from symlearn.export.learned_export import load_operators
    from symlearn.learning.relational_training import load_relational
    from symlearn.planning.learned_loop import LearnedLoopConfig, goal_atoms, run_learned
    from symlearn.problems.problem import Problem
    from symlearn.world import Action

    # the stick let go at l2 covers l1 and l2; a cube on the table at l0 beside it. A stick let go at l1 with the cube
    # on its end over l0 reads the same cells (a pick at l0 meets the cube): only the goal's on-table atoms tell them
    # apart, and without them LM-cut's shortest plan builds the other scene and believes the goal reached
    model, blob = load_relational(SHIPPED_COVER)
    ops = load_operators(SHIPPED_COVER)
    spec = ((C, 4), (C, 5), (S, 3))
    sim.build(spec)
    initial = sim.get_scene()
    sim.step(Action(3, 2))
    sim.step(Action(5, 0))
    problem = Problem("beside", 0, spec, initial, (20, 30), sim.get_scene(), task="beside")
    goal = goal_atoms(sim, model, blob, problem, ("on",))
    assert {("at", "o3", "l1"), ("at", "o3", "l2"), ("at", "o2", "l0"), ("on-table", "o2")} <= goal
    cfg = LearnedLoopConfig(goal_relations=("on",), relax_unreachable=True)
    res = run_learned(sim, model, blob, ops, problem, cfg)
    assert res.success and len(res.actions) == 2, (res.stop, res.actions)
    res = run_learned(sim, model, blob, ops, problem, cfg, frozenset(a for a in goal if a[0] != "on-table"))
    assert not res.success and res.stop == "goal believed reached", (res.stop, res.actions)


def observe_atoms_of_goal(sim, model, blob, problem) -> frozenset:
    from symlearn.planning.learned_loop import observe_atoms

    sim.reset(problem.goal)
    return observe_atoms(sim, model, blob)


SHIPPED_CARRY = Path(__file__).resolve().parents[1] / "pretrained" / "relations_carry"


def test_the_carry_model_predicts_table_one_and_its_variants(sim):
    # trained with far-stick scenes: Table I's 9 objects right, every rider within 50 mm but the top of a stack on
    # the stick's end (predicted 232 mm against 182), and no false rider beside the stick
    from symlearn.learning.carrying import run_probes
    from symlearn.learning.relational_training import load_relational

    model, blob = load_relational(SHIPPED_CARRY)
    res = run_probes(model, blob)
    assert res["table1_right"] == "9/9"
    wrong = [(r["name"], i) for r in res["probes"] for i, o in enumerate(r["objects"]) if not o["right"]]
    assert wrong == [("stacked_on_end", 2)], wrong
    for r in res["probes"]:
        if r["name"].startswith("stack_beside"):
            assert all(not o["moved"] and o["right"] for o in r["objects"][1:])  # no false rider


SHIPPED_CARRY_EFFECT = SHIPPED_CARRY.parent / "relations_carry_effect"


def test_the_refit_effect_predictor_gets_every_rider_and_reads_the_carry_models_symbols(sim):
    # pretrained/relations_carry_effect: the carry model's effect predictor refit on its evaluation symbols. Every
    # weight that computes a symbol is the carry model's, so its domain is too; the probes all come out right
    from symlearn.learning.carrying import run_probes
    from symlearn.learning.relational_training import load_relational

    model, blob = load_relational(SHIPPED_CARRY_EFFECT)
    carry, _ = load_relational(SHIPPED_CARRY)
    effect = {n for n, p in model.named_parameters() if any(p is q for q in model.effect_parameters())}
    refit, kept = model.state_dict(), carry.state_dict()
    assert {n for n in refit if not torch.equal(refit[n], kept[n])} <= effect and any(
        not torch.equal(refit[n], kept[n]) for n in effect)
    for name in ("operators.json", "domain.pddl"):
        assert (SHIPPED_CARRY_EFFECT / "learned" / name).read_bytes() == (SHIPPED_CARRY / "learned" / name).read_bytes()
    res = run_probes(model, blob)
    assert (res["table1_right"], res["all_right"], res["riders_right"]) == ("9/9", "31/31", "12/12")
    stacked = next(r for r in res["probes"] if r["name"] == "stacked_on_end")
    assert all(o["moved"] and o["miss_mm"] < 50 for o in stacked["objects"])
    for r in res["probes"]:
        if r["name"].startswith("stack_beside"):
            assert all(not o["moved"] for o in r["objects"][1:])  # no false rider


def test_a_stock_planner_carries_a_stick_with_its_rider_and_the_simulator_builds_it(sim, tmp_path, capsys):
    # the goal: the far-row stick with a cube on its end, both in the near row. Stock lama-first's plan on the
    # exported problem is one action of a learned carrying operator (it moves two items and keeps (on c s)),
    # executed in the simulator it builds the goal scene; without carrying it takes 3 actions
    from symlearn.export.learned_export import load_operators
    from symlearn.learning.carrying import carry_problems
    from symlearn.planning.learned_loop import step_action
    from symlearn.problems.problem import GOAL_TOLERANCE_M, max_goal_distance, save_problem
    from symlearn.world import Action
    from search.stock_planners import solve_files

    problems = {p.name: p for p in carry_problems(sim)}
    problem = problems["carry_rider_to_near_row"]
    save_problem(tmp_path / "carry" / "carry_rider_to_near_row.json", problem)
    out = tmp_path / "lp"
    rc, _ = cli("export-learned-problems", "--run", SHIPPED_CARRY, "--problems", tmp_path / "carry", "--out", out,
                "--goal-relations", "on")
    assert rc == 0
    res = solve_files(out / "domain.pddl", out / "carry_rider_to_near_row.pddl", "fd-lama-first", 60.0)
    assert res.status.name == "SOLVED" and len(res.steps) == 1, res.steps
    ops = {o.name: o for o in load_operators(SHIPPED_CARRY)}
    op = ops[res.steps[0].strip("()").split()[0]]
    moved = {a[1] for a in op.add if a[0] == "at"}
    assert len(moved) == 2 and any(a[0] == "on" for a in op.precondition) and not any(a[0] == "on" for a in op.delete)
    action = step_action(res.steps[0], ops)
    sim.reset(problem.initial)
    sim.step(Action(action // 6, action % 6))
    assert max_goal_distance(sim.get_scene(), problem.goal) <= GOAL_TOLERANCE_M  # the cube on the stick, near row


def test_every_shipped_carry_operator_requires_what_it_deletes():
    # export preset carry keeps each deleted atom in the precondition (LearnedExportConfig.keep_deleted): "put a stick
    # on ?o2" requires (clear ?o2), so no planner puts it on a covered cube; the other operators are as the data found
    # them, every carrying operator among them
    from symlearn.export.learned_export import EXPORT_PRESETS, load_operators

    ops = load_operators(SHIPPED_CARRY)
    assert EXPORT_PRESETS["carry"].keep_deleted
    assert [o.name for o in ops if not set(o.delete) <= set(o.precondition)] == []
    on_item = [o for o in ops if ("clear", "?o2") in o.delete]
    assert len(on_item) >= 10 and all(("clear", "?o2") in o.precondition for o in on_item)
    report = json.loads((SHIPPED_CARRY / "learned" / "report.json").read_text())
    assert report["config"]["keep_deleted"] and report["operators"] == len(ops) == 54
    assert sum(1 for n in report["found"] if n["kept"] and "carries" in n) == 8


def test_the_carrying_problem_of_the_carry_readme_is_one_carry_for_every_planner(tmp_path):
    # pretrained/relations_carry/README.md writes a problem by hand: a far-row stick with a cube on its end, both to the
    # near row. Stock lama-first and LM-cut, and pyperplan and Fast Downward through unified-planning (its validator
    # checks their plans), all answer the one learned carrying action
    import re

    from search.classical import solve_pddl
    from search.stock_planners import solve_files

    readme = (SHIPPED_CARRY / "README.md").read_text()
    problem = re.search(r"```\n(\(define \(problem carry\).*?)```", readme, re.S).group(1)
    domain = SHIPPED_CARRY / "learned" / "domain.pddl"
    want = ("(move-82 l1 s c l4)",)
    (tmp_path / "carry.pddl").write_text(problem)
    for planner in ("fd-lama-first", "fd-lmcut"):
        res = solve_files(domain, tmp_path / "carry.pddl", planner, 60.0)
        assert res.status.name == "SOLVED" and tuple(res.steps) == want, (planner, res.message, res.steps)
    for engine in ("pyperplan", "fast-downward"):
        res = solve_pddl(domain.read_text(), problem, engine, 60.0)
        assert res.status.name == "SOLVED" and tuple(res.steps) == want, (engine, res.message, res.steps)

