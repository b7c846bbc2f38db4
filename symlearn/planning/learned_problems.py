"""A problem set written as PDDL problems of a run's learned domain, for planners run outside the project.

    symlearn export-learned-problems --run pretrained/relations_on --problems problems/rel_test4 \\
        --out out/rel_test4 --goal-relations on

Each problem's initial scene and goal scene are placed in the simulator and read by the relational model,
exactly as the closed loop reads them (symlearn.planning.learned_loop: `observe_atoms`, `goal_atoms`), and
written as OUT/NAME.pddl over OUT/domain.pddl, the domain the closed loop plans with. OUT/problems.json records,
per problem, its shortest plan in the simulator (the problem's `optimal_length`), so that a planner run on the
folder can tell a reachable goal reported unsolvable and how long its plans are against the shortest:

    python bench/stock_fd.py --domain OUT/domain.pddl --problems OUT --shortest OUT/problems.json --out x.json

It also records the run, model and operator hashes, the settings and the versions.

With `focus=True` (`--focus`) each problem is also written as OUT/focus/NAME.pddl over the objects its goal needs
alone (learned_loop.focus_problem, the closed loop's first call): the objects a goal atom names that does not hold,
what rests on them, the top of a stack at a cell the goal puts one at, and what each rests on; the atoms of the
others are left out, so the cells they fill stay not `empty` and what they rest on not `clear`. Every plan of a
focus problem is a plan of the whole problem (no operator reads or changes an object it does not name), so a
planner may solve OUT/focus/NAME.pddl first and fall back to OUT/NAME.pddl where that finds no plan (the goal may
need another object moved out of the way). A problem whose focus is none, or more than FOCUS_MAX of its objects
(grounding it would cost nearly the whole problem's time), gets no focus file. The loop plans over a second set
before the whole (learned_loop.object_sets: the focus and the tops of the other stacks); the files hold the first.
At 9-10 objects the translator grounds a whole problem in 5-6 s; the focus problem is what makes a 10 s call work:

    python bench/stock_fd.py --domain OUT/domain.pddl --problems OUT --focus OUT/focus --shortest OUT/problems.json \\
        --out x.json

The folder is written whole at the end (atomic_write_folder) and never over an existing one.
"""
from __future__ import annotations

import json
from pathlib import Path

from pddl_export.files import atomic_write_folder, sha256_file
from pddl_export.learned_domain import domain_pddl, predicates_of, problem_pddl
from symlearn.export.learned_export import load_operators, operators_path, run_hashes
from symlearn.learning.relational_training import load_relational
from symlearn.planning.learned_calls import focus_problem
from symlearn.planning.learned_loop import goal_atoms, observe_atoms
from symlearn.problems.problem import load_problems
from symlearn.provenance import versions

MANIFEST = "problems.json"
FORMAT = "symlearn-learned-problems"
FOCUS_FOLDER = "focus"


def export_learned_problems(run_dir: Path, problems_dir: Path, out: Path,
                            goal_relations: tuple[str, ...] = (), focus: bool = False, equality: bool = True) -> dict:
    """Write OUT/domain.pddl, OUT/NAME.pddl for every problem of problems_dir and OUT/problems.json (with `focus`,
    OUT/focus/NAME.pddl too, over the objects the goal needs); returns the manifest. Without `equality`, the domain
    and problems in plain typed STRIPS (pddl_export.learned_domain.domain_pddl). Refused in one line, before the
    simulator starts, when OUT exists or an input is missing."""
    from symlearn.sim.simulator import TabletopSimulator

    run_dir, problems_dir, out = Path(run_dir), Path(problems_dir), Path(out)
    if out.exists():
        raise ValueError(f"{out} exists; choose another --out (nothing is written over it)")
    if not out.parent.is_dir():
        raise ValueError(f"cannot write {out}: its folder {out.parent} does not exist")
    ops = load_operators(run_dir)
    model, blob = load_relational(run_dir)
    predicates = predicates_of(ops)
    unknown = [r for r in goal_relations if r not in predicates]
    if unknown:
        raise ValueError(f"{operators_path(run_dir)}: no operator reads or changes {unknown}; "
                         f"relations of this domain: {sorted(set(predicates) - {'at', 'empty'})}")
    problems = load_problems(problems_dir)
    files: dict[str, str] = {"domain.pddl": domain_pddl(ops, equality=equality)}
    rows = []
    with TabletopSimulator() as sim:
        for path, problem in problems:
            goal = goal_atoms(sim, model, blob, problem, goal_relations)
            sim.reset(problem.initial)
            init = observe_atoms(sim, model, blob)
            objects = [f"o{i + 1}" for i in range(problem.initial.k)]
            files[f"{problem.name}.pddl"] = problem_pddl(problem.name, objects, init, goal, predicates,
                                                         equality=equality)
            row = {}
            few = focus_problem(objects, init, goal) if focus else None
            if few is not None:
                names, few_init, few_goal = few
                files[f"{FOCUS_FOLDER}/{problem.name}.pddl"] = problem_pddl(problem.name, names, few_init, few_goal,
                                                                           predicates, equality=equality)
                row = {"focus_file": f"{FOCUS_FOLDER}/{problem.name}.pddl", "focus_objects": names}
            rows.append({"name": problem.name, "file": f"{problem.name}.pddl", **row, "k": problem.initial.k,
                         "shortest": problem.optimal_length, "generator_length": problem.generator_length,
                         "goal_atoms": len(goal), "goal_believed_reached": goal <= init,
                         "problem_sha256": sha256_file(path)})
    manifest = {"format": FORMAT, "run": str(run_dir), **run_hashes(run_dir), "problems": str(problems_dir),
                "goal_relations": list(goal_relations), "focus": focus, "equality": equality, "rows": rows,
                "versions": versions()}
    files[MANIFEST] = json.dumps(manifest, indent=1)
    atomic_write_folder(out, files)
    return manifest
