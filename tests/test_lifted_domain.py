"""The lifted domain: located codes read as pieces, rules distilled from moves, and the PDDL that states them.

The world here is the simulator's own symbolic model (symlearn.problems.stacking) written as located codes the way
the encoder and location bits give them: eight learned bits of which five repeat the location (as the trained
encoders' do, from the crops' image x and y), one says cube, one says "on the table", then location, place and
level. Rules distilled from its moves must reproduce held-out moves exactly, and the PDDL must do what the rules do.
"""
from __future__ import annotations

import dataclasses
import itertools
import re
from collections import Counter

import numpy as np
import pytest

from pddl_export.lifted_distil import distil_lifted
from pddl_export.lifted_domain import PICK_CUBE, domain_pddl, schemas
from pddl_export.lifted_plans import plan_actions, plan_decoder
from pddl_export.lifted_problem import _rests_fact, problem_pddl
from pddl_export.lifted_rules import REFINEMENTS, LiftedRules, key_of, observed_moves, participants, stick_reader
from pddl_export.lifted_rules_io import load_lifted
from pddl_export.lifted_scene import CodeLayout, Piece, kept_bits, read_scene
from pddl_export.lifted_vocabulary import layer_names, negated_bits, object_name
from pddl_export.symbolic import SymbolicGoal
from symlearn.problems.stacking import act, drop_all
from symlearn.world import ObjectType

LOC_PATTERN = (0b10101, 0b01101, 0b11011, 0b00110, 0b10010, 0b01001)  # five learned bits that track the location
POSITION_BITS = (1, 3, 4, 5, 7)


def _level(state, types, i) -> int:
    g = state[i]
    size = 1 if types[i] == ObjectType.STICK else 2
    return size if g.on is None else _level(state, types, g.on) + size


def located_code(state, types, i) -> int:
    """Object i's 17-bit located code: learned bits (cube, on-table, location pattern), location, place 0, level."""
    g = state[i]
    learned = [0] * 8
    learned[0] = int(types[i] == ObjectType.CUBE)
    learned[6] = int(g.on is None)
    for b, v in zip(POSITION_BITS, format(LOC_PATTERN[g.location], "05b")):
        learned[b] = int(v)
    code = int("".join(map(str, learned)), 2)
    return (code << 9) | (g.location << 6) | (0 << 3) | _level(state, types, i)


def world_moves(n: int, seed: int, objects=(1, 4)):
    """(before codes, action, after codes, types) of random legal moves of the symbolic world."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        k = int(rng.integers(objects[0], objects[1] + 1))
        types = [ObjectType.STICK if i == 0 and rng.random() < 0.5 else ObjectType.CUBE for i in range(k)]
        spec = [(t, int(rng.integers(0, 6))) for t in types]
        try:
            state = drop_all(spec)
            for _ in range(int(rng.integers(0, 3))):  # a few moves first, for stacks and riders
                state = act(state, types, int(rng.integers(0, 6)), int(rng.integers(0, 6)))
            p, r = int(rng.integers(0, 6)), int(rng.integers(0, 6))
            nxt = act(state, types, p, r)
        except ValueError:
            continue
        if p == r:
            continue
        out.append(([located_code(state, types, i) for i in range(k)], p * 6 + r,
                    [located_code(nxt, types, i) for i in range(k)], [t == ObjectType.STICK for t in types]))
    return out


def _arrays(moves):
    k = max(len(m[0]) for m in moves)
    before = np.full((len(moves), k), -1, np.int64)
    after = before.copy()
    stick = np.zeros((len(moves), k), bool)
    for n, (b, a, nxt, st) in enumerate(moves):
        before[n, :len(b)], after[n, :len(b)], stick[n, :len(b)] = b, nxt, st
    return before, np.array([m[1] for m in moves]), after, before >= 0, stick


def _distil(moves_list, min_count: int = 1, **pooling) -> LiftedRules:
    before, actions, after, mask, stick = _arrays(moves_list)
    objs = before[mask]
    learned = (objs[:, None] >> (9 + np.arange(7, -1, -1))) & 1
    layout = CodeLayout(8, kept_bits(learned, (objs >> 6) & 7))
    stick_of = stick_reader(before, mask, stick, layout)
    moves, _ = observed_moves(LiftedRules(layout, stick_of), before, after, actions, mask)
    return distil_lifted(layout, stick_of, moves, min_count=min_count, model_hash="0123456789abcdef", **pooling)


@pytest.fixture(scope="module")
def world_rules() -> LiftedRules:
    return _distil(world_moves(1500, seed=0))


@pytest.fixture(scope="module")
def pair_rules() -> LiftedRules:
    """Rules of two-object scenes only: a domain small enough for unified-planning's reader in seconds."""
    return _distil(world_moves(400, seed=3, objects=(2, 2)))


@pytest.fixture(scope="module")
def pooled_pair_rules() -> LiftedRules:
    """Two-object rules where a structure needs 30 moves of its own: the rarer ones (a cube on a tower, a stick
    placed off its spot) are pooled."""
    rules = _distil(world_moves(400, seed=3, objects=(2, 2)), min_count=30, pool_min_count=3, pool_structure_min=1)
    assert rules.stats["pooled_rules"] >= 3 and rules.stats["pools"] >= 2
    return rules


def test_the_bits_that_track_the_location_are_dropped(world_rules):
    assert world_rules.layout.kept == (0, 6)  # cube and on-table; bit 2 never varies


def test_a_far_stick_covers_its_neighbours_and_carries_its_rider():
    layout = CodeLayout(8, (0, 6))
    stick = Piece(kind=0b01, stick=True, loc=1, place=0, level=1)
    rider = Piece(kind=0b10, stick=False, loc=0, place=0, level=3)
    under = Piece(kind=0b11, stick=False, loc=4, place=0, level=2)
    graph = read_scene((stick, rider, under))
    assert graph.tops == (1, 0, 0, None, 2, None)
    assert graph.support == (None, 0, None)
    move = participants(graph, 1, 4)
    assert (move.o, move.under, move.v, move.riders) == (0, 0, 2, (1,))
    assert participants(graph, 2, 4) == "a stick's end"
    assert participants(graph, 3, 4) == "nothing to pick"
    assert layout.piece(located_code(drop_all([(ObjectType.CUBE, 3)]), [ObjectType.CUBE], 0), False).level == 2


def test_each_step_is_a_rule_a_rare_structure_or_a_move_no_lifted_rule_describes(world_rules):
    """case_of, by which the export's check says where the rules lose to m(z)."""
    from symlearn.export.lifted_export import case_of
    pieces = world_rules.pieces(located_code(drop_all([(ObjectType.CUBE, 3)]), [ObjectType.CUBE], 0) for _ in [0])

    def case(rules, action):
        return case_of(pieces, action, rules.step_pieces(pieces, action)[1] is not None)
    assert case(world_rules, 3 * 6 + 0) == "rule"
    assert case(world_rules, 3 * 6 + 3) == "same location"
    assert case(world_rules, 4 * 6 + 0) == "nothing to pick"
    assert case(dataclasses.replace(world_rules, rules=()), 3 * 6 + 0) == "no rule"


def test_rules_reproduce_held_out_moves_of_the_world(world_rules):
    test = world_moves(400, seed=1)
    described = exact = 0
    for before, action, after, _ in test:
        pieces = world_rules.pieces(before)
        got, rule = world_rules.step_pieces(pieces, action)
        if rule is None:
            continue
        described += 1
        exact += [(p.loc, p.place, p.level, p.kind) for p in got] == \
                 [(p.loc, p.place, p.level, p.kind) for p in world_rules.pieces(after)]
    assert described >= 0.9 * len(test)
    assert exact == described


def test_rules_round_trip_through_json(world_rules, tmp_path):
    import json
    path = tmp_path / "lifted.json"
    path.write_text(json.dumps(world_rules.to_json()))
    back = load_lifted(path)
    assert back.rules == world_rules.rules and back.layout == world_rules.layout
    assert back.stick_of == world_rules.stick_of
    path.write_text('{"kind": "symlearn-lifted-rules", "version": 1, "rules": 3}')
    with pytest.raises(ValueError, match="malformed lifted rules"):
        load_lifted(path)


def test_the_domain_is_small_plain_strips(world_rules):
    text = domain_pddl(world_rules)
    assert len(text.encode()) < 100_000
    assert "(define (domain symlearn-0123456789abcdef)" in text
    for word in ("when", "forall", "exists", ":derived", "either"):
        assert word not in text


@pytest.mark.parametrize("costs", [False, True])
def test_far_row_moves_that_differ_only_in_their_locations_are_one_schema(world_rules, costs):
    """merged_pairs: each pair move stands in exactly one schema (its own, or a merged one whose static facts name
    its pick and release locations), and the plan decoder reads a merged step's locations back."""
    from pddl_export.lifted_domain import PAIR_MOVE, merged_pairs, static_facts
    from pddl_export.lifted_moves import moves
    whole = moves(world_rules, costs)
    merged = merged_pairs(whole)
    joined = [s for s in merged if s.name.startswith(PAIR_MOVE)]
    pairs = [s for s in whole if s.step == "move" and s.pick is not None]
    alone = [s for s in merged if s.step == "move" and s.pick is not None]
    assert joined and len(merged) == len(whole) - sum(len(s.statics) - 1 for s in joined)
    facts = [f.strip("()").split() for s in joined for f in s.statics]
    covered = [(int(f[1][1]), int(f[2][1])) for f in facts] + [(s.pick, s.release) for s in alone]
    assert sorted(covered) == sorted((s.pick, s.release) for s in pairs)
    assert all(len(set(f[1:])) == len(f) - 1 for f in facts)  # a move's locations are distinct
    assert set(x for s in joined for x in s.statics) <= set(static_facts(whole))
    decode = plan_decoder(world_rules, costs)
    for s in joined:
        assert [p for p, _ in s.params[:3]] == ["?o", "?from", "?to"] and s.pre[0].startswith(f"(pair-move-")
        for f in s.statics:
            words = f.strip("()").split()
            step = f"({' '.join([s.name, 'o1', words[1], words[2]] + ['x'] * (len(s.params) - 3))})"
            assert decode([step]) == [(int(words[1][1]) * 6 + int(words[2][1]), s.alternative)]


def test_rules_that_write_the_same_action_write_it_once(world_rules):
    """Rules whose keys differ only in what the PDDL leaves unsaid give one schema, which names the others."""
    from pddl_export.lifted_moves import moves, rule_schema
    written = moves(world_rules)
    bodies = [(s.params, s.pre, s.eff) for s in written]
    assert len(set(bodies)) == len(bodies)
    every = [rule_schema(world_rules, r, i) for i, r in enumerate(world_rules.rules)]
    assert {(s.params, s.pre, s.eff) for s in every} == set(bodies)
    dropped = {s.name for s in every} - {s.name for s in written}
    assert len(dropped) == len(every) - len(written)
    named = [n for s in written if "stands for " in s.text.split("\n", 1)[0]
             for n in s.text.split("\n", 1)[0].split("stands for ", 1)[1].split(", ")]
    assert sorted(named) == sorted(dropped)


def _step(action, params) -> str:
    return f"({action.name} {' '.join(str(p) for p in params)})"


def _robot_ids(decode, steps) -> list[int]:
    """plan_actions through a decoder the test built once for its rules (plan_decoder): plan_actions writes every
    schema anew on each call, and these tests read back thousands of single ground actions."""
    return [a for a, _ in decode(steps)]


def _robot_moves(sim, state, decode) -> list[tuple[int, object]]:
    """(robot action, next state) of every whole move applicable in a unified-planning state and of every
    pick-cube followed by a release-cube (a cube put back where it was picked is no robot action); decode: the
    rules' plan_decoder."""
    out = []
    for action, params in sim.get_applicable_actions(state):
        nxt = sim.apply(state, action, params)
        if action.name != PICK_CUBE:
            out.append((_robot_ids(decode, [_step(action, params)])[0], nxt))
            continue
        assert not any(a.name == PICK_CUBE for a, _ in sim.get_applicable_actions(nxt)), "two cubes in the hand"
        for release, args in sim.get_applicable_actions(nxt):
            ids = _robot_ids(decode, [_step(action, params), _step(release, args)])
            if ids:
                out.append((ids[0], sim.apply(nxt, release, args)))
    return out


@pytest.mark.parametrize("fixture", ["pair_rules", "pooled_pair_rules"])
def test_pddl_successors_are_the_rules(fixture, request):
    """Every action of sampled states has one applicable ground action in the PDDL where the rules have a rule for it,
    and none elsewhere, and it leads where the rules lead; pooled rules too (their schemas lifted over levels)."""
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import SequentialSimulator, get_environment
    get_environment().credits_stream = None
    pair_rules = request.getfixturevalue(fixture)
    domain = domain_pddl(pair_rules)
    assert "(vacant ?to " in domain  # the world's rules state where a place is free (test_two_blocks_at_one_...)
    states = [m[0] for m in world_moves(3 if fixture == "pair_rules" else 12, seed=2, objects=(2, 2))]
    checked = pooled = 0
    decode = plan_decoder(pair_rules)
    for start in states:
        goal = SymbolicGoal(tuple(start))
        problem = PDDLReader().parse_problem_string(domain, problem_pddl(pair_rules, start, goal, "p"))
        pieces = pair_rules.pieces(start)
        with SequentialSimulator(problem) as sim:
            state = sim.get_initial_state()
            by_action = {}
            for a, nxt in _robot_moves(sim, state, decode):
                by_action.setdefault(a, []).append(nxt)
        for a in range(36):
            want, rule = pair_rules.step_pieces(pieces, a)
            assert (rule is not None) == (a in by_action), f"action {a} from {start}"
            # the leaves partition the moves, and so do the schemas: one ground action per (pick, release)
            assert len(by_action.get(a, [])) <= 1, f"action {a} from {start}: {len(by_action[a])} ground actions"
            for nxt in by_action.get(a, []):
                checked += 1
                pooled += rule.pool is not None
                for i, p in enumerate(want):
                    o = problem.object(object_name(i))
                    at = [loc for loc in range(6) if nxt.get_value(problem.fluent("at")(o, problem.object(f"l{loc}"))).bool_constant_value()]
                    lvl = [h for h in range(8) if nxt.get_value(problem.fluent("level")(o, problem.object(f"h{h}"))).bool_constant_value()]
                    assert at == [p.loc] and lvl == [p.level], f"object {i} after action {a} from {start}"
                    # stands repeats at and level together: exactly the one pair, whatever moved
                    stands = [(loc, h) for loc in range(6) for h in range(8) if nxt.get_value(problem.fluent("stands")(
                        o, problem.object(f"l{loc}"), problem.object(f"h{h}"))).bool_constant_value()]
                    assert stands == [(p.loc, p.level)], f"object {i} stands at {stands} after action {a} from {start}"
                # rests: what the problem writer reads under each block of the scene the rules predict (a goal
                # states it, _rests_fact, so the two must agree or a goal the rules reach would be refused)
                rests = {f"(rests {object_name(i)} {t})" for i in range(len(want)) for t in layer_names()
                         if nxt.get_value(problem.fluent("rests")(problem.object(object_name(i)),
                                                                  problem.object(t))).bool_constant_value()}
                assert rests == {_rests_fact(want, i) for i, p in enumerate(want) if p.loc < 6}, \
                    f"rests after action {a} from {start}"
                # vacant: exactly the (location, level) places no block stands at
                vacant = {(loc, h) for loc in range(6) for h in range(8) if nxt.get_value(problem.fluent("vacant")(
                    problem.object(f"l{loc}"), problem.object(f"h{h}"))).bool_constant_value()}
                assert vacant == {(loc, h) for loc in range(6) for h in range(8)} - {(p.loc, p.level) for p in want}, \
                    f"vacant places after action {a} from {start}"
    assert checked >= 3 and (pooled >= 5 if fixture == "pooled_pair_rules" else pooled == 0)


def _facts(problem_text: str) -> tuple[set[str], dict[str, list[str]]]:
    """A problem's initial facts and its objects of each type (with the domain's constants)."""
    objects = problem_text.split("(:objects", 1)[1].split(")", 1)[0].split()
    typed = {"block": [], "cube": [], "stick": [], "location": [f"l{i}" for i in range(6)], "layer": layer_names()}
    for name, _, kind in zip(objects[::3], objects[1::3], objects[2::3]):
        typed[kind].append(name)
        typed["block"].append(name)
    lines = problem_text.split("(:init", 1)[1].split("(:goal", 1)[0].splitlines()
    return {line.strip()[:line.strip().index(")") + 1] for line in lines if line.strip().startswith("(")}, typed


def _ground(atom: str, binding: dict) -> str:
    return "(" + " ".join(binding.get(w, w) for w in atom.strip("()").split()) + ")"


def _applicable(schema_list, init: set[str], typed: dict) -> list[tuple]:
    """(schema, binding) of each ground action whose preconditions hold in a state (a small grounder for the test:
    bindings by type, pruned as soon as a precondition's terms are bound)."""
    found: list[tuple] = []
    for s in schema_list:
        names = [p for p, _ in s.params]
        def holds(atom: str, binding: dict) -> bool | None:
            if any(w.startswith("?") and w not in binding for w in atom.strip("()").split()):
                return None
            return _ground(atom, binding) in init
        def extend(binding: dict, k: int):
            if any(holds(a, binding) is False for a in s.pre):
                return
            if k == len(names):
                found.append((s, binding))
                return
            for value in typed[s.params[k][1]]:
                extend({**binding, names[k]: value}, k + 1)
        extend({}, 0)
    return found


def _robot_actions(schema_list, problem_text: str, decode) -> dict[int, list[str]]:
    """Robot action -> the names of the ground actions (a whole move, or a pick-cube and a release-cube) that
    stand for it in the problem's initial state; decode: the rules' plan_decoder."""
    init, typed = _facts(problem_text)
    out: dict[int, list[str]] = {}
    step = lambda s, b: f"({s.name} {' '.join(b[p] for p, _ in s.params)})"  # noqa: E731
    for s, b in _applicable(schema_list, init, typed):
        if s.name != PICK_CUBE:
            out.setdefault(_robot_ids(decode, [step(s, b)])[0], []).append(s.name)
            continue
        held = (init - {_ground(e[5:-1], b) for e in s.eff if e.startswith("(not ")}) | \
            {_ground(e, b) for e in s.eff if not e.startswith("(not ")}
        for r, rb in _applicable(schema_list, held, typed):
            for a in _robot_ids(decode, [step(s, b), step(r, rb)]):
                out.setdefault(a, []).append(r.name)
    return out


def test_a_plan_reads_back_as_robot_actions_a_pick_and_its_release_as_one(world_rules):
    """plan_decoder: a pick-cube and the release-cube after it are one robot action (pick * 6 + release), a stick's
    move is one on its own, a cube put back where it was picked is none; a plan that releases what is not held,
    moves while holding, or ends holding is refused in one line."""
    written = schemas(world_rules)
    release = next(s for s in written if s.step == "release" and s.release is None)
    stick = next(s for s in written if s.step == "move" and s.pick is not None)
    assert sum(s.step == "pick" for s in written) == 1 and all(s.name != PICK_CUBE for s in written if s.step != "pick")
    decode = plan_decoder(world_rules)
    pick = "(pick-cube o1 l4 h2 h0)"
    stick_step = f"({stick.name} {' '.join('o0' for _ in stick.params)})"
    assert decode([pick, f"({release.name} o1 l0)", stick_step]) == [(4 * 6 + 0, 0),
                                                                       (stick.pick * 6 + stick.release, 0)]
    assert decode([pick, f"({release.name.upper()} O1 L4)"]) == []  # put back: no robot action
    assert plan_actions(world_rules, [pick, f"({release.name} o1 l2)"]) == [4 * 6 + 2]
    for steps, message in (([f"({release.name} o1 l0)"], "releases a cube that is not held"),
                           ([pick, pick], "comes while o1 is held"),
                           ([pick, stick_step], "comes while o1 is held"),
                           ([pick], "the plan ends with o1 held"),
                           ([pick, f"({release.name} o2 l0)"], "releases o2, but o1 is held"),
                           (["(pick-cube o1 l9 h2 h0)"], "'l9' is not a location"),
                           (["(pick-cube o1 l4)"], "gives 2 arguments, pick-cube takes 4"),
                           (["(fly o1)"], "names no action of the lifted domain")):
        with pytest.raises(ValueError, match=message.replace("(", r"\(")):
            decode(steps)


def test_one_ground_action_per_pick_and_release_where_stick_ends_and_towers_share_a_height(world_rules):
    """A cube released onto a far-row stick's end and one released onto a block standing at the location are
    different moves (the structure's `v.at`), as is a cube lifted off a stick's end and one lifted off a block
    (`u.at`); the PDDL states what the top at a location is and what a block rests on (`h3` or `h3-end`), so in
    every state at most one ground action stands for each robot action, the one of the rule that matches."""
    assert any(not r.fields()["v.at"] and r.fields()["v.level"] > 0 for r in world_rules.rules)
    assert any(not r.fields()["u.at"] and r.fields()["u.level"] > 0 for r in world_rules.rules)
    written = schemas(world_rules)
    decode = plan_decoder(world_rules)
    onto_end = checked = 0
    for start, _, _, _ in world_moves(120, seed=5, objects=(3, 4)):
        text = problem_pddl(world_rules, start, SymbolicGoal(tuple(start)), "p")
        pieces = world_rules.pieces(start)
        graph = read_scene(pieces)
        by_action = _robot_actions(written, text, decode)
        for a in range(36):
            _, rule = world_rules.step_pieces(pieces, a)
            assert len(by_action.get(a, [])) == (rule is not None), f"action {a} from {start}: {by_action.get(a)}"
            if rule is not None:
                checked += 1
                v = graph.tops[a % 6]
                onto_end += v is not None and pieces[v].loc != a % 6
    assert checked > 300 and onto_end > 5


@pytest.mark.parametrize("planner", ["fd-lmcut", "fd-lama-first", "pyperplan"])
def test_stock_planners_plan_a_tower_the_rules_build(world_rules, tmp_path, planner):
    """Stock Fast Downward (its own translator) and pyperplan solve a lifted problem; pyval accepts the plan; the
    rules, run along it, build the tower."""
    import pyval

    from search.stock_planners import solve_files
    types = [ObjectType.CUBE] * 3
    start_state = drop_all([(t, loc) for t, loc in zip(types, (3, 4, 5))])
    goal_state = start_state
    for p, r in ((4, 0), (5, 0)):
        goal_state = act(goal_state, types, p, r)
    start = [located_code(start_state, types, i) for i in range(3)]
    goal = [None, located_code(goal_state, types, 1), located_code(goal_state, types, 2)]
    (tmp_path / "domain.pddl").write_text(domain_pddl(world_rules))
    (tmp_path / "p01.pddl").write_text(problem_pddl(world_rules, start, SymbolicGoal(tuple(goal)), "p01"))
    res = solve_files(tmp_path / "domain.pddl", tmp_path / "p01.pddl", planner, timeout_s=120,
                      action_ids=lambda steps: plan_actions(world_rules, steps))
    assert res.found, res.message
    if planner == "fd-lmcut":
        assert len(res.plan) == 2  # optimal: both cubes onto location 0
    (tmp_path / "plan.txt").write_text("".join(f"{s}\n" for s in res.steps))
    verdict = pyval.PDDLValidator().validate(str(tmp_path / "domain.pddl"), str(tmp_path / "p01.pddl"),
                                             str(tmp_path / "plan.txt"))
    assert verdict.status == "VALID"
    pieces = world_rules.pieces(start)
    for a in res.plan:
        pieces, rule = world_rules.step_pieces(pieces, a)
        assert rule is not None
    assert [(p.loc, p.level) for p in pieces[1:]] == [(0, 2), (0, 4)]


def test_a_goal_no_move_builds_in_one_place_is_refused_by_the_translator(world_rules, tmp_path):
    """`stands` states a block's location and level together, so a goal that no move can build there (a stick on a
    block in the far row, once the rules that put one there are taken out) is found unreachable by Fast Downward's
    translator before any search, though a stick can reach l0 and level 3 each (the search would have had to
    exhaust the task's states to prove it: with at and level alone it expands states)."""
    from search.result import PlanStatus
    from search.stock_planners import solve_files

    def far_onto_block(r) -> bool:
        f = r.fields()
        return f["o.stick"] and isinstance(f["cls"], tuple) and f["cls"][1] in (0, 1, 2) and f["v.level"] > 0
    rules = dataclasses.replace(world_rules, rules=tuple(r for r in world_rules.rules if not far_onto_block(r)))
    assert len(rules.rules) < len(world_rules.rules)
    types = [ObjectType.STICK, ObjectType.CUBE, ObjectType.CUBE]
    start_state = drop_all([(ObjectType.STICK, 3), (ObjectType.CUBE, 0), (ObjectType.CUBE, 4)])
    start = [located_code(start_state, types, i) for i in range(3)]
    goal_state = act(start_state, types, 3, 0)  # the stick onto the cube at l0, in the world
    goal = [located_code(goal_state, types, 0), None, None]
    assert rules.pieces([goal[0]])[0].level == 3
    adds = {e for s in schemas(rules) if dict(s.params).get("?o") == "stick" for e in s.eff}
    assert {"(at ?o l0)", "(level ?o h3)"} <= adds  # each on its own, some stick move reaches it
    (tmp_path / "domain.pddl").write_text(domain_pddl(rules))
    (tmp_path / "p01.pddl").write_text(problem_pddl(rules, start, SymbolicGoal(tuple(goal)), "p01"))
    res = solve_files(tmp_path / "domain.pddl", tmp_path / "p01.pddl", "fd-lama-first", timeout_s=60,
                      action_ids=lambda steps: plan_actions(rules, steps))
    assert res.status == PlanStatus.UNSOLVABLE, res.message
    # the translator's relaxed exploration found no way to the goal: it wrote the trivially unsolvable task
    assert res.extra["translator_operators"] == 0, f"{res.extra} (the search expanded {res.expansions} states)"


def test_two_blocks_at_one_place_are_refused_by_the_translator(world_rules, tmp_path):
    """`vacant` and `stands` make "one block per location and level" an invariant Fast Downward's translator finds,
    so a goal with two cubes on the table at l5 (two tops at level 2 there, which the height field's last layer
    can state of a tall tower) is refused before any search, though each cube alone can be put there."""
    from search.result import PlanStatus
    from search.stock_planners import solve_files
    types = [ObjectType.CUBE] * 3
    start = [located_code(drop_all([(ObjectType.CUBE, x) for x in (0, 3, 4)]), types, i) for i in range(3)]
    first = located_code(drop_all([(ObjectType.CUBE, x) for x in (5, 3, 4)]), types, 0)
    second = located_code(drop_all([(ObjectType.CUBE, x) for x in (0, 5, 4)]), types, 1)
    assert world_rules.pieces([first])[0].level == world_rules.pieces([second])[0].level == 2
    (tmp_path / "domain.pddl").write_text(domain_pddl(world_rules))
    for name, goal, status in (("alone", (first, None, None), PlanStatus.SOLVED),
                               ("both", (first, second, None), PlanStatus.UNSOLVABLE)):
        (tmp_path / f"{name}.pddl").write_text(problem_pddl(world_rules, start, SymbolicGoal(goal), name))
        res = solve_files(tmp_path / "domain.pddl", tmp_path / f"{name}.pddl", "fd-lama-first", timeout_s=60,
                          action_ids=lambda steps: plan_actions(world_rules, steps))
        assert res.status == status, (name, res.message)
    assert res.extra["translator_operators"] == 0, f"{res.extra} (the search expanded {res.expansions} states)"


def test_a_whole_goal_says_what_each_block_rests_on_and_a_top_no_move_reaches_is_refused(world_rules, tmp_path):
    """Where every object's goal is known the goal also states `rests` (what each block is on, as blocks-world
    goals do). With the moves that put a cube on a far-row stick's end taken out, a cube on the end of a stick at l0
    is refused by the translator: some move still puts a cube at l1 at level 3 (onto a stick standing there), so
    without `rests` the goal passes the relaxed check and the search has to look."""
    from search.result import PlanStatus
    from search.stock_planners import solve_files
    types = [ObjectType.STICK, ObjectType.CUBE]
    start_state = drop_all([(ObjectType.STICK, 0), (ObjectType.CUBE, 4)])
    start = [located_code(start_state, types, i) for i in range(2)]
    on_end = act(start_state, types, 4, 1)  # the cube onto the stick's end over l1, in the world
    goal = [located_code(on_end, types, i) for i in range(2)]
    text = problem_pddl(world_rules, start, SymbolicGoal(tuple(goal)), "p01")
    assert {"(rests o0 h0)", "(rests o1 h1-end)"} == set(re.findall(r"\(rests o\d [^\s)]+\)", text.split("(:goal")[1]))
    partial = problem_pddl(world_rules, start, SymbolicGoal((None, goal[1])), "p").split("(:goal", 1)[1]
    assert "(rests " not in partial  # what the cube rests on depends on the stick, whose goal is not known
    rules = dataclasses.replace(world_rules, rules=tuple(r for r in world_rules.rules if r.fields()["o.stick"] or not (
        r.fields()["v.level"] == 1 and not r.fields()["v.at"])))
    assert len(rules.rules) < len(world_rules.rules)
    (tmp_path / "domain.pddl").write_text(domain_pddl(rules))
    text = problem_pddl(rules, start, SymbolicGoal(tuple(goal)), "p01")
    (tmp_path / "p01.pddl").write_text(text)
    (tmp_path / "p02.pddl").write_text(text.replace("(rests o1 h1-end))", ")"))
    found = {}
    for name in ("p01", "p02"):
        found[name] = solve_files(tmp_path / "domain.pddl", tmp_path / f"{name}.pddl", "fd-lama-first",
                                  timeout_s=60, action_ids=lambda steps: plan_actions(rules, steps))
        assert found[name].status == PlanStatus.UNSOLVABLE, found[name].message
    assert found["p01"].extra["translator_operators"] == 0, found["p01"].extra
    assert found["p02"].extra["translator_operators"] > 0, found["p02"].extra  # without rests: searched


@pytest.mark.parametrize("pre, eff", [
    # a cube landing at the level of the top it lands on (both the height field's last layer)
    (("(holding ?o)", "(height ?to h7)"), ("(at ?o ?to)", "(stands ?o ?to h7)")),
    # a stick dragged by its end that may keep its location and level
    (("(at ?o l0)", "(level ?o ?h)"), ("(not (stands ?o l0 ?h))", "(stands ?o l0 ?new)")),
    # two blocks put at one place
    (("(holding ?o)",), ("(stands ?o ?to h3)", "(stands ?r0 ?to h3)")),
])
def test_a_move_that_cannot_state_occupancy_leaves_it_out_of_the_whole_domain(pre, eff):
    """Where a move may leave two blocks at one place, or keep a block where it stood, `vacant` would forbid what
    the rules allow: that move states none (_occupancy gives None) and `schemas` writes no occupancy at all."""
    from pddl_export.lifted_domain import _occupancy
    from pddl_export.lifted_vocabulary import Schema
    params = (("?o", "block"), ("?to", "location"), ("?r0", "block"), ("?h", "layer"), ("?new", "layer"))
    assert _occupancy(Schema("m", None, None, "  ; m\n  (:action m\n", params, pre, eff)) is None
    plain = _occupancy(Schema("m", None, None, "  ; m\n  (:action m\n", params,
                              ("(at ?o l0)", "(level ?o h2)", "(height ?to h0)"),
                              ("(not (stands ?o l0 h2))", "(stands ?o ?to h2)", "(increase (total-cost) 10)"), cost=10))
    assert plain.pre == ("(stands ?o l0 h2)", "(height ?to h0)", "(vacant ?to h2)")
    assert plain.eff == ("(not (stands ?o l0 h2))", "(stands ?o ?to h2)", "(not (vacant ?to h2))", "(vacant l0 h2)",
                         "(increase (total-cost) 10)")


def _pddlgym_env(domain, problems_dir):
    import warnings
    with warnings.catch_warnings():  # gym 0.26 warns on import that it is unmaintained
        warnings.simplefilter("ignore")
        from pddlgym.core import PDDLEnv
    return PDDLEnv(str(domain), str(problems_dir), operators_as_actions=True, dynamic_action_space=True)


def test_pddlgym_loads_the_domain_and_steps_to_the_goal_as_the_rules_do(world_rules, tmp_path):
    """pddlgym (its own parser and successor function) reads the lifted domain; the ground actions it offers at
    the start are the robot actions the rules allow; Fast Downward's plan, stepped in pddlgym, reaches the goal."""
    from search.stock_planners import solve_files
    types = [ObjectType.CUBE, ObjectType.CUBE, ObjectType.STICK]
    start_state = drop_all([(t, loc) for t, loc in zip(types, (3, 4, 1))])
    goal_state = act(act(start_state, types, 4, 3), types, 1, 5)
    start = [located_code(start_state, types, i) for i in range(3)]
    goal = SymbolicGoal(tuple(located_code(goal_state, types, i) for i in range(3)))
    (tmp_path / "problems").mkdir()
    (tmp_path / "domain.pddl").write_text(domain_pddl(world_rules))
    (tmp_path / "problems" / "p01.pddl").write_text(problem_pddl(world_rules, start, goal, "p01"))
    env = _pddlgym_env(tmp_path / "domain.pddl", tmp_path / "problems")
    obs, _ = env.reset()
    step = lambda lit: f"({lit.predicate.name} {' '.join(v.name for v in lit.variables)})"  # noqa: E731
    offered = set()  # the robot actions of pddlgym's ground actions: a whole move, or a pick and a release
    decode = plan_decoder(world_rules)
    for lit in env.action_space.all_ground_literals(obs):
        if lit.predicate.name != PICK_CUBE:
            offered.add(_robot_ids(decode, [step(lit)])[0])
            continue
        held, *_ = env.step(lit)
        offered |= {a for rel in env.action_space.all_ground_literals(held)
                    for a in _robot_ids(decode, [step(lit), step(rel)])}
        env.set_state(obs)
    allowed = {a for a in range(36) if world_rules.step_pieces(world_rules.pieces(start), a)[1] is not None}
    assert offered == allowed
    res = solve_files(tmp_path / "domain.pddl", tmp_path / "problems" / "p01.pddl", "fd-lama-first",
                      timeout_s=120, action_ids=lambda steps: plan_actions(world_rules, steps))
    assert res.found and sorted(res.plan) == [1 * 6 + 5, 4 * 6 + 3], res.message
    assert len(res.steps) == 3  # the cube picked and released, the stick moved whole
    done = False
    for text in res.steps:
        by_text = {step(lit).lower(): lit for lit in env.action_space.all_ground_literals(obs)}
        obs, reward, done, *_ = env.step(by_text[" ".join(text.lower().split())])
    assert done and reward == 1.0
    facts = {str(lit) for lit in obs.literals}
    assert "at(o0:cube,l3:location)" in facts and "at(o2:stick,l5:location)" in facts


def test_export_lifted_and_plan_with_stock_fast_downward_on_a_tiny_run(tiny_run_copy, tiny_data, tmp_path):
    """The whole route on real codes: m(z) on 9 location bits, export-pddl (lifted), the registry's planner."""
    import json

    import pyval

    from conftest import cli, write_config
    from symlearn.data.dataset import load_split
    from symlearn.export.rules_export import training_codes
    from symlearn.planning.planners import PlannerContext, make_planner
    from symlearn.symbolic.learned_transition import planning_models

    run = tiny_run_copy
    rc, _ = cli("export-pddl", "--run", run, "--data", tiny_data.path)
    assert rc == 2  # the tiny run's m(z) reads no location bits: refused in one line
    config = write_config(tmp_path / "located.toml", {"transition": {"location_bits": 9}, "lifted": {"min_count": 1}})
    rc, _ = cli("train-transition", "--run", run, "--data", tiny_data.path, "--preset", "quick", "--config", config,
                "--quiet")
    assert rc == 0
    rc, text = cli("export-pddl", "--run", run, "--data", tiny_data.path, "--config", config)
    assert rc == 0 and "lifted rules" in text
    lifted = load_lifted(run / "pddl" / "lifted.json")
    report = json.loads((run / "pddl" / "lifted.json").read_text())["stats"]
    assert lifted.rules and report["model_hash"] == lifted.model_hash and "checks_test_split" in report
    for group in report["checks_test_split"][str(tiny_data.path)].values():  # the cases add up, by case too
        cases = group["by_case"].values()
        assert sum(c["cases"] for c in cases) == group["cases"] and sum(c["disagree"] for c in cases) == group["disagree"]
        assert group["disagree"] == round((1 - group["fidelity_to_net"]) * group["cases"])
        assert group["world_sides_with_rules"] + group["world_sides_with_net"] <= group["disagree"]
        assert group["by_case"].get("rule", {}).get("rule_fired", 1.0) == 1.0
        assert all(c["rule_fired"] == 0 for name, c in group["by_case"].items() if name != "rule")
    before, after = training_codes(run, tiny_data.path, planning_models(run)[0])
    actions = load_split(tiny_data.path, "train").action
    case = next((row[row >= 0].tolist(), int(a)) for row, a in zip(before, actions)
                if lifted.step_codes(row[row >= 0].tolist(), int(a))[1] is not None)
    start, action = case
    want = lifted.step_codes(start, action)[0]
    planner = make_planner("fast-downward-lifted", PlannerContext.for_run(run, ["fast-downward-lifted"],
                                                                            write_dir=tmp_path / "tasks"))
    res = planner(None, np.asarray(start), SymbolicGoal(tuple(want)), 60.0)
    assert res.found and len(res.plan) <= 1, res.message
    fields = lambda codes: [(p.loc, p.place, p.level) for p in lifted.pieces(codes)]  # noqa: E731
    assert fields(res.predicted_states[-1]) == fields(want)
    (tmp_path / "plan.txt").write_text("".join(f"{s}\n" for s in res.steps))
    verdict = pyval.PDDLValidator().validate(str(tmp_path / "tasks" / "domain.pddl"),
                                             str(tmp_path / "tasks" / "problem.pddl"), str(tmp_path / "plan.txt"))
    assert verdict.status == "VALID"
    # the all-outcomes cost form of the same export: its files, stock Fast Downward's plan, pyval's verdict
    planner = make_planner("fast-downward-lifted-outcomes", PlannerContext.for_run(
        run, ["fast-downward-lifted-outcomes"], write_dir=tmp_path / "cost_tasks"))
    res = planner(None, np.asarray(start), SymbolicGoal(tuple(want)), 60.0)
    assert res.found and len(res.plan) <= 1, res.message
    assert fields(res.predicted_states[-1]) == fields(want)
    domain = (tmp_path / "cost_tasks" / "domain.pddl").read_text()
    assert ":action-costs" in domain and "(:metric minimize (total-cost))" in (
        tmp_path / "cost_tasks" / "problem.pddl").read_text()
    (tmp_path / "cost_plan.txt").write_text("".join(f"{s}\n" for s in res.steps))
    verdict = pyval.PDDLValidator().validate(str(tmp_path / "cost_tasks" / "domain.pddl"),
                                             str(tmp_path / "cost_tasks" / "problem.pddl"),
                                             str(tmp_path / "cost_plan.txt"))
    assert verdict.status == "VALID"
    # one reading of the training moves (experiments/preset_sweep.py distils several settings from it), distilled under
    # the export's setting, gives the exported rules; a setting of another source cannot reuse it
    from symlearn.export.lifted_export import LiftedConfig, distil_rules, training_moves
    reader, transition = planning_models(run)
    seen = training_moves(reader, transition, [tiny_data.path], LiftedConfig(min_count=1))
    assert len(seen.moves) == len(seen.answers) > 0
    again = distil_rules(seen, LiftedConfig(min_count=1), lifted.model_hash)
    assert [(r.key, r.outcome, r.support) for r in again.rules] == [(r.key, r.outcome, r.support) for r in lifted.rules]
    with pytest.raises(ValueError, match="cannot be distilled under source='network'"):
        distil_rules(seen, LiftedConfig(min_count=1, source="network"), lifted.model_hash)


def test_moves_the_world_model_never_makes_still_write_a_domain_fast_downward_reads(world_rules, tmp_path):
    """Riders falling off a carried stick (staying, or landing elsewhere) and a cube ending off its location are
    outcomes m(z) gives that the symbolic world does not: their schemas must still be PDDL the translator reads."""
    from pddl_export.lifted_rules import STRUCTURE, Rule
    from search.stock_planners import solve_texts
    base = {"cls": (1, 4), "o.stick": True, "o.place": 0, "o.level": 1, "u.level": 0, "v.level": 0,
            "riders.sides": (-1, 1), "riders.place": (0, 0), "riders.level": (3, 3), "beneath": (0, 0),
            "landing": (), "u.at": False, "v.at": False}
    key = tuple((n, base[n]) for n in STRUCTURE)
    falls = Rule(0, key, (("to", 0, 1, 1), None, None, ("stay", 3, 2, 3), (5, 0, 2, 3)), 4)
    cube = dict(base, cls="cube", **{"o.stick": False, "o.level": 2, "riders.sides": (), "riders.place": (),
                                     "riders.level": (), "beneath": ()})
    off = Rule(0, tuple((n, cube[n]) for n in STRUCTURE), (("to", 2, 2, 3), None, None), 3)
    rules = dataclasses.replace(world_rules, rules=(falls, off), stick_of={(1, 1): True, (2, 3): False})
    text = domain_pddl(rules)
    assert "None" not in text and text.count("(:action") == 3  # the stick's move; pick-cube, the cube's release
    start = [(1 << 9) | (1 << 6) | 1, (2 << 9) | (0 << 6) | 3, (2 << 9) | (2 << 6) | 3]  # a stick at 1, two riders
    goal = SymbolicGoal(((1 << 9) | (4 << 6) | 1, None, None))  # the stick at 4
    res = solve_texts(text, problem_pddl(rules, start, goal, "p"), "fd-blind", 60)
    assert res.status.value == "solved", res.message


def test_moves_that_carry_riders_need_fewer_answers_than_others():
    """distil_lifted keeps a description seen min_count times, or rider_min_count times when its outcome moves
    riders: riders are rare, and a domain without them could not say that a stick carries what stands on it."""
    before, actions, after, mask, stick = _arrays(world_moves(1500, seed=0))
    objs = before[mask]
    layout = CodeLayout(8, kept_bits((objs[:, None] >> (9 + np.arange(7, -1, -1))) & 1, (objs >> 6) & 7))
    stick_of = stick_reader(before, mask, stick, layout)
    moves, _ = observed_moves(LiftedRules(layout, stick_of), before, after, actions, mask)
    counts = Counter(key_of(sig, len(REFINEMENTS)) for sig, out in moves if len(out) > 3)
    assert counts, "the stacking world's walks carry riders"
    high = max(counts.values()) + 1  # above every rider description's count
    riders = lambda rules: [r for r in rules.rules if len(r.outcome) > 3]  # noqa: E731
    assert not riders(distil_lifted(layout, stick_of, moves, min_count=high))
    kept = distil_lifted(layout, stick_of, moves, min_count=high, rider_min_count=1)
    assert riders(kept) and all(len(r.outcome) > 3 or r.support >= high for r in kept.rules)


def test_a_rule_keeps_its_outcome_share_and_the_cost_form_plans_on_its_alternatives(tmp_path):
    """A description m(z) answered two ways (7 and 3 times): one rule with share 0.7 and the other answer as its
    alternative. The deterministic domain states the rule's own outcome; the cost form one action per outcome,
    costing 10 (1 - ln share), so stock Fast Downward (A* with LM-cut) takes the cheaper one where both reach the
    goal and the alternative where only it does; the planner's predictions follow the outcome each step chose."""
    import pyval

    from pddl_export.lifted_moves import outcome_cost
    from search.stock_planners import solve_texts
    from symlearn.planning.lifted_planner import LiftedPlanner
    before, actions, after, mask, stick = _arrays(world_moves(300, seed=0))
    objs = before[mask]
    layout = CodeLayout(8, kept_bits((objs[:, None] >> (9 + np.arange(7, -1, -1))) & 1, (objs >> 6) & 7))
    stick_of = stick_reader(before, mask, stick, layout)
    plain = LiftedRules(layout, stick_of)
    for i in range(len(actions)):  # the first move of a lone cube onto the table: no riders, nothing under it
        one, _ = observed_moves(plain, before[i:i + 1], after[i:i + 1], actions[i:i + 1], mask[i:i + 1])
        if one and len(one[0][1]) == 3 and one[0][0]["cls"] == "cube" and one[0][1][0][2] == 2:
            break
    sig, out = one[0]
    higher = ((out[0][0], out[0][1], out[0][2] + 1, out[0][3]), *out[1:])  # the cube ends one level higher
    rules = distil_lifted(layout, stick_of, [(sig, out)] * 7 + [(sig, higher)] * 3, min_count=3, model_hash="ab" * 8)
    assert len(rules.rules) == 1
    rule = rules.rules[0]
    assert (rule.outcome, rule.share, rule.alternatives) == (out, 0.7, ((higher, 0.3),))
    (tmp_path / "lifted.json").write_text(__import__("json").dumps(rules.to_json()))
    assert load_lifted(tmp_path / "lifted.json").rules == rules.rules  # shares and alternatives round-trip

    start, action = [int(c) for c in before[i][mask[i]]], int(actions[i])
    own, _ = rules.step_codes(start, action)
    alt, _ = rules.step_codes(start, action, alternative=1)
    moved = [j for j in range(len(start)) if own[j] != start[j]]
    assert [rules.pieces(alt)[j].level for j in moved] == [rules.pieces(own)[j].level + 1 for j in moved]
    with pytest.raises(ValueError, match="has 1 alternatives, not 2"):
        rules.step_codes(start, action, alternative=2)

    deterministic, costed = domain_pddl(rules), domain_pddl(rules, costs=True)
    assert deterministic.count("(:action") == 2 and "total-cost" not in deterministic  # pick-cube, one release
    assert costed.count("(:action") == 3 and ":action-costs" in costed
    assert (outcome_cost(0.7), outcome_cost(0.3), outcome_cost(1.0)) == (14, 22, 10)
    assert "(increase (total-cost) 14)" in costed and "(increase (total-cost) 22)" in costed
    with pytest.raises(ValueError, match="must lie in"):
        outcome_cost(0.0)
    decode = plan_decoder(rules, costs=True)
    for target, alternative in ((own, 0), (alt, 1)):
        goal = SymbolicGoal(tuple(c if j in moved else None for j, c in enumerate(target)))
        problem = problem_pddl(rules, start, goal, "p", costs=True)
        assert "(:metric minimize (total-cost))" in problem
        res = solve_texts(costed, problem, "fd-lmcut", 60, action_ids=lambda steps: [a for a, _ in decode(steps)])
        assert res.found and decode(res.steps) == [(action, alternative)], res.message
        (tmp_path / "d.pddl").write_text(costed)
        (tmp_path / "p.pddl").write_text(problem)
        (tmp_path / "plan.txt").write_text("".join(f"{s}\n" for s in res.steps))
        assert pyval.PDDLValidator().validate(str(tmp_path / "d.pddl"), str(tmp_path / "p.pddl"),
                                              str(tmp_path / "plan.txt")).status == "VALID"
        planned = LiftedPlanner(rules, "fast-downward-lifted-outcomes", "fd-lmcut", costs=True)(None, np.asarray(start),
                                                                                                  goal, 60.0)
        assert planned.found and planned.predicted_states[-1] == tuple(
            g if g is not None else c for c, g in zip(target, goal.codes))
    only_own = dataclasses.replace(rule, alternatives=())
    assert domain_pddl(dataclasses.replace(rules, rules=(only_own,)), costs=True).count("(:action") == 2


def test_a_kind_that_follows_the_release_location_splits_the_rule_there_and_the_pddl_does_the_same():
    """The kept bits of a moved object can follow where it lands (as the trained encoders' do). Moves whose cube
    takes another kind when released at l2: the tree refines on the release location, the other locations keep
    one lifted rule (`?to` with `(differ ?to l2)`), and every ground action of the PDDL sets the bits the rules set."""
    before, actions, after, mask, stick = _arrays(world_moves(400, seed=3, objects=(2, 2)))
    objs = before[mask]
    layout = CodeLayout(8, kept_bits((objs[:, None] >> (9 + np.arange(7, -1, -1))) & 1, (objs >> 6) & 7))
    stick_of = stick_reader(before, mask, stick, layout)
    moves, _ = observed_moves(LiftedRules(layout, stick_of), before, after, actions, mask)
    flip = 1 << (len(layout.kept) - 1)  # the first kept bit

    def relabel(sig, out):
        if sig["cls"] == "cube" and sig["to"] == 2:
            o = out[0]
            return sig, ((o[0], o[1], o[2], o[3] ^ flip), *out[1:])
        return sig, out
    rules = distil_lifted(layout, stick_of, [relabel(*m) for m in moves], min_count=1, model_hash="ab" * 8)
    cube_to = [dict(r.key)["to"] for r in rules.rules if dict(r.key)["cls"] == "cube" and "to" in dict(r.key)]
    assert (2,) in cube_to and any(len(t) > 1 and 2 not in t for t in cube_to), cube_to
    domain = domain_pddl(rules)
    assert "(differ ?to l2)" in domain and "(:action release-cube-to-l2-" in domain
    assert negated_bits(rules) == frozenset() and "no-bit-" not in domain  # no rule tests a bit
    assert _bits_as_the_rules_set_them(rules, domain) >= 6


def _bits_as_the_rules_set_them(rules, domain: str, starts=None) -> int:
    """How many robot actions of the PDDL (from the start codes given, else six 2-object scenes; up's simulator)
    leave every object's kept bits as the rule of the same action does; fails on the first that does not, or on an
    action no rule has."""
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import SequentialSimulator, get_environment
    get_environment().credits_stream = None
    checked = 0
    decode = plan_decoder(rules)
    for start in starts if starts is not None else [m[0] for m in world_moves(6, seed=5, objects=(2, 2))]:
        problem = PDDLReader().parse_problem_string(domain, problem_pddl(rules, start, SymbolicGoal(tuple(start)), "p"))
        pieces = rules.pieces(start)
        with SequentialSimulator(problem) as sim:
            state = sim.get_initial_state()
            for a, nxt in _robot_moves(sim, state, decode):
                want, rule = rules.step_pieces(pieces, a)
                assert rule is not None, f"the PDDL offers action {a} from {start}, no rule does"
                for i, p in enumerate(want):
                    o = problem.object(object_name(i))
                    kind = 0
                    for b in rules.layout.kept:
                        kind = (kind << 1) | int(nxt.get_value(problem.fluent(f"bit-{b}")(o)).bool_constant_value())
                    assert kind == p.kind, f"object {i}'s kept bits after action {a} from {start}"
                checked += 1
    return checked


def test_a_bit_a_rule_tests_as_zero_gets_its_negative_form_and_no_other_does():
    """Bits are plain predicates (`bit-I` true where the bit is 1). Where a rule's condition reads a bit as 0 (here
    each cube move is seen again with o's last kept bit flipped and another outcome kind, so the tree refines on o's
    kind), that bit also gets `no-bit-I`, maintained by every action and stated in every problem, so that no
    precondition is negative; a bit no rule tests as 0 does not; and the PDDL's actions still set the bits the rules
    set, from scenes whose cubes have the bit at 0 as well."""
    before, actions, after, mask, stick = _arrays(world_moves(400, seed=3, objects=(2, 2)))
    objs = before[mask]
    layout = CodeLayout(8, kept_bits((objs[:, None] >> (9 + np.arange(7, -1, -1))) & 1, (objs >> 6) & 7))
    assert len(layout.kept) >= 2
    stick_of = stick_reader(before, mask, stick, layout)
    moves, _ = observed_moves(LiftedRules(layout, stick_of), before, after, actions, mask)
    first, last = 1 << (len(layout.kept) - 1), 1

    def twin(sig, out):  # the same cube move with the last kept bit flipped, its cube taking another kind
        o = out[0]
        return {**sig, "o.kind": sig["o.kind"] ^ last}, ((o[0], o[1], o[2], o[3] ^ first), *out[1:])
    twins = [twin(*m) for m in moves if m[0]["cls"] == "cube"]
    rules = distil_lifted(layout, stick_of, moves + twins, min_count=20, model_hash="cd" * 8)
    tested = {dict(r.key)["o.kind"] for r in rules.rules if "o.kind" in dict(r.key)}
    assert tested, "the tree should refine on o's kind"
    zero = {b for pos, b in enumerate(layout.kept) for k in tested if not (k >> (len(layout.kept) - 1 - pos)) & 1}
    assert negated_bits(rules) == zero and layout.kept[-1] in zero and layout.kept[0] not in zero  # bit 0 is 1 here
    domain = domain_pddl(rules)
    declared = {int(b) for b in re.findall(r"\(no-bit-(\d+) \?b - block\)", domain)}
    assert declared == zero and set(layout.kept) - zero <= {int(b) for b in re.findall(r"\(bit-(\d+) \?b", domain)}
    preconditions = [a.split(":effect")[0] for a in domain.split("(:action")[1:]]
    assert any(f"(no-bit-{layout.kept[-1]} ?o)" in pre for pre in preconditions)
    # a scene as the world has it and the same with each cube's last kept bit flipped (a kind no start of
    # the world has here), so that the init states no-bit-I and actions whose precondition reads it run too
    scenes = [m[0] for m in world_moves(1, seed=5, objects=(2, 2))]
    flipped = [tuple(c if rules.is_stick(c) else (layout.with_kind(layout.learned(c), layout.kind(c) ^ last) << 9)
                     | (c & 511) for c in scene) for scene in scenes]
    assert [[p.stick for p in rules.pieces(f)] for f in flipped] == [[p.stick for p in rules.pieces(s)] for s in scenes]
    for start in scenes + flipped:
        init = problem_pddl(rules, start, SymbolicGoal(tuple(start)), "p").split("(:goal")[0]
        for i, p in enumerate(rules.pieces(start)):
            for pos, b in enumerate(layout.kept):
                one = (p.kind >> (len(layout.kept) - 1 - pos)) & 1
                assert (f"(bit-{b} o{i})" in init) == bool(one)
                assert (f"(no-bit-{b} o{i})" in init) == (not one and b in zero)
    assert any("(no-bit-" in problem_pddl(rules, f, SymbolicGoal(tuple(f)), "p") for f in flipped)
    fired = [r for f in flipped for a in range(36) if (r := rules.step_pieces(rules.pieces(f), a)[1]) is not None]
    assert any(not r.fields().get("o.kind", last) & last for r in fired)  # a rule that reads the bit as 0 fires
    assert _bits_as_the_rules_set_them(rules, domain, scenes + flipped) >= 2


def test_rarer_structures_take_their_pools_change_and_reproduce_the_world(tmp_path):
    """A structure seen fewer than min_count times takes its pool's change relative to the top it lands on (a cube
    ends 2 levels above it, a stick 1): exact on held-out moves of the world, one schema per pool whose static
    facts list its structures, and back through JSON; a pool whose rules disagree is refused."""
    import json
    from pddl_export.lifted_domain import static_facts
    from pddl_export.lifted_moves import moves
    rules = _distil(world_moves(1500, seed=0), min_count=60, pool_min_count=10, pool_structure_min=2)
    plain = _distil(world_moves(1500, seed=0), min_count=60)
    pooled = [r for r in rules.rules if r.pool is not None]
    assert rules.stats["pooled_rules"] == len(pooled) >= 10 and len(rules.rules) == len(plain.rules) + len(pooled)
    assert {r.outcome[0][2] - r.fields()["v.level"] for r in pooled if not r.fields()["o.stick"]} == {2}
    fired = exact = 0
    for before, action, after, _ in world_moves(600, seed=1):
        got, rule = rules.step_pieces(rules.pieces(before), action)
        if rule is None or rule.pool is None:
            assert plain.step_pieces(plain.pieces(before), action)[1] == rule  # the others are the plain rules'
            continue
        assert plain.step_pieces(plain.pieces(before), action)[1] is None
        fired += 1
        exact += [(p.loc, p.place, p.level, p.kind) for p in got] == \
                 [(p.loc, p.place, p.level, p.kind) for p in rules.pieces(after)]
    assert fired >= 20 and exact == fired
    written = [s for s in moves(rules) if s.statics]
    assert len(written) == rules.stats["pools"]
    facts = static_facts(moves(rules))
    assert sum(len(s.statics) for s in written) == len({f for f in facts if f.startswith("(pooled-")}) == \
        len({(r.pool, r.fields()["o.level"], r.fields()["u.level"], r.fields()["u.at"], r.fields()["v.level"],
              r.fields()["v.at"]) for r in pooled})
    text = domain_pddl(rules)
    assert all(f"({s.predicate[1:].split()[0]} ?h ?t ?top ?new)" in text for s in written)
    path = tmp_path / "lifted.json"
    path.write_text(json.dumps(rules.to_json()))
    assert load_lifted(path).rules == rules.rules
    d = rules.to_json()
    first = next(r for r in d["rules"] if "pool" in r)
    other = next(r for r in d["rules"] if r.get("pool") not in (None, first["pool"]))
    other["pool"] = first["pool"]
    path.write_text(json.dumps(d))
    with pytest.raises(ValueError, match="the rules of one pool must share its key and relative outcome"):
        load_lifted(path)


@pytest.mark.parametrize("change, message", [({"source": "net"}, "source='net' must be one of observed, network"),
                                             ({"pool_min_count": -1}, "pool_min_count=-1 must be a non-negative"),
                                             ({"end_min_count": -2}, "end_min_count=-2 must be a non-negative"),
                                             ({"pair_min_count": 0}, "pair_min_count=0 must be a positive integer"),
                                             ({"min_gain": 1.0}, "min_gain=1.0 must lie in [0, 1)")])
def test_lifted_settings_are_refused_in_one_line(change, message):
    from symlearn.export.lifted_export import LiftedConfig
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("(", r"\(").replace(")", r"\)")):
        LiftedConfig(**change)


def _true_atoms(problem, state, predicates) -> set[str]:
    """The ground atoms of the given predicates that hold in a unified-planning state, as '(p a b)' strings."""
    out = set()
    for name in predicates:
        fluent = problem.fluent(name)
        domains = [[o for o in problem.all_objects if o.type == p.type or o.type.is_subtype(p.type)]
                   for p in fluent.signature]
        for args in itertools.product(*domains):
            if state.get_value(fluent(*args)).bool_constant_value():
                out.add(f"({name} {' '.join(a.name for a in args)})")
    return out


END_STATE_PREDICATES = ("at", "level", "stands", "place", "height", "beneath", "rests")


def test_a_pick_at_a_stick_end_drags_the_stick_and_the_pddl_does_the_same(pair_rules):
    """End rules (pddl_export.end_moves): one per (stick's location, pick, release) class, its most frequent change,
    refused where the PDDL cannot state it; the PDDL's successor of every end move is the rules' successor, whole
    (locations, levels, places, heights, what lies beneath the stick's ends), and no other action stands for it."""
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import SequentialSimulator, get_environment
    from pddl_export.end_moves import EndRule, distil_end_rules, end_case, end_participants
    get_environment().credits_stream = None
    stick, cube = (lambda loc, level: Piece(1, True, loc, 0, level)), (lambda loc, level: Piece(2, False, loc, 0, level))
    code = lambda p: pair_rules.code_of(p, 0)  # noqa: E731
    # distilled: the majority per class, min_count, its cases seen case_min times, and no rule for a stick ending
    # on its spot in the far row
    g = read_scene((stick(0, 1),))
    m13, m12 = end_participants(g, 1, 3), end_participants(g, 1, 2)
    assert m13.cls == (0, 1, 3) and end_participants(g, 0, 3) is None and end_participants(g, 2, 3) is None
    triples = [(g, m13, (3, 2, 1, 0))] * 5 + [(g, m13, (4, 2, 1, 0))] * 2 + [(g, m12, (1, 0, 1, 1))] * 9
    case = end_case(g, m13, 3)
    assert case == (1, (0, False), (0,), (0, False))
    assert distil_end_rules(triples, min_count=6) == (EndRule((0, 1, 3), 3, 2, 0, 7, round(5 / 7, 4), (case,)),)
    assert distil_end_rules(triples, min_count=6, case_min=8) == ()
    assert distil_end_rules(triples[:5], min_count=6) == ()
    templates = (EndRule((0, 1, 3), 3, 2, 0, 7, 0.7), EndRule((1, 0, 1), 1, 4, 1, 9, 0.6),
                 EndRule((1, 2, 0), 0, 5, 1, 9, 0.6), EndRule((2, 1, 4), 4, 0, 0, 9, 0.6))
    scenes = [(stick(0, 1),), (stick(0, 1), cube(3, 2)), (stick(1, 1), cube(0, 2)), (cube(1, 2), stick(1, 3)),
              (stick(2, 1),), (stick(2, 1), cube(4, 2), cube(5, 2)), (stick(1, 1),)]
    unlisted = scenes[5]  # a case of no rule: the stick at l2 with a cube at l4 is not dragged there
    cases: dict = {}
    for pieces in scenes:
        graph = read_scene(pieces)
        for t in templates:
            m = end_participants(graph, t.cls[1], t.cls[2])
            if m is not None and m.cls == t.cls and pieces != unlisted:
                cases.setdefault(t.cls, set()).add(end_case(graph, m, t.destination))
    ends = tuple(dataclasses.replace(t, cases=tuple(sorted(cases[t.cls], key=repr))) for t in templates)
    rules = dataclasses.replace(pair_rules, end_rules=ends)
    assert rules.step_pieces(unlisted, 1 * 6 + 4) == (unlisted, None)
    domain = domain_pddl(rules)
    fired = set()
    decode = plan_decoder(rules)
    for pieces in scenes:
        start = [code(p) for p in pieces]
        problem = PDDLReader().parse_problem_string(domain, problem_pddl(rules, start, SymbolicGoal(tuple(start)), "p"))
        with SequentialSimulator(problem) as sim:
            by_action: dict = {}
            for a, nxt in _robot_moves(sim, sim.get_initial_state(), decode):
                by_action.setdefault(a, []).append(nxt)
        for a in range(36):
            want, rule = rules.step_pieces(rules.pieces(start), a)
            assert (rule is not None) == (a in by_action) and len(by_action.get(a, [])) <= 1, f"action {a}, {pieces}"
            if not isinstance(rule, EndRule):
                continue
            fired.add((rule.cls, pieces))
            after = [code(p) for p in want]
            expected, _ = _facts(problem_pddl(rules, after, SymbolicGoal(tuple(after)), "p"))
            got = _true_atoms(problem, by_action[a][0], END_STATE_PREDICATES)
            assert got == {f for f in expected if f.split()[0][1:] in END_STATE_PREDICATES}, f"action {a}, {pieces}"
    assert {cls for cls, _ in fired} == {r.cls for r in ends}
    # the stick lands one layer above the top it finds: on the cube at l3, on the table at l1, back at l1 on the cube
    assert rules.step_pieces((stick(0, 1), cube(3, 2)), 1 * 6 + 3)[0][0] == Piece(0, True, 3, 2, 3)
    assert rules.step_pieces((cube(1, 2), stick(1, 3)), 0 * 6 + 0)[0] == (cube(1, 2), stick(1, 3))  # same location
    assert rules.step_pieces((cube(1, 2), stick(1, 3)), 0 * 6 + 3)[0] == (cube(1, 2), stick(1, 3))  # no rule
    assert rules.step_pieces((cube(1, 2), stick(1, 3)), 0 * 6 + 1)[0][1] == Piece(1, True, 1, 4, 3)  # back on it
    assert rules.step_pieces((cube(1, 2), stick(1, 3)), 2 * 6 + 0)[0][1] == Piece(1, True, 0, 5, 1)


def test_end_rules_round_trip_through_json_and_a_bad_one_is_refused(pair_rules, tmp_path):
    import json
    from pddl_export.end_moves import EndRule
    rules = dataclasses.replace(pair_rules, end_rules=(EndRule((0, 1, 3), 3, 2, 0, 7, 0.7, (
        (1, (0, False), (0,), (0, False)), (3, (2, True), (0,), (2, True)))),))
    path = tmp_path / "lifted.json"
    path.write_text(json.dumps(rules.to_json()))
    assert load_lifted(path).end_rules == rules.end_rules
    for bad, message in (({"class": [0, 2, 3]}, "no pick at a far-row stick's end"),
                         ({"destination": 1, "place": 0}, "is not one the PDDL states"),
                         ({"cases": [[1, [0, False], [0, 0], [0, False]]]}, "does not fit its class")):
        d = rules.to_json()
        d["end_rules"][0].update(bad)
        path.write_text(json.dumps(d))
        with pytest.raises(ValueError, match=f"malformed lifted rules .*{message}"):
            load_lifted(path)


@pytest.mark.parametrize("planner", ["fd-lmcut", "fd-lama-first"])
def test_stock_planners_drag_a_stick_by_its_end_in_a_domain_with_pools(pooled_pair_rules, tmp_path,
                                                                        planner):
    """The schemas of end rules and of pools, with the static facts they list, are plain typed STRIPS that stock
    Fast Downward takes: a stick lying at l0 is picked at its end (l1) and dragged to l3, a 1-step plan that
    unified-planning's validator, reading the files with its own parser, accepts. (pyperplan's grounder enumerates
    every binding of their six layer parameters before it reads the static facts, and pyval spends minutes on its
    state bookkeeping for this task: both are left out here; docs/DOMAIN.md.)"""
    from unified_planning.io import PDDLReader
    from unified_planning.plans import SequentialPlan
    from unified_planning.shortcuts import PlanValidator

    from pddl_export.end_moves import EndRule
    from search.stock_planners import solve_files
    rules = dataclasses.replace(pooled_pair_rules, end_rules=(EndRule((0, 1, 3), 3, 2, 0, 7, 0.7,
                                                                      ((1, (0, False), (0,), (0, False)),)),))
    start_pieces = (Piece(1, True, 0, 0, 1), Piece(2, False, 5, 0, 2))
    want, rule = rules.step_pieces(start_pieces, 1 * 6 + 3)
    assert isinstance(rule, EndRule) and want[0] == Piece(0, True, 3, 2, 1)
    start = [rules.code_of(p, 0) for p in start_pieces]
    goal = [rules.code_of(want[0], 0), None]
    (tmp_path / "domain.pddl").write_text(domain_pddl(rules))
    (tmp_path / "p01.pddl").write_text(problem_pddl(rules, start, SymbolicGoal(tuple(goal)), "p01"))
    res = solve_files(tmp_path / "domain.pddl", tmp_path / "p01.pddl", planner, timeout_s=120,
                      action_ids=lambda steps: plan_actions(rules, steps))
    assert res.found and tuple(res.plan) == (1 * 6 + 3,), res.message
    (tmp_path / "plan.txt").write_text("".join(f"{s}\n" for s in res.steps))
    reader = PDDLReader()
    problem = reader.parse_problem(str(tmp_path / "domain.pddl"), str(tmp_path / "p01.pddl"))
    plan = reader.parse_plan(problem, str(tmp_path / "plan.txt"))
    with PlanValidator(problem_kind=problem.kind) as validator:
        assert validator.validate(problem, plan).status.name == "VALID"
        assert validator.validate(problem, SequentialPlan([])).status.name == "INVALID"  # the stick stays at l0
    assert any(s.statics for s in schemas(rules) if "pooled" in s.name)  # the pools' schemas were in the domain


def test_the_presets_of_export_pddl():
    """fast (the default): no pools, no end rules; accurate: rarer structures of its own, far-row pairs only where
    seen more often, pooled cubes and end rules; --preset with --rules is refused in one line."""
    from symlearn.export.lifted_export import LIFTED_PRESETS, LiftedConfig
    fast = LIFTED_PRESETS["fast"]
    assert fast == LiftedConfig() and fast.pool_min_count == 0 == fast.end_min_count
    acc = LIFTED_PRESETS["accurate"]
    assert (fast.min_count, fast.rider_min_count) == (20, 6) and (acc.min_count, acc.rider_min_count) == (30, 3)
    assert acc.pair_min_count > fast.pair_min_count
    assert acc.pool_min_count > 0 and acc.end_min_count > 0 and set(acc.pool_classes) == {"cube"}
    with pytest.raises(ValueError, match="pool_classes=.* must name some of cube, near"):
        LiftedConfig(pool_classes=("pair",))
