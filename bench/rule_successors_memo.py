"""Rule successors with and without the memo of (own code, context counts) answers, on real search calls.

Plans each given problem with `rules-outcomes` on RUN's exported rules (in the simulator, one open-loop call
each), recording every batch of states the search asks RuleSuccessors about. The recorded batches are then
replayed, in order, through the dense comparison of every (state, object) pair with all of its code's rules
(the baseline: RuleSuccessors before the memo) and through RuleSuccessors with its memo, one instance per rule
set across all problems as in a benchmark. Both must give the same successors. Writes JSON.

    python bench/rule_successors_memo.py --run RUN --problems problems/depth/structures/problem_0042.json ... \
        --out bench/results/rule_successors_memo.json
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np


def dense_successors(succ, states: np.ndarray) -> np.ndarray:
    """The baseline: every (state, object) pair compared with all of its own code's rules, nothing kept."""
    from pddl_export.rules import COUNT_CAP

    out = np.repeat(states[:, None, :], len(succ.actions), axis=1)
    counts = (states[:, :, None] == succ._context).sum(axis=1)
    for c in np.unique(states).tolist():
        if c not in succ._groups:
            continue
        cols, lo, hi, acol, code_to = succ._groups[c]
        rows, pos = np.nonzero(states == c)
        others = np.minimum(counts[rows][:, cols] - (succ._context[cols] == c), COUNT_CAP).astype(np.int16)
        p, r = np.nonzero(np.all((others[:, None, :] >= lo) & (others[:, None, :] < hi), axis=2))
        out[rows[p], acol[r], pos[p]] = code_to[r]
    return out


def record_calls(run: Path, problems: list[Path], timeout_s: float) -> tuple[list, list, list[dict]]:
    """Plan each problem; the rule sets, the recorded (rule set index, states) calls and one row per problem."""
    import pddl_export.rule_successors as rs_module
    from symlearn.planning.execution import ExecutionConfig, run_problem
    from symlearn.planning.planners import make_planners
    from symlearn.problems.problem import load_problem
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    seen_sets, calls = [], []
    original = rs_module.RuleSuccessors.__call__

    def recording(self, states):
        if not any(s is self.rules for s in seen_sets):
            seen_sets.append(self.rules)
        calls.append((next(i for i, s in enumerate(seen_sets) if s is self.rules), np.asarray(states, np.int64).copy()))
        return original(self, states)

    fn = make_planners(["rules-outcomes"], run)["rules-outcomes"]
    encoder, transition = planning_models(run)
    cfg = ExecutionConfig(closed_loop=False, timeout_s=timeout_s)
    rows = []
    rs_module.RuleSuccessors.__call__ = recording
    try:
        with TabletopSimulator() as sim:
            for path in problems:
                before = len(calls)
                row = run_problem(sim, encoder, transition, load_problem(path), "rules-outcomes", fn, cfg)
                rows.append({"problem": str(path), "status": str(row.status), "planning_time_s": row.planning_time_s,
                             "expansions": row.expansions, "success": row.success, "calls": len(calls) - before})
    finally:
        rs_module.RuleSuccessors.__call__ = original
    return seen_sets, calls, rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True, help="run directory with pddl/rules.json and outcomes.json")
    ap.add_argument("--problems", nargs="+", required=True, help="problem JSON files")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds per planning call while recording")
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    from pddl_export.rule_successors import RuleSuccessors
    from symlearn.provenance import atomic_write_json, bench_context

    sets, calls, rows = record_calls(Path(args.run), [Path(p) for p in args.problems], args.timeout)
    memo = [RuleSuccessors(s) for s in sets]
    base_s = memo_s = 0.0
    for i, states in calls:
        t = time.perf_counter()
        want = dense_successors(memo[i], states)
        base_s += time.perf_counter() - t
        t = time.perf_counter()
        got = memo[i](states)
        memo_s += time.perf_counter() - t
        if not np.array_equal(got, want):
            raise SystemExit(f"rule_successors_memo: the memo's successors differ on a batch of {len(states)} states")
    out = {"run": args.run, "rule_sets": [len(s.rules) for s in sets], "bits": sets[0].bits if sets else None,
           "problems": rows, "n_calls": len(calls), "n_states": int(sum(len(s) for _, s in calls)),
           "baseline_s": round(base_s, 3), "memo_s": round(memo_s, 3),
           "speedup": round(base_s / memo_s, 1) if memo_s else None, "memo_entries": [len(m._memo) for m in memo],
           **bench_context()}
    print(json.dumps({k: v for k, v in out.items() if k != "problems"}))
    atomic_write_json(args.out, out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
