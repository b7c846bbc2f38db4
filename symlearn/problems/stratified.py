"""Problem sets stratified by shortest-plan length: n problems per cell of objects x shortest-plan length.

`symlearn problems` (its default kind, stratified) fills the cells (k objects, 1-5) x (shortest plan 1-2, 3-4, 5-6,
7-8, 9-12 actions), plus one "off" cell per object count: goals that leave a judged object off the table locations
(no shortest length: symlearn.problems.shortest), kept apart from the on-location cells. Problem i of a cell
is the first of its draws (rng [seed, k, lo, hi, i, draw]; the off cell has lo = hi = 0) that falls in the
cell and is not already in the cell or in an `exclude`d set (same initial and goal scene within 2 cm). Draws
cycle over three sources:

- "walk": a random walk (problem_generation.generate_problem) of a length drawn in lo..2*hi (1..8 for the
  off cell, which only walks can fill), task "random-walk";
- "structure": a structure-suite task that fits k objects (structure_suite), task its own name;
- "aimed": from a start made by 0..8 random actions on a dropped scene (so towers and far-row sticks start
  too), a walk aimed at a state of the symbolic model lo..hi actions away, drawn uniformly among those
  states and reached by a shortest plan, task "aimed-walk". Random walks seldom end deep: from a dropped
  5-object scene 25 of the model's 30,240 states need 9 actions, 3 of 3,024 need 7 with 4 objects, and
  none needs 5 with 3 objects (those start stacked).

A cell the model cannot fill is skipped up front (MODEL_MAX_LENGTH: 1 object never needs more than 1 action,
2 objects 4, 3 objects 6: the exact diameters of the model's state spaces); a cell whose problem finds no
draw in MAX_CELL_DRAWS is given up and reported. Problems already written are kept, so the same command
resumes an interrupted set.

    >>> paths, cells = generate_stratified(Path("problems/dev"), n=10, objects=(1, 5), seed=1000)  # doctest: +SKIP
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from symlearn.problems.paths import path_under
from symlearn.problems.problem import (GOAL_TOLERANCE_M, PROBLEM_VERSION, OutOfReach, Problem, load_problem,
                                       load_problems, save_problem)
from symlearn.problems.problem_generation import (MANIFEST_FORMAT, ProblemConfig, _changing_action, _done,
                                                  _is_count, generate_problem, prepare_problem_dir)
from symlearn.problems.shortest import NotCovered, scene_state, with_shortest
from symlearn.problems.stacking import successors
from symlearn.provenance import sha256_bytes
from symlearn.sim.exploration import MAX_OBJECTS, ExplorationConfig, sample_scene_spec
from symlearn.world import decode_action

SHORTEST_BUCKETS = ((1, 2), (3, 4), (5, 6), (7, 8), (9, 12))
# The longest shortest plan between any two states of the model, by object count (breadth-first search from
# every state: 6, 42 and 336 states). 4 and 5 objects: at least 7 and 9 (the deepest states from a start).
MODEL_MAX_LENGTH = {1: 1, 2: 4, 3: 6}
MAX_CELL_DRAWS = 60  # draws for one problem of a cell before the cell is given up
OFF_WALK_LENGTH = (1, 8)  # walk lengths drawn for the off-location cell
SOURCES = ("walk", "structure", "aimed")
AIMED_WALK = "aimed-walk"  # the task of a walk aimed at a state of the model
AIMED_START_WALK = 8  # an aimed walk starts after 0..8 random actions from the dropped scene
AIMED_MAX_STATES = 200_000  # an aimed walk lists the model's states up to cell.hi actions away, at most this many
PER_CELL = 10  # problems per cell unless asked otherwise (`symlearn problems`, the recommended pipeline)
OBJECTS = (1, 5)  # the object range stratified unless asked otherwise: every scene size the data sets hold


@dataclass(frozen=True)
class Cell:
    """k objects and a shortest-plan range lo..hi; lo = hi = 0 is the off-location cell."""

    k: int
    lo: int
    hi: int

    @property
    def off(self) -> bool:
        return self.lo == 0

    @property
    def label(self) -> str:
        """The cell as the benchmark grid names it: "1-2" ... "9-12", or "off"."""
        return "off" if self.off else f"{self.lo}-{self.hi}"

    def name(self, i: int) -> str:
        """Problem name: k3_opt5-6_0007, or k3_off_0002."""
        return f"k{self.k}_off_{i:04d}" if self.off else f"k{self.k}_opt{self.lo}-{self.hi}_{i:04d}"

    def holds(self, problem: Problem) -> bool:
        if self.off:
            return problem.goal_off_locations > 0
        return problem.optimal_length is not None and self.lo <= problem.optimal_length <= self.hi


def shortest_cells(objects: tuple[int, int]) -> tuple[list[Cell], list[tuple[Cell, str]]]:
    """The cells to fill in the object range, and the cells skipped with the reason (the model's bound)."""
    cells, skipped = [], []
    for k in range(objects[0], objects[1] + 1):
        for lo, hi in SHORTEST_BUCKETS:
            bound = MODEL_MAX_LENGTH.get(k)
            if bound is not None and lo > bound:
                skipped.append((Cell(k, lo, hi), f"no goal of {k} object{'s' if k > 1 else ''} needs more than "
                                                 f"{bound} action{'s' if bound > 1 else ''} in the model"))
            else:
                cells.append(Cell(k, lo, hi))
        cells.append(Cell(k, 0, 0))
    return cells, skipped


def same_problem(a: Problem, b: Problem, tol: float = GOAL_TOLERANCE_M) -> bool:
    """Whether two problems ask the same: same objects and free set, initial and judged goal poses within tol."""
    if [t for t, _ in a.spec] != [t for t, _ in b.spec] or a.free != b.free:
        return False
    init = np.linalg.norm(a.initial.positions() - b.initial.positions(), axis=1).max()
    fixed = list(a.fixed)
    goal = np.linalg.norm(a.goal.positions()[fixed] - b.goal.positions()[fixed], axis=1).max()
    return bool(init <= tol and goal <= tol)


def _aimed(sim, rng: np.random.Generator, cell: Cell, name: str, seed: int) -> Problem | None:
    """A walk to a model state drawn among those cell.lo..cell.hi actions from a drawn initial scene."""
    expl = ExplorationConfig.with_k_range(cell.k, cell.k)
    expl = ExplorationConfig(k_values=expl.k_values, k_probs=expl.k_probs, pick_occupied_prob=1.0)
    spec = sample_scene_spec(rng, expl, cell.k)
    sim.build(spec)
    sim.reset(sim.get_scene())
    for _ in range(int(rng.integers(0, AIMED_START_WALK + 1))):  # a start of any arrangement, not only dropped ones
        if sim.step(_changing_action(rng, sim.occupied(), expl)).off_table:
            return None
    initial = sim.get_scene()
    try:
        start = scene_state(initial)
    except NotCovered:
        return None
    types = tuple(t for t, _ in spec)
    parent, frontier, deep = {start: None}, [start], []
    for depth in range(1, cell.hi + 1):
        nxt = []
        for state in frontier:
            for a, child in successors(state, types):
                if child not in parent:
                    parent[child] = (state, a)
                    nxt.append(child)
        if len(parent) > AIMED_MAX_STATES:  # 6-8 objects: the states within reach are too many to list
            return None
        if depth >= cell.lo:
            deep += nxt
        frontier = nxt
    if not deep:
        return None
    state, plan = deep[int(rng.integers(len(deep)))], []
    while parent[state] is not None:
        state, a = parent[state]
        plan.append(a)
    sim.reset(initial)  # execution starts from a reset to these poses, so the walk does too
    for a in reversed(plan):
        if sim.step(decode_action(a)).off_table:
            return None
    return with_shortest(Problem(name, seed, tuple(spec), initial, tuple(reversed(plan)), sim.get_scene(),
                                 task=AIMED_WALK))


def draw(sim, cell: Cell, i: int, attempt: int, seed: int) -> Problem | None:
    """Draw `attempt` of problem i of a cell (None where the source gives nothing this time)."""
    from symlearn.problems.structure_suite import fitting_templates, structure_problem

    rng = np.random.default_rng([seed, cell.k, cell.lo, cell.hi, i, attempt])
    source = "walk" if cell.off else SOURCES[attempt % len(SOURCES)]
    name = cell.name(i)
    try:
        if source == "walk":
            lo, hi = OFF_WALK_LENGTH if cell.off else (cell.lo, 2 * cell.hi)
            cfg = ProblemConfig(objects=(cell.k, cell.k), length=(lo, hi))
            return generate_problem(sim, rng, cfg, name, seed)
        if source == "structure":
            templates = fitting_templates((cell.k, cell.k))
            if not templates:  # the suite's tasks hold at most 5 objects
                return None
            template = templates[int(rng.integers(len(templates)))]
            return structure_problem(sim, template, (cell.k, cell.k), rng, name, seed)
        return _aimed(sim, rng, cell, name, seed)
    except RuntimeError:  # a walk or a task with no valid draw this time (the simulator refused it)
        return None
    except OutOfReach:  # a scene the problem format refuses: with 6-8 objects, one pushed out of reach
        return None


def _settings(n: int, objects: tuple[int, int], seed: int, exclude: list[tuple[str, str]]) -> dict:
    d = {"format": MANIFEST_FORMAT, "problem_version": PROBLEM_VERSION, "n": n, "objects": list(objects),
         "seed": seed, "stratify": "shortest"}
    if exclude:
        d["exclude"] = [{"folder": f, "sha256": h} for f, h in exclude]
    return d


def _set_hash(problems: list[tuple[Path, Problem]]) -> str:
    return sha256_bytes(b"".join(sha256_bytes(p.read_bytes()).encode() for p, _ in problems))[:16]


@dataclass(frozen=True)
class CellReport:
    """How far one cell got: problems written (of n), and why it stopped short."""

    cell: Cell
    filled: int
    n: int
    why: str = ""

    def line(self) -> str:
        head = f"k{self.cell.k} {self.cell.label:>5}: {self.filled}/{self.n}"
        return head + (f" ({self.why})" if self.why else "")


def generate_stratified(out_dir: Path, n: int, objects: tuple[int, int] = OBJECTS, seed: int = 0, sim=None,
                        overwrite: bool = False, exclude: tuple[Path, ...] = (),
                        progress=None) -> tuple[list[Path], list[CellReport]]:
    """Write n problems per cell (module doc) to out_dir; returns the paths and a report per cell.

    `exclude`: folders of problem sets (e.g. the dev set when making the test set) whose problems are never
    drawn again; their content hashes are part of the set's settings. `progress(line)` is told each cell's end.
    """
    from symlearn.sim.simulator import TabletopSimulator

    if not _is_count(n):
        raise ValueError(f"n={n!r} must be an integer of at least 1")
    if not _is_count(seed, least=0):
        raise ValueError(f"seed={seed!r} must be a non-negative integer")
    objects = (int(objects[0]), int(objects[1]))
    if not 1 <= objects[0] <= objects[1] <= MAX_OBJECTS:
        raise ValueError(f"object range {objects[0]}-{objects[1]} must lie within 1-{MAX_OBJECTS}")
    out_dir = Path(out_dir)
    banned: list[Problem] = []
    hashes = []
    for folder in exclude:
        if Path(folder).resolve() == out_dir.resolve():
            raise ValueError(f"--exclude {folder} is the set being made (--out)")
        loaded = load_problems(Path(folder))
        banned += [p for _, p in loaded]
        hashes.append((str(folder), _set_hash(loaded)))
    prepare_problem_dir(out_dir, _settings(n, objects, seed, hashes), overwrite)
    cells, skipped = shortest_cells(objects)
    reports = {c: CellReport(c, 0, n, why) for c, why in skipped}
    own, paths = sim is None, []
    try:
        for cell in cells:
            kept = [p for p in banned if p.k == cell.k]
            why, filled = "", 0
            for i in range(n):
                name = cell.name(i)
                path = path_under(out_dir, f"{name}.json")
                if _done(path, name):
                    kept.append(load_problem(path))
                    paths.append(path)
                    filled += 1
                    continue
                sim = sim or TabletopSimulator()
                found = None
                for attempt in range(MAX_CELL_DRAWS):
                    cand = draw(sim, cell, i, attempt, seed)
                    if cand is not None and cell.holds(cand) and not any(same_problem(cand, p) for p in kept):
                        found = cand
                        break
                if found is None:
                    why = f"no new problem in {MAX_CELL_DRAWS} draws for problem {i}"
                    break
                save_problem(path, found)
                kept.append(found)
                paths.append(path)
                filled += 1
            reports[cell] = CellReport(cell, filled, n, why)
            if progress is not None:
                progress(reports[cell].line())
    finally:
        if own and sim is not None:
            sim.close()
    order = sorted(reports, key=lambda c: (c.k, c.off, c.lo))
    return paths, [reports[c] for c in order]

