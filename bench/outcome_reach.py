"""Does m(z) reach each benchmark goal along the actions that made it: by its likeliest predictions, or among its likely outcomes?

For every problem the initial and goal scenes are encoded; the generator's own actions are then rolled
through m(z) twice: taking the likeliest next state each step, and keeping a beam of the most likely
outcome chains (each step branching into the outcomes `astar-outcomes` would follow: up to 4 per
action, each at least 5% as likely as the likeliest; search.learned_astar.likely_outcomes). A goal
"reached" has its fixed objects' codes at the end of the chain (argmax) or of some chain in the beam.
This is why `astar` times out on bigger scenes and `astar-outcomes` does not: it measures whether the
goal lies in the graph each planner searches along one route known to work. Writes JSON, by 1-3 and
4-5 objects and goals on / off the table locations.

    python bench/outcome_reach.py --run pretrained/quick-stab12k \
        --problems problems/depth/walks,problems/depth/structures --out bench/results/outcome_reach.json
"""
from __future__ import annotations

import argparse
from pathlib import Path


def reach(transition, start: tuple[int, ...], actions: tuple[int, ...], fixed: dict[int, int], beam: int,
          max_outcomes: int, min_ratio: float) -> tuple[bool, int | None]:
    """(the likeliest chain ends on the goal, rank of the likeliest beam chain that does or None)."""
    import numpy as np

    from search.learned_astar import likely_outcomes

    def hit(state: tuple[int, ...]) -> bool:
        return all(state[i] == c for i, c in fixed.items())

    likeliest = start
    chains = {start: 0.0}  # state -> -log P of the likeliest chain to it
    for a in actions:
        likeliest = tuple(int(c) for c in transition(np.array([likeliest]), np.array([a]))[0])
        states = list(chains)
        probs = transition.bit_probabilities(np.array(states), np.full(len(states), a))
        nxt: dict[tuple[int, ...], float] = {}
        for s, row in zip(states, likely_outcomes(probs, max_outcomes, min_ratio)):
            for t, nll in row:
                nxt[t] = min(nxt.get(t, np.inf), chains[s] + nll)
        chains = dict(sorted(nxt.items(), key=lambda kv: kv[1])[:beam])
    ranked = sorted(chains, key=chains.get)
    return hit(likeliest), next((r for r, s in enumerate(ranked) if hit(s)), None)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, required=True, help="run with best.pt and transition.pt")
    ap.add_argument("--problems", required=True, help="comma-separated problem folders")
    ap.add_argument("--beam", type=int, default=32, help="outcome chains kept per step (default 32)")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    import numpy as np
    import torch

    from pddl_export.files import atomic_write_json
    from symlearn.learning.checkpoint import effect_model_sha256, load_effect_model
    from symlearn.planning.planners import MIN_OUTCOME_RATIO, OUTCOMES_PER_ACTION
    from symlearn.planning.problem import load_problems
    from symlearn.planning.scenes import scene_codes
    from symlearn.provenance import bench_context
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import LearnedTransition

    torch.set_num_threads(1)
    encoder, _ = load_effect_model(args.run)
    transition = LearnedTransition.from_run(args.run)
    rows = []
    with TabletopSimulator() as sim:
        for folder in args.problems.split(","):
            for _, pr in load_problems(Path(folder)):
                start = tuple(int(c) for c in scene_codes(sim, encoder, pr.initial))
                goal = scene_codes(sim, encoder, pr.goal)
                likeliest, rank = reach(transition, start, pr.actions, {i: int(goal[i]) for i in pr.fixed},
                                        args.beam, OUTCOMES_PER_ACTION, MIN_OUTCOME_RATIO)
                rows.append({"problem": f"{Path(folder).name}/{pr.name}", "n_objects": pr.initial.k,
                             "goal_off_locations": pr.goal_off_locations, "length": len(pr.actions),
                             "likeliest_reaches": likeliest, "beam_rank": rank})
    groups = {}
    for group, ks in (("1-3 objects", (1, 2, 3)), ("4-5 objects", (4, 5))):
        for part, off in (("on_locations", False), ("off_locations", True)):
            sel = [r for r in rows if r["n_objects"] in ks and (r["goal_off_locations"] > 0) == off]
            groups.setdefault(group, {})[part] = {
                "n_problems": len(sel),
                "likeliest_reaches": round(float(np.mean([r["likeliest_reaches"] for r in sel])), 4) if sel else None,
                "among_outcomes": round(float(np.mean([r["beam_rank"] is not None for r in sel])), 4) if sel else None}
            print(f"{group}, {part}: {groups[group][part]}")
    atomic_write_json(args.out, {"run": args.run.name, "effect_model_sha256": effect_model_sha256(args.run),
                                 "problems": args.problems, "beam": args.beam, "max_outcomes": OUTCOMES_PER_ACTION,
                                 "min_outcome_ratio": MIN_OUTCOME_RATIO, "groups": groups, "rows": rows,
                                 **bench_context()})
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
