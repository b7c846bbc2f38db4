"""`rules-outcomes` planning time with the code graph read off the rules once, against once per call.

The heuristic's code graph (search.rules_search.code_distances) holds the (code_from, code_to)
pairs of every rule and second-outcome rule. Until 2026-11-29 each call read them off all the
rules; now RuleSuccessors.code_changes reads them once. On 200k rules that read cost more than
the rest of a short search.

Tasks: test scenes of a data set (their codes under the run's encoder, all in the rules' vocabulary),
each with a goal 2-6 random actions away under the rules (the main rules' step, so a plan exists).
Every task is planned twice in the same process, once reading the pairs per call (the baseline) and
once with them read once, alternating which goes first; as in `symlearn benchmark`, each mode keeps
one pair of successor functions for all its calls. Plans must be equal where both solved.

    python bench/rules_outcomes_speed.py --run RUN --data data/k15 --n 60 --out bench/results/rules_outcomes_speed.json
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from pddl_export.outcome_rules import load_outcomes
from pddl_export.rule_successors import RuleSuccessors
from pddl_export.rules import apply_rules
from pddl_export.rules_io import load_rules
from pddl_export.symbolic import SymbolicGoal
from search.rules_outcomes import plan_rules_outcomes
from symlearn.provenance import atomic_write_json, bench_context


class PerCallCodeGraph(RuleSuccessors):
    """The baseline: the rules' (code_from, code_to) pairs read off every rule at every call."""

    @property
    def code_changes(self) -> frozenset[tuple[int, int]]:  # type: ignore[override]
        return frozenset((r.code_from, r.code_to) for r in self.rules.rules)


def tasks(run: Path, data: Path, n: int, seed: int) -> list[tuple[list[int], tuple[int, ...]]]:
    """(start codes, goal codes) pairs: test scenes in the vocabulary, goals 2-6 rule steps away."""
    from symlearn.data.dataset import load_split
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.symbols import encode_codes

    rules, _ = load_rules(run)
    model, _ = planning_models(run)  # the codes the rules were distilled on, location bits included
    split = load_split(data, "test")
    codes = encode_codes(model, split.pre_depth, split.pre_origin, split.mask)
    vocab, rng, out = set(rules.vocabulary), np.random.default_rng(seed), []
    for i in rng.permutation(len(codes)).tolist():
        start = [int(c) for c in codes[i] if c >= 0]
        if not set(start) <= vocab:
            continue
        state = np.array(start)
        for a in rng.choice(rules.actions, int(rng.integers(2, 7))).tolist():
            state = apply_rules(rules, state, int(a))
        if tuple(state.tolist()) != tuple(start):
            out.append((start, tuple(int(c) for c in state)))
        if len(out) == n:
            break
    return out


def time_tasks(run: Path, task_list, timeout_s: float, seed: int) -> dict:
    """Plan every task both ways; per-call seconds and the plans."""
    rules, _ = load_rules(run)
    outcomes, _ = load_outcomes(run)
    costs = outcomes.alternative_costs()
    times: dict[str, dict[int, float]] = {"per_call": {}, "once": {}}
    plans: dict[str, dict[int, tuple]] = {"per_call": {}, "once": {}}
    # as in `symlearn benchmark`: one pair of successor functions for every call of the planner
    succ = {mode: (cls(rules), cls(outcomes.rules)) for mode, cls in (("per_call", PerCallCodeGraph),
                                                                       ("once", RuleSuccessors))}
    order = np.random.default_rng(seed).permutation(len(task_list))
    for j, i in enumerate(order.tolist()):
        start, goal = task_list[i]
        modes = ("per_call", "once") if j % 2 == 0 else ("once", "per_call")
        for mode in modes:
            main, alt = succ[mode]
            t0 = time.perf_counter()
            res = plan_rules_outcomes(main, alt, costs, start, SymbolicGoal(goal), risk_weight=1.0,
                                      timeout_s=timeout_s)
            times[mode][i] = time.perf_counter() - t0
            plans[mode][i] = (res.status.value, tuple(res.plan))
    return {"times": times, "plans": plans, "n_rules": rules.n_rules, "n_outcome_rules": outcomes.rules.n_rules}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True, help="a run with pddl/rules.json and pddl/outcomes.json")
    ap.add_argument("--data", required=True, help="the data set whose test scenes start the tasks")
    ap.add_argument("--n", type=int, default=60)
    ap.add_argument("--timeout", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    run, data = Path(args.run), Path(args.data)
    task_list = tasks(run, data, args.n, args.seed)
    got = time_tasks(run, task_list, args.timeout, args.seed)
    plans, times = got["plans"], got["times"]
    solved = [i for i in plans["once"] if plans["once"][i][0] == plans["per_call"][i][0] == "solved"]
    if any(plans["once"][i] != plans["per_call"][i] for i in solved):
        raise SystemExit("the two ways planned differently")
    med = {m: statistics.median(t.values()) for m, t in times.items()}
    by_size: dict[str, dict] = {}
    for k in sorted({len(s) for s, _ in task_list}):
        idx = [i for i, (s, _) in enumerate(task_list) if len(s) == k]
        u, c = (statistics.median(times[m][i] for i in idx) for m in ("per_call", "once"))
        by_size[str(k)] = {"n": len(idx), "median_per_call_s": round(u, 5), "median_once_s": round(c, 5),
                           "speedup": round(u / c, 2)}
    report = {
        **bench_context(), "run": str(run), "data": str(data), "n_tasks": len(task_list), "timeout_s": args.timeout,
        "n_rules": got["n_rules"], "n_outcome_rules": got["n_outcome_rules"],
        "median_per_call_s": round(med["per_call"], 5), "median_once_s": round(med["once"], 5),
        "speedup": round(med["per_call"] / med["once"], 2),
        "total_per_call_s": round(sum(times["per_call"].values()), 2),
        "total_once_s": round(sum(times["once"].values()), 2),
        "solved": {m: sum(p[0] == "solved" for p in plans[m].values()) for m in plans},
        "same_plans_where_both_solved": len(solved), "by_objects": by_size,
    }
    atomic_write_json(Path(args.out), report)
    print({k: v for k, v in report.items() if k not in ("versions", "by_objects")})
    print(by_size)


if __name__ == "__main__":
    main()
