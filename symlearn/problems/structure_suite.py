"""Problem sets of the structure suite, and single problems from goal files, written as problem JSON files.

`generate_structures` writes n problems, cycling over the templates whose object counts meet the asked
range, problem i drawn from default_rng([seed, i]); each is built and checked in the simulator, and a
draw the simulator refuses is replaced by the next draw of the same rng. The set's settings are kept
in OUT/problems.manifest as for random-walk sets, so the same command completes an interrupted set.

    >>> generate_structures(Path("problems/structures"), n=22, objects=(1, 5), seed=0)  # doctest: +SKIP
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from symlearn.folder_lock import folder_lock
from symlearn.problems.goal_problems import goal_file_problem, goal_problem
from symlearn.problems.paths import path_under
from symlearn.problems.problem import PROBLEM_VERSION, Problem, load_problem, save_problem
from symlearn.problems.problem_generation import (MANIFEST_FORMAT, PROBLEMS_MANIFEST, _done,
                                                  prepare_problem_dir)
from symlearn.problems.structures import TEMPLATES, Template, structure_goal
from symlearn.sim.exploration import MAX_OBJECTS

SUITES = ("structures",)
MAX_DRAWS = 20  # draws of one problem before the set is given up


def fitting_templates(objects: tuple[int, int]) -> list[Template]:
    """The templates that can be drawn with an object count in the inclusive range."""
    lo, hi = objects
    if not 1 <= lo <= hi <= MAX_OBJECTS:
        raise ValueError(f"object range {lo}-{hi} must lie within 1-{MAX_OBJECTS}")
    return [t for t in TEMPLATES if t.objects[0] <= hi and lo <= t.objects[1]]


def structure_problem(sim, template: Template, objects: tuple[int, int], rng: np.random.Generator,
                      name: str, seed: int) -> Problem:
    """One problem of a template, k drawn in the range; draws the simulator refuses are replaced."""
    lo, hi = max(objects[0], template.objects[0]), min(objects[1], template.objects[1])
    reasons = []
    for _ in range(MAX_DRAWS):
        k = int(rng.integers(lo, hi + 1))
        try:
            goal = structure_goal(template.name, rng, k, seed)
            return goal_problem(sim, goal, name, f"problem {name} ({template.name}, {k} objects)")
        except ValueError as e:
            reasons.append(str(e))
    raise RuntimeError(f"problem {name}: no {template.name} draw held in {MAX_DRAWS} tries (last: {reasons[-1]})")


def _settings(suite: str, n: int, objects: tuple[int, int], seed: int) -> dict:
    return {"format": MANIFEST_FORMAT, "problem_version": PROBLEM_VERSION, "suite": suite, "n": n,
            "objects": list(objects), "seed": seed}


def generate_structures(out_dir: Path, n: int, objects: tuple[int, int] = (1, 5), seed: int = 0, sim=None,
                        overwrite: bool = False, suite: str = "structures") -> list[Path]:
    """Write n suite problems to out_dir/problem_NNNN.json; the same call again completes an interrupted set."""
    from symlearn.sim.simulator import TabletopSimulator

    if suite not in SUITES:
        raise ValueError(f"unknown suite {suite!r}; known: {', '.join(SUITES)}")
    if not (isinstance(n, int) and n >= 1) or not (isinstance(seed, int) and seed >= 0):
        raise ValueError(f"n={n!r} must be a positive integer and seed={seed!r} a non-negative one")
    objects = (int(objects[0]), int(objects[1]))
    templates = fitting_templates(objects)
    out_dir = Path(out_dir)
    with folder_lock(out_dir):  # one writer: a second `problems` into this folder is refused at once
        prepare_problem_dir(out_dir, _settings(suite, n, objects, seed), overwrite)
        own, paths = sim is None, []
        try:
            for i in range(n):
                name = f"problem_{i:04d}"
                path = path_under(out_dir, f"{name}.json")
                if not _done(path, name):
                    sim = sim or TabletopSimulator()
                    rng = np.random.default_rng([seed, i])
                    save_problem(path, structure_problem(sim, templates[i % len(templates)], objects, rng, name,
                                                         seed))
                paths.append(path)
        finally:
            if own and sim is not None:
                sim.close()
    return paths


def write_goal_problem(goal_path: Path, out_dir: Path, sim=None, overwrite: bool = False) -> Path:
    """Turn one goal file into out_dir/<stem>.json; an existing different file there is kept unless `overwrite`."""
    goal_path, out_dir = Path(goal_path), Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise ValueError(f"--out {out_dir} is a file, not a folder")
    _refuse_a_set_folder(out_dir)
    problem = goal_file_problem(goal_path, sim)
    with folder_lock(out_dir):
        _refuse_a_set_folder(out_dir)  # again, now that no other `problems` writes here
        path = path_under(out_dir, f"{problem.name}.json")
        if path.exists() and not overwrite and _load_or_none(path) != problem:
            raise ValueError(f"{path} already holds another problem; use --overwrite to replace it")
        save_problem(path, problem)
    return path


def _refuse_a_set_folder(out_dir: Path) -> None:
    """A goal problem does not join a generated set (its folder's problems.manifest): the set's own command,
    run again, could then neither complete nor --overwrite it."""
    if (out_dir / PROBLEMS_MANIFEST).exists():
        raise ValueError(f"{out_dir} holds a generated problem set ({PROBLEMS_MANIFEST}); write goal problems to a "
                         f"folder of their own (benchmark --problems takes several folders: A,B)")


def _load_or_none(path: Path) -> Problem | None:
    try:
        return load_problem(path)
    except ValueError:
        return None
