"""Enumeration, exact rule distillation and PDDL export, checked against hand-made networks.

ToyRobot mimics what the learned network does on the tabletop with 3-bit codes: a near cube
is placed on the far row unless a stick is there (then it lands on the stick, unless the
stick already carries a rider), the stick moves and carries its rider, three far cubes make
the bottom ones occluded, uncovering needs the ABSENCE of far cubes, and one action changes
nothing. RandomEquivariant is an arbitrary permutation-equivariant function (a random table
over (action, own code, multiset of others)) that stresses exactness.
"""
from __future__ import annotations

import itertools
import re
from math import comb

import numpy as np
import pytest

from pddl_export.enumeration import enumerate_transitions, multiset_indices, vocabulary_closure
from pddl_export.pddl_writer import (
    StateLimitError,
    action_id_from_name,
    action_name,
    code_from_predicate,
    code_predicate,
    conditional_domain,
    object_name,
    pddl_name,
    problem_pddl,
    reachable_transitions,
    strips_pddl,
)
from pddl_export.files import atomic_write_text
from pddl_export.distil import NotEquivariantError, distil_rules
from pddl_export.fidelity import rule_fidelity
from pddl_export.rules import COUNT_CAP, INF, AmbiguousRulesError, Rule, RuleSet, _first_overlap, apply_rules, apply_rules_batch
from pddl_export.symbolic import N_ACTIONS

NEAR, FAR, STICK, RIDER, UNDER, STICK_M, RIDER_M = 1, 2, 3, 4, 5, 6, 7
A_PLACE, A_STACK, A_STICK, A_UNCOVER, A_BACK, A_NOOP = 3, 10, 22, 24, 27, 35
TOY_VOCAB = (NEAR, FAR, STICK, RIDER, UNDER, STICK_M, RIDER_M)


class ToyRobot:
    """Hand-made permutation-equivariant transition function with 3-bit codes (see module doc)."""

    bits = 3

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        codes = np.asarray(codes, np.int64)
        a = np.asarray(actions)[:, None]

        def others(x: int) -> np.ndarray:  # (B, K) how many OTHER objects have code x
            return (codes == x).sum(1, keepdims=True) - (codes == x)

        out = codes.copy()
        changes = [
            ((a == A_PLACE) & (codes == NEAR) & (others(STICK) == 0), FAR),
            ((a == A_PLACE) & (codes == NEAR) & (others(STICK) > 0) & (others(RIDER) == 0), RIDER),
            ((a == A_STACK) & (codes == FAR) & (others(FAR) >= 2), UNDER),
            ((a == A_STICK) & (codes == STICK), STICK_M),
            ((a == A_STICK) & (codes == RIDER) & (others(STICK) > 0), RIDER_M),
            ((a == A_BACK) & (codes == STICK_M), STICK),
            ((a == A_BACK) & (codes == RIDER_M) & (others(STICK_M) > 0), RIDER),
            ((a == A_UNCOVER) & (codes == FAR), NEAR),
            ((a == A_UNCOVER) & (codes == UNDER) & (others(FAR) == 0), FAR),
        ]
        for mask, value in changes:  # masks read the pre-state `codes`: simultaneous update
            out[mask] = value
        return out


class RandomEquivariant:
    """Random outcome per (action, own code, sorted others); only `actions` ever change anything."""

    def __init__(self, bits: int, vocab: tuple[int, ...], actions: tuple[int, ...], seed: int, p_change: float = 0.4):
        self.bits, self.vocab, self.actions, self.p = bits, vocab, set(actions), p_change
        self.rng = np.random.default_rng(seed)
        self.table: dict = {}

    def outcome(self, a: int, own: int, others: tuple[int, ...]) -> int:
        key = (a, own, tuple(sorted(others)))
        if key not in self.table:
            change = a in self.actions and self.rng.random() < self.p
            self.table[key] = int(self.rng.choice(self.vocab)) if change else own
        return self.table[key]

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = np.array(codes, np.int64)
        for b, (row, a) in enumerate(zip(np.asarray(codes).tolist(), np.asarray(actions).tolist())):
            for i, c in enumerate(row):
                out[b, i] = self.outcome(a, c, tuple(row[:i] + row[i + 1:]))
        return out


class PositionDependent:
    """Not equivariant: object 0 behaves differently from the others."""

    bits = 2

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        out = np.array(codes, np.int64)
        out[:, 0] = np.where(actions == 0, 3, out[:, 0])
        return out


@pytest.fixture(scope="module")
def toy():
    enum = enumerate_transitions(ToyRobot(), TOY_VOCAB, max_objects=3)
    return enum, distil_rules(enum)


@pytest.fixture(scope="module")
def random_nets():
    """Three random equivariant functions over 2-bit codes, a few changing actions each."""
    out = []
    for seed in range(3):
        net = RandomEquivariant(2, (0, 1, 2), actions=(0, 7, 35), seed=seed)
        enum = enumerate_transitions(net, (0, 1, 2), max_objects=3)
        out.append((net, enum, distil_rules(enum)))
    return out


# ----------------------------------------------------------------------------- enumeration


@pytest.mark.parametrize("n,k", [(1, 1), (1, 3), (3, 1), (4, 2), (5, 3), (3, 4)])
def test_multiset_indices_match_itertools(n, k):
    want = np.array(list(itertools.combinations_with_replacement(range(n), k)))
    assert np.array_equal(multiset_indices(n, k), want)


def test_enumeration_counts_and_batches(toy):
    enum, _ = toy
    v = len(TOY_VOCAB)
    assert [len(b.scenes) for b in enum.blocks] == [comb(v + k - 1, k) for k in (1, 2, 3)]
    assert enum.n_queries == sum(comb(v + k - 1, k) for k in (1, 2, 3)) * N_ACTIONS
    assert enum.n_calls == 3 and enum.queries_per_s > 0
    small = enumerate_transitions(ToyRobot(), TOY_VOCAB, max_objects=3, batch_size=100)
    assert small.n_calls == sum(-(-len(b.scenes) * N_ACTIONS // 100) for b in enum.blocks)
    for b, s in zip(enum.blocks, small.blocks):
        assert np.array_equal(b.next_codes, s.next_codes)
    with pytest.raises(ValueError):
        enum.blocks[0].next_codes[0, 0] = 0  # read-only arrays


def test_enumeration_matches_slow_reference(toy):
    enum, _ = toy
    net = ToyRobot()
    for b in enum.blocks:
        scenes = list(itertools.combinations_with_replacement(TOY_VOCAB, b.n_objects))
        assert np.array_equal(b.scenes, np.array(scenes))
        for r, (scene, a) in enumerate(itertools.product(scenes, range(N_ACTIONS))):
            want = net(np.array([scene]), np.array([a]))[0]
            assert b.actions[r] == a and np.array_equal(b.next_codes[r], want)


def test_vocabulary_closure_reaches_fixed_point():
    closure = vocabulary_closure(ToyRobot(), [NEAR, STICK], max_objects=3)
    assert closure.converged and closure.vocabulary == TOY_VOCAB
    assert closure.added == ((FAR, RIDER, STICK_M), (UNDER, RIDER_M))
    assert closure.enumeration.vocabulary == TOY_VOCAB
    assert closure.n_queries > closure.enumeration.n_queries
    short = vocabulary_closure(ToyRobot(), [NEAR, STICK], max_objects=3, max_iterations=1)
    assert not short.converged and short.missing == (FAR, RIDER, STICK_M)


def test_enumeration_refuses_bad_input():
    with pytest.raises(ValueError):
        enumerate_transitions(ToyRobot(), [8], max_objects=2)  # does not fit in 3 bits
    with pytest.raises(ValueError):
        enumerate_transitions(ToyRobot(), [], max_objects=2)
    with pytest.raises(ValueError):
        enumerate_transitions(ToyRobot(), [1], max_objects=0)


# ----------------------------------------------------------------------------- rules


def test_toy_rules_are_exact_and_general(toy):
    enum, rs = toy
    assert set(rs.rules) == {
        Rule(A_PLACE, NEAR, FAR, forbids=(STICK,)),
        Rule(A_PLACE, NEAR, RIDER, requires=(STICK,), forbids=(RIDER,)),
        Rule(A_STACK, FAR, UNDER, at_least=((FAR, 2),)),
        Rule(A_STICK, STICK, STICK_M),
        Rule(A_STICK, RIDER, RIDER_M, requires=(STICK,)),
        Rule(A_BACK, STICK_M, STICK),
        Rule(A_BACK, RIDER_M, RIDER, requires=(STICK_M,)),
        Rule(A_UNCOVER, FAR, NEAR),
        Rule(A_UNCOVER, UNDER, FAR, forbids=(FAR,)),
    }
    assert A_NOOP not in rs.actions and rs.actions == (A_PLACE, A_STACK, A_STICK, A_UNCOVER, A_BACK)
    assert rs.n_rules < rs.n_rules_before_generalization
    fid = rule_fidelity(rs, enum)
    assert fid.fraction == 1.0 and fid.n_transitions == enum.n_queries and not fid.mismatches
    assert rule_fidelity(rs, enum, reference=True).n_exact == enum.n_queries


def test_n_rules_before_generalization_counts_changing_cases(toy):
    enum, rs = toy
    cases = set()
    for b in enum.blocks:
        for scene, a, nxt in zip(b.states.tolist(), b.actions.tolist(), b.next_codes.tolist()):
            for i, (c, d) in enumerate(zip(scene, nxt)):
                if c != d:
                    cases.add((a, c, tuple(sorted(scene[:i] + scene[i + 1:]))))
    assert rs.n_rules_before_generalization == len(cases)


def test_random_functions_are_reproduced_exactly(random_nets):
    rng = np.random.default_rng(0)
    for _, enum, rs in random_nets:
        fid = rule_fidelity(rs, enum)
        assert fid.fraction == 1.0 and fid.n_object_codes_exact == fid.n_object_codes
        assert rule_fidelity(rs, enum, reference=True).fraction == 1.0
        assert set(rs.actions) <= {0, 7, 35}
        # batched and reference semantics agree beyond the enumerated scene sizes too
        codes = rng.choice([0, 1, 2], size=(200, 5))
        actions = rng.choice([0, 7, 35, 1], size=200)
        batch = apply_rules_batch(rs, codes, actions)
        for row, a, got in zip(codes, actions, batch):
            assert np.array_equal(apply_rules(rs, row, int(a)), got)
    assert any(r.at_least or r.fewer_than for _, _, rs in random_nets for r in rs.rules)


def test_apply_rules_is_simultaneous():
    rules = (Rule(0, 1, 2), Rule(0, 2, 1))  # swap codes 1 and 2 in one step
    assert apply_rules(rules, np.array([1, 2, 2]), 0).tolist() == [2, 1, 1]
    assert apply_rules(rules, np.array([1, 2]), 5).tolist() == [1, 2]
    with pytest.raises(AmbiguousRulesError):
        apply_rules((Rule(0, 1, 2), Rule(0, 1, 3)), np.array([1]), 0)


def test_rule_and_ruleset_validation():
    with pytest.raises(ValueError):
        Rule(0, 1, 1)  # no change
    with pytest.raises(ValueError):
        Rule(36, 1, 2)
    with pytest.raises(ValueError):
        Rule(0, 1, 2, requires=(3,), forbids=(3,))
    with pytest.raises(ValueError):
        Rule(0, 1, 2, at_least=((3, 1),))
    with pytest.raises(ValueError):
        Rule(0, 1, 2, at_least=((3, 3),), fewer_than=((3, 2),))
    ok = RuleSet(2, (1, 2, 3), 2, (Rule(0, 1, 2, forbids=(3,)), Rule(0, 1, 3, requires=(3,))), 2)
    assert ok.n_rules == 2 and ok.codes == (1, 2, 3)
    with pytest.raises(ValueError, match="mutually exclusive"):  # the exactness pitfall (docs/DESIGN.md)
        RuleSet(2, (1, 2, 3), 2, (Rule(0, 1, 2), Rule(0, 1, 3, requires=(3,))), 2)
    with pytest.raises(ValueError):
        RuleSet(2, (1, 2, 3), 2, (Rule(0, 1, 4),), 1)  # code 4 does not fit in 2 bits
    assert Rule(0, 1, 2, requires=(3,), fewer_than=((3, 2),)).matches({3: 1})
    assert not Rule(0, 1, 2, requires=(3,), fewer_than=((3, 2),)).matches({3: 2})
    with pytest.raises(ValueError, match="count bound above"):  # bounds are compared as int16
        RuleSet(2, (1, 2, 3), 2, (Rule(0, 1, 2, at_least=((3, COUNT_CAP + 1),)),), 1)
    assert RuleSet(2, (1, 2, 3), 2, (Rule(0, 1, 2, at_least=((3, COUNT_CAP),)),), 1).n_rules == 1


def test_overlap_check_and_batch_application_in_chunks():
    """The overlap check and apply_rules_batch work in chunks; any chunk size gives the same answers."""
    # eight disjoint rules of action 4 on code 1: exactly x other objects with code 3, x = 0..7
    rules = tuple(Rule(4, 1, 2, at_least=((3, x),) if x > 1 else (), requires=(3,) if x == 1 else (),
                       forbids=(3,) if x == 0 else (), fewer_than=((3, x + 1),) if x > 0 else ()) for x in range(8))
    rs = RuleSet(2, (1, 2, 3), 9, rules, 8)
    lo, hi = rs.dense_groups[(4, 1)][1:3]
    assert lo.dtype == np.int16 and lo.shape == (8, 1)
    assert _first_overlap(lo, hi, max_cells=1) is None and _first_overlap(lo, hi) is None
    hi2 = hi.copy()
    hi2[5, 0] = 7  # box 5 now also holds counts 6: overlaps box 6
    assert _first_overlap(lo, hi2, max_cells=1) == _first_overlap(lo, hi2) == (5, 6)
    rng = np.random.default_rng(3)
    codes, actions = rng.choice([1, 2, 3], size=(300, 9)), rng.choice([4, 5], size=300)
    want = np.stack([apply_rules(rs, row, int(a)) for row, a in zip(codes, actions)])
    for cells in (1, 7, 1 << 22):
        assert np.array_equal(apply_rules_batch(rs, codes, actions, max_cells=cells), want)
    assert (want != codes).any() and (want == codes).any()


def test_non_equivariant_network_is_refused():
    enum = enumerate_transitions(PositionDependent(), (0, 1), max_objects=2)
    with pytest.raises(NotEquivariantError):
        distil_rules(enum)


# ----------------------------------------------------------------------------- PDDL text


def _pddl_parse(domain: str, problem: str):
    """Parse with the independent `pddl` package (its parser leaves sys.tracebacklimit at 0 on errors)."""
    import sys

    from pddl.parser.domain import DomainParser
    from pddl.parser.problem import ProblemParser

    old = getattr(sys, "tracebacklimit", None)
    try:
        return DomainParser()(domain), ProblemParser()(problem)
    finally:
        if old is None and hasattr(sys, "tracebacklimit"):
            del sys.tracebacklimit


def _up_parse(domain: str, problem: str):
    from unified_planning.io import PDDLReader
    from unified_planning.shortcuts import get_environment

    get_environment().credits_stream = None
    return PDDLReader().parse_problem_string(domain, problem)


def test_names():
    assert code_predicate(27, 8) == "code-00011011" and code_from_predicate("code-00011011") == 27
    assert action_name(3 * 6 + 4) == "pick-3-release-4"
    assert action_id_from_name("pick-3-release-4") == 22 and action_id_from_name("PICK-3-release-4-s17") == 22
    assert object_name(2) == "o2"
    assert pddl_name("My Model/v2.pt") == "my-model-v2-pt" and pddl_name("3d") == "x-3d"
    for bad in ("pick-6-release-0", "move", "pick-1-release-2-x"):
        with pytest.raises(ValueError):
            action_id_from_name(bad)
    with pytest.raises(ValueError):
        pddl_name("!!!")


def test_conditional_domain_parses_with_both_parsers(toy, tmp_path):
    from pddl import parse_domain, parse_problem
    from pddl.requirements import Requirements as R

    _, rs = toy
    domain = conditional_domain(rs, model_hash="sha256:abc\ndef", name="Learned Symbols")
    problem = problem_pddl(rs, [NEAR, STICK, NEAR], [RIDER_M, None, None], model_hash="sha256:abc", name="t1",
                           domain_name="Learned Symbols")
    header = [ln for ln in domain.splitlines() if ln.startswith(";;")]
    assert ";; model-hash: sha256:abc def" in header and ";; vocabulary-size: 7" in header
    assert f";; rules: 9 (before generalization: {rs.n_rules_before_generalization})" in header
    assert re.findall(r"\(:action (\S+)", domain) == [action_name(a) for a in rs.actions]
    d, p = _pddl_parse(domain, problem)
    assert d.requirements == {R.STRIPS, R.TYPING, R.CONDITIONAL_EFFECTS, R.EXISTENTIAL_PRECONDITION,
                              R.UNIVERSAL_PRECONDITION, R.NEG_PRECONDITION, R.EQUALITY}
    assert {a.name for a in d.actions} == {action_name(a) for a in rs.actions} and p.name == "t1"
    dpath = atomic_write_text(tmp_path / "domain.pddl", domain)
    ppath = atomic_write_text(tmp_path / "problem.pddl", problem)
    assert parse_domain(dpath).name == "learned-symbols" and len(parse_problem(ppath).objects) == 3
    up_problem = _up_parse(domain, problem)
    assert {a.name for a in up_problem.actions} == {action_name(a) for a in rs.actions}
    assert sorted(o.name for o in up_problem.all_objects) == ["o0", "o1", "o2", "the-scene"]
    assert len(up_problem.goals) == 1


def _pddl_successor(domain: str, rules: RuleSet, codes: list[int], action: int) -> list[int]:
    """Each object's code after `action`, simulated on the written PDDL by unified-planning (-1: not one code)."""
    from unified_planning.shortcuts import SequentialSimulator

    prob = _up_parse(domain, problem_pddl(rules, codes, [codes[0]] + [None] * (len(codes) - 1), "h"))
    names = [a.name for a in prob.actions]
    if action_name(action) not in names:
        return list(codes)
    objs = [prob.object(object_name(i)) for i in range(len(codes))]
    fluents = {c: prob.fluent(code_predicate(c, rules.bits)) for c in rules.codes}
    with SequentialSimulator(prob) as sim:
        state = sim.apply(sim.get_initial_state(), prob.action(action_name(action)), ())
        held = [[c for c, f in fluents.items() if state.get_value(f(o)).bool_constant_value()] for o in objs]
    return [h[0] if len(h) == 1 else -1 for h in held]


def test_requirements_follow_what_is_used():
    """Declared requirements match the features used, and the written conditions mean what the rules say."""
    from pddl.requirements import Requirements as R

    plain = RuleSet(2, (1, 2), 2, (Rule(0, 1, 2),), 1)
    d, _ = _pddl_parse(conditional_domain(plain, "h"), problem_pddl(plain, [1], [2], "h"))
    assert d.requirements == {R.STRIPS, R.TYPING, R.CONDITIONAL_EFFECTS} and not d.constants
    absent = RuleSet(2, (1, 2, 3), 2, (Rule(0, 1, 2, forbids=(3,)),), 1)
    text = conditional_domain(absent, "h")
    d, _ = _pddl_parse(text, problem_pddl(absent, [1], [2], "h"))
    assert d.requirements == {R.STRIPS, R.TYPING, R.CONDITIONAL_EFFECTS, R.EXISTENTIAL_PRECONDITION,
                              R.UNIVERSAL_PRECONDITION, R.NEG_PRECONDITION, R.EQUALITY}
    # a context is wrapped in a universal over a one-object type (see the writer's docstring)
    assert [str(c.name) for c in d.constants] == ["the-scene"]
    # "no other object has 3": the rule fires unless another object holds 3, and an object's own 3 does not count
    for codes in ([1], [1, 2], [1, 3], [3, 1], [1, 1], [2, 3]):
        assert _pddl_successor(text, absent, codes, 0) == apply_rules(absent, np.array(codes), 0).tolist(), codes
    assert _pddl_successor(text, absent, [1, 3], 0) == [1, 3] and _pddl_successor(text, absent, [1, 1], 0) == [2, 2]
    empty = RuleSet(2, (1, 2), 2, (), 0)
    text = conditional_domain(empty, "h")
    d, _ = _pddl_parse(text, problem_pddl(empty, [1], [2], "h"))
    assert d.requirements == {R.STRIPS, R.TYPING} and not d.actions
    assert not _up_parse(text, problem_pddl(empty, [1], [2], "h")).actions


def test_problem_writer_checks_codes(toy):
    _, rs = toy
    text = problem_pddl(rs, [NEAR, FAR], [None, UNDER], model_hash="h")
    _, p = _pddl_parse(conditional_domain(rs, "h"), text)
    atoms = lambda lits: {(code_from_predicate(str(a.name)), str(a.terms[0].name)) for a in lits}  # noqa: E731
    assert atoms(p.init) == {(NEAR, "o0"), (FAR, "o1")} and sorted(str(o.name) for o in p.objects) == ["o0", "o1"]
    goal = p.goal.operands if hasattr(p.goal, "operands") else (p.goal,)
    assert atoms(goal) == {(UNDER, "o1")}
    with pytest.raises(ValueError, match="vocabulary"):
        problem_pddl(rs, [0, FAR], [None, UNDER], model_hash="h")
    with pytest.raises(ValueError):
        problem_pddl(rs, [NEAR, FAR], [UNDER], model_hash="h")
    with pytest.raises(ValueError):
        problem_pddl(rs, [NEAR], [None], model_hash="h")  # a goal must fix something


def test_fidelity_through_the_pddl_is_exact(toy, random_nets):
    from pddl_export.fidelity import pddl_fidelity

    enum, rs = toy
    fid = pddl_fidelity(conditional_domain(rs, "h"), rs, enum)
    assert fid.n_cases == enum.n_queries and fid.n_agree == fid.n_cases and not fid.disagreements
    _, enum_r, rs_r = random_nets[0]
    fid = pddl_fidelity(conditional_domain(rs_r, "h"), rs_r, enum_r)
    assert fid.n_cases == enum_r.n_queries and fid.fraction == 1.0


def test_pddl_fidelity_catches_a_wrong_domain_and_samples(toy):
    from pddl_export.fidelity import pddl_fidelity

    enum, rs = toy
    broken = RuleSet(rs.bits, rs.vocabulary, rs.max_objects, rs.rules[1:], rs.n_rules_before_generalization)
    fid = pddl_fidelity(conditional_domain(broken, "h"), rs, enum)
    assert fid.fraction < 1.0 and fid.disagreements
    sample = pddl_fidelity(conditional_domain(rs, "h"), rs, enum, max_cases=50, seed=1)
    assert sample.n_cases == 50 and sample.n_enumerated == enum.n_queries and sample.fraction == 1.0


def test_strips_form_is_strips_only_and_round_trips(toy):
    from pddl.requirements import Requirements as R
    from unified_planning.shortcuts import SequentialSimulator

    _, rs = toy
    init, goal = [NEAR, STICK, NEAR, UNDER], [RIDER_M, None, None, FAR]  # 4 objects: beyond enumeration
    task = strips_pddl(rs, init, goal, model_hash="h")
    states, edges = reachable_transitions(rs, init)
    assert task.n_states == len(states) and task.n_actions == len(edges) > 0
    d, p = _pddl_parse(task.domain, task.problem)
    assert d.requirements == {R.STRIPS, R.TYPING}
    assert "(not" not in "".join(re.findall(r":precondition (.*)", task.domain)) and "forall" not in task.domain
    prob = _up_parse(task.domain, task.problem)
    kind = prob.kind
    assert not (kind.has_negative_conditions() or kind.has_conditional_effects() or kind.has_existential_conditions())
    # Walk the reachable states through the PDDL and compare each step with the network.
    net, objs = ToyRobot(), sorted(prob.all_objects, key=lambda o: o.name)
    fluents = {c: prob.fluent(code_predicate(c, rs.bits)) for c in rs.codes}

    def decode(state):
        return tuple(next(c for c, f in fluents.items() if state.get_value(f(o)).bool_constant_value()) for o in objs)

    with SequentialSimulator(prob) as sim:
        frontier, seen = [sim.get_initial_state()], set()
        while frontier:
            state = frontier.pop()
            codes = decode(state)
            if codes in seen:
                continue
            seen.add(codes)
            by_action = {}
            for act in prob.actions:
                if sim.is_applicable(state, act, ()):
                    by_action.setdefault(action_id_from_name(act.name), []).append(act)
            want = net(np.tile(codes, (N_ACTIONS, 1)), np.arange(N_ACTIONS))
            for a in range(N_ACTIONS):
                acts = by_action.get(a, [])
                assert len(acts) <= 1  # one ground action per (state, real action)
                if not acts:
                    assert tuple(want[a]) == codes
                    continue
                nxt = sim.apply(state, acts[0], ())
                assert decode(nxt) == tuple(want[a])
                frontier.append(nxt)
    assert seen == set(states)


def test_strips_state_limit(toy):
    _, rs = toy
    with pytest.raises(StateLimitError):
        strips_pddl(rs, [NEAR, STICK, NEAR, UNDER], [FAR, None, None, None], model_hash="h", max_states=2)


def test_atomic_write_text(tmp_path):
    path = tmp_path / "sub" / "d.pddl"
    atomic_write_text(path, "one")
    atomic_write_text(path, "two")
    assert path.read_text() == "two" and sorted(p.name for p in path.parent.iterdir()) == ["d.pddl"]


def test_enumerate_scenes_queries_only_given_scenes_and_distils_exactly(toy):
    from pddl_export.enumeration import enumerate_scenes

    enum_all, _ = toy
    net = ToyRobot()
    vocab = enum_all.vocabulary
    scenes = [(vocab[0],), (vocab[1], vocab[0]), (vocab[0], vocab[1]), (vocab[2], vocab[2], vocab[1])]
    enum = enumerate_scenes(net, vocab, scenes, max_objects=3)
    assert not enum.complete and enum.n_scenes == 3 and enum.n_queries == 3 * 36  # the duplicate pair counted once
    assert [len(b.scenes) for b in enum.blocks] == [1, 1, 1]
    rs = distil_rules(enum)
    assert rule_fidelity(rs, enum).fraction == 1.0
    with pytest.raises(ValueError, match="objects, expected"):
        enumerate_scenes(net, vocab, [tuple(vocab[:1]) * 4], max_objects=3)


def _brute_force_overlap(lo: np.ndarray, hi: np.ndarray) -> tuple[int, int] | None:
    """First pair (row-major) of boxes whose intervals meet on every column: the definition, pair by pair."""
    for i in range(len(lo)):
        for j in range(len(lo)):
            if i != j and all(max(lo[i, c], lo[j, c]) < min(hi[i, c], hi[j, c]) for c in range(lo.shape[1])):
                return i, j
    return None


@pytest.mark.parametrize("seed", range(4))
def test_overlap_check_is_the_pairwise_definition_on_random_boxes(seed):
    """_first_overlap tests disjointness as a product of (column, upper bound) features; it must name the same
    first overlapping pair as comparing every pair on every column, in any chunk size, including open and
    COUNT_CAP bounds."""
    rng = np.random.default_rng(seed)
    n_none = 0
    for _ in range(300):
        n, c = int(rng.integers(1, 10)), int(rng.integers(1, 5))
        lo = np.zeros((n, c), np.int16)
        hi = np.full((n, c), COUNT_CAP + 1, np.int16)
        bounded = rng.random((n, c)) < 0.6
        low = rng.integers(0, 4, (n, c))
        high = np.where(rng.random((n, c)) < 0.3, COUNT_CAP + 1, low + rng.integers(1, 3, (n, c)))
        lo[bounded], hi[bounded] = low[bounded], high[bounded]
        lo[(rng.random((n, c)) < 0.05) & (hi == COUNT_CAP + 1)] = COUNT_CAP
        want = _brute_force_overlap(lo, hi)
        n_none += want is None
        for cells in (1, 3, 1 << 22):
            assert _first_overlap(lo, hi, max_cells=cells) == want, (lo.tolist(), hi.tolist(), cells)
    assert 20 < n_none < 280  # both verdicts occur


def test_a_rule_keeps_its_bounds_whatever_a_caller_does_with_them():
    r = Rule(3, 1, 2, requires=(5,), forbids=(7, 4), at_least=((9, 2),), fewer_than=((5, 3),))
    b = r.bounds()
    assert b == {4: (0, 1), 5: (1, 3), 7: (0, 1), 9: (2, INF)} and list(b) == [4, 5, 7, 9]
    b[4] = (0, INF)
    assert r.bounds()[4] == (0, 1) and r.matches({5: 1, 9: 2}) and not r.matches({5: 1, 9: 2, 4: 1})
    with pytest.raises(ValueError, match="contradictory conditions on code 5"):
        Rule(3, 1, 2, at_least=((5, 3),), fewer_than=((5, 3),))


def test_paused_gc_restores_the_collector_as_it_found_it():
    import gc

    from pddl_export.rules_io import paused_gc

    with pytest.raises(RuntimeError), paused_gc():
        assert not gc.isenabled()
        raise RuntimeError("a failed load")
    assert gc.isenabled()
    gc.disable()
    try:
        with paused_gc():
            pass
        assert not gc.isenabled()  # a caller that had it off keeps it off
    finally:
        gc.enable()
    frozen = gc.get_freeze_count()
    try:
        with pytest.raises(RuntimeError), paused_gc(freeze=True):
            raise RuntimeError("a failed load freezes nothing")
        assert gc.get_freeze_count() == frozen and gc.isenabled()
        with paused_gc(freeze=True):
            built = [[i] for i in range(1000)]  # what a load builds stays out of later collections
        assert gc.get_freeze_count() >= frozen + len(built) and gc.isenabled()
    finally:
        gc.unfreeze()
