"""The exported second outcomes (pddl_export.outcome_rules) and the rules-outcomes planner (search.rules_outcomes)."""
import gc
import itertools
import json

import numpy as np
import pytest

from pddl_export.enumeration import enumerate_transitions
from pddl_export.fidelity import rule_fidelity
from pddl_export.outcome_rules import (OUTCOMES_FILE, AlternativeCosts, OutcomeRules, SecondOutcome, distil_outcomes,
                                       load_outcomes, outcomes_from_json, outcomes_to_json, second_codes)
from pddl_export.rule_successors import RuleSuccessors
from pddl_export.rules import Rule, RuleSet
from pddl_export.symbolic import SymbolicGoal, codes_from_bits
from search.result import PlanStatus
from search.rules_outcomes import outcome_steps, plan_rules_outcomes
from search.rules_search import plan_rules


@pytest.mark.parametrize("seed", range(4))
def test_second_codes_are_the_second_likeliest_codes_by_enumeration(seed):
    rng = np.random.default_rng(seed)
    bits, ratio = 4, 0.2
    probs = rng.uniform(0.01, 0.99, (30, 3, bits))
    alt, extra = second_codes(probs, ratio)
    values = np.array(list(itertools.product((0, 1), repeat=bits)))  # every code's bits, MSB first
    for b, k in np.ndindex(30, 3):
        p = np.prod(np.where(values == 1, probs[b, k], 1 - probs[b, k]), axis=1)
        first, second = np.argsort(-p)[:2]
        codes = codes_from_bits(values)
        if p[second] >= ratio * p[first]:
            assert alt[b, k] == codes[second] and extra[b, k] == pytest.approx(np.log(p[first] / p[second]))
        else:
            assert alt[b, k] == codes[first] and extra[b, k] == np.inf


def test_second_codes_refuse_a_bad_ratio():
    for bad in (0.0, -0.1, 1.5):
        with pytest.raises(ValueError, match="min_ratio must lie in"):
            second_codes(np.full((1, 1, 2), 0.7), bad)


class _Toy:
    """3-bit codes, each bit kept with P 0.9; action 2 sets the low bit of code 4 with P 0.7, or 0.2 beside a 1."""

    bits = 3

    def bit_probabilities(self, codes, actions):
        codes = np.asarray(codes, np.int64)
        probs = ((codes[..., None] >> np.array([2, 1, 0])) & 1).astype(float) * 0.8 + 0.1
        others_1 = (codes == 1).sum(1, keepdims=True) - (codes == 1) > 0
        hit = (np.asarray(actions)[:, None] == 2) & (codes == 4)
        probs[..., 2] = np.where(hit, np.where(others_1, 0.2, 0.7), probs[..., 2])
        return probs

    def __call__(self, codes, actions):
        return codes_from_bits(self.bit_probabilities(codes, actions) >= 0.5)


def test_distilled_outcomes_reproduce_the_second_codes_and_their_costs():
    toy = _Toy()
    enum = enumerate_transitions(toy, [1, 4, 6], max_objects=2)
    outcomes, alt_enum = distil_outcomes(toy, enum, 0.05)
    assert rule_fidelity(outcomes.rules, alt_enum).fraction == 1.0
    for block in alt_enum.blocks:  # the enumeration is SecondOutcome's own answer on the main rules' scenes
        assert np.array_equal(block.next_codes, SecondOutcome(toy, 0.05)(block.states, block.actions))
    costs = {(a, c, d): x for a, c, d, x in outcomes.costs}
    # action 2 on code 4: the likeliest is 5 (P 0.7) and 4 second, or with a 1 beside it the likeliest is 4, 5 second
    assert costs[(2, 4, 4)] == pytest.approx(np.log(0.7 / 0.3))
    assert costs[(2, 4, 5)] == pytest.approx(np.log(0.8 / 0.2))
    others = {k: x for k, x in costs.items() if k[:2] != (2, 4)}  # the rest flip one bit, 9 times less likely
    assert len(others) == 35 * 3 + 2 and {k[:2] for k in others} == {(a, c) for a in range(36) for c in (1, 4, 6)} - {(2, 4)}
    assert all(x == pytest.approx(np.log(9)) and bin(c ^ d).count("1") == 1 for (a, c, d), x in others.items())
    table = outcomes.alternative_costs()
    assert table.bits == 3 and len(table.keys) == len(outcomes.costs)
    assert table(2, 4, 5) == pytest.approx(np.log(4.0)) and np.isinf(table(2, 4, 6))
    got = table(np.array([[2], [2], [0]]), np.array([4, 4, 7]), np.array([[5], [4], [3]]))  # broadcast, (3, 3)
    assert got.shape == (3, 3) and got[0, 0] == pytest.approx(np.log(4.0)) and got[1, 1] == pytest.approx(np.log(7 / 3))
    assert np.isinf(got[2]).all() and np.isinf(AlternativeCosts.from_costs([], 3)(1, 2, 3))
    wide = AlternativeCosts.from_costs([(35, (1 << 14) - 1, 5, 0.25)], 14)  # 14-bit codes: no dense 36 GB table
    assert wide(35, (1 << 14) - 1, 5) == 0.25 and np.isinf(wide(35, 5, (1 << 14) - 1)) and wide.keys.nbytes == 8
    # a ratio above every certain bit's odds keeps action 2's alternatives only
    strict, _ = distil_outcomes(toy, enum, 0.2)
    assert {a for a, *_ in strict.costs} == {2} and {r.action for r in strict.rules.rules} == {2}


def test_outcomes_round_trip_and_refusals(tmp_path):
    toy = _Toy()
    outcomes, _ = distil_outcomes(toy, enumerate_transitions(toy, [1, 4], max_objects=2), 0.1)
    back = outcomes_from_json(json.loads(json.dumps(outcomes_to_json(outcomes))))
    assert back.rules.rules == outcomes.rules.rules and back.min_ratio == 0.1
    assert [c[:3] for c in back.costs] == [c[:3] for c in outcomes.costs]
    assert np.allclose([c[3] for c in back.costs], [c[3] for c in outcomes.costs], atol=1e-6)
    with pytest.raises(ValueError, match="no exported outcome rules at .*outcomes.json; re-run 'symlearn export-pddl"):
        load_outcomes(tmp_path)
    (tmp_path / "pddl").mkdir()
    for text, match in (("{", "not valid JSON"), ("[1]", "a JSON list"), ('{"bits": 3}', "missing field")):
        (tmp_path / "pddl" / OUTCOMES_FILE).write_text(text)
        with pytest.raises(ValueError, match=match) as info:
            load_outcomes(tmp_path)
        assert OUTCOMES_FILE in str(info.value) and "\n" not in str(info.value) and gc.isenabled()
    with pytest.raises(ValueError, match="finite"):
        OutcomeRules(outcomes.rules, ((2, 4, 5, float("inf")),), 0.1)
    with pytest.raises(ValueError, match="no bit probabilities"):
        SecondOutcome(lambda c, a: c)


def _toy_rules(*rules: Rule) -> RuleSet:
    return RuleSet(bits=2, vocabulary=(0, 1, 2, 3), max_objects=3, n_rules_before_generalization=len(rules),
                   rules=rules)


def _costs(**entries: float) -> AlternativeCosts:
    return AlternativeCosts.from_costs([(*(int(v) for v in key[1:].split("_")), x) for key, x in entries.items()], 2)


def test_a_goal_only_a_second_outcome_reaches():
    main = _toy_rules(Rule(action=5, code_from=1, code_to=2))
    alt = _toy_rules(Rule(action=5, code_from=1, code_to=3))
    costs = _costs(a5_1_3=0.5)
    goal = SymbolicGoal((3, None))
    assert plan_rules(main, [1, 0], goal, "bfs", timeout_s=5).status is PlanStatus.UNSOLVABLE
    res = plan_rules_outcomes(RuleSuccessors(main), RuleSuccessors(alt), costs, [1, 0], goal, risk_weight=2.0,
                              timeout_s=5)
    assert res.plan == (5,) and res.predicted_states == ((1, 0), (3, 0)) and res.extra["cost"] == pytest.approx(2.0)
    # execution saw action 5 give the likeliest outcome here: the second one is no longer counted on
    seen = {(1, 0): {5: (2, 0)}}
    res = plan_rules_outcomes(RuleSuccessors(main), RuleSuccessors(alt), costs, [1, 0], goal, risk_weight=2.0,
                              timeout_s=5, seen=seen)
    assert res.status is PlanStatus.UNSOLVABLE


def test_a_goal_code_no_chain_reaches_is_refused_before_search():
    main = _toy_rules(Rule(action=5, code_from=1, code_to=2))
    alt = _toy_rules(Rule(action=5, code_from=1, code_to=3))
    res = plan_rules_outcomes(RuleSuccessors(main), RuleSuccessors(alt), _costs(a5_1_3=0.5), [2, 1], SymbolicGoal((None, 0)),
                              risk_weight=1.0, timeout_s=5)
    assert res.status is PlanStatus.UNSOLVABLE and res.expansions == 0 and res.extra["proof"] == "code_graph"
    assert res.message == "object 1 cannot reach its goal code 00 from 01 through any chain of rules or second outcomes"


def test_risk_weight_trades_a_longer_sure_plan_for_a_short_unlikely_one():
    main = _toy_rules(Rule(action=1, code_from=1, code_to=2), Rule(action=2, code_from=2, code_to=3))
    alt = _toy_rules(Rule(action=1, code_from=1, code_to=3))
    args = (RuleSuccessors(main), RuleSuccessors(alt), _costs(a1_1_3=0.7), [1], SymbolicGoal((3,)))
    short = plan_rules_outcomes(*args, risk_weight=1.0, timeout_s=5, batch=1)
    sure = plan_rules_outcomes(*args, risk_weight=2.0, timeout_s=5, batch=1)  # one pop at a time: the cheapest plan
    assert short.plan == (1,) and short.extra["cost"] == pytest.approx(1.7)
    assert sure.plan == (1, 2) and sure.predicted_states == ((1,), (2,), (3,)) and sure.extra["cost"] == 2.0


def test_objects_sharing_a_code_may_part():
    main = _toy_rules(Rule(action=7, code_from=1, code_to=2))
    alt = _toy_rules(Rule(action=7, code_from=1, code_to=3))
    goal = SymbolicGoal((2, 3))
    proof = plan_rules(main, [1, 1], goal, "bfs", timeout_s=5)
    assert proof.status is PlanStatus.UNSOLVABLE and proof.extra["proof"] == "coincidence"
    res = plan_rules_outcomes(RuleSuccessors(main), RuleSuccessors(alt), _costs(a7_1_3=1.0), [1, 1], goal,
                              risk_weight=1.0, timeout_s=5)
    assert res.plan == (7,) and res.predicted_states[-1] == (2, 3)


def test_each_action_keeps_the_cheapest_deviations():
    main = _toy_rules(Rule(action=3, code_from=1, code_to=2))
    alt = _toy_rules(Rule(action=3, code_from=1, code_to=3), Rule(action=3, code_from=0, code_to=3))
    costs = _costs(a3_1_3=0.4, a3_0_3=0.1)
    states = np.array([[1, 1, 0, 1, 0]])
    for m, want in ((3, {(2, 2, 3, 2, 0), (2, 2, 0, 2, 3), (3, 2, 0, 2, 0)}), (1, {(2, 2, 3, 2, 0)})):
        steps = [s for s in outcome_steps(RuleSuccessors(main), RuleSuccessors(alt), costs, states, 1.0, m)[0]
                 if s[0] == 3]
        assert steps[0] == (3, (2, 2, 0, 2, 0), 1.0)  # the rules' own step first, at cost 1
        assert len(steps) == 1 + m
        assert {s[1] for s in steps[1:]} == want
        assert sorted(round(s[2], 4) for s in steps[1:]) == sorted([1.1, 1.1, 1.4][:m])
    with pytest.raises(ValueError, match="do not match"):
        plan_rules_outcomes(RuleSuccessors(main), RuleSuccessors(alt), AlternativeCosts.from_costs([], 3), [1],
                            SymbolicGoal((2,)), risk_weight=1.0, timeout_s=1)
    with pytest.raises(ValueError, match="risk_weight"):
        plan_rules_outcomes(RuleSuccessors(main), RuleSuccessors(alt), costs, [1], SymbolicGoal((2,)),
                            risk_weight=0.0, timeout_s=1)
