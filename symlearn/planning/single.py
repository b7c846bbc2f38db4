"""Planning and executing one problem file with one planner, optionally recorded (`symlearn plan`, the pipeline).

plan_problem loads the problem, checks every path it will write before any work (the recorded GIF and
its filmstrip beside it, and RUN/pddl/problems/NAME where PDDL planners write their tasks), builds the
planner and the run's models, executes the plan in a fresh simulator and saves the recording. The
command line and the pipeline both call it, so `symlearn plan` and the pipeline's recorded plan are
the same code.

    >>> done = plan_problem(Path("runs/paper"), Path("problems/p13/problem_0000.json"), "astar",
    ...                     ExecutionConfig(closed_loop=True), record=Path("runs/paper/plan.gif"))  # doctest: +SKIP
    >>> done.row.success, done.gif                                                            # doctest: +SKIP
    (True, PosixPath('runs/paper/plan.gif'))
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from symlearn.planning.execution import ExecutionConfig, ProblemRun
from symlearn.problems.problem import Problem

DEFAULT_RECORD_SIZE = (320, 240)  # recorded frame width x height


@dataclass(frozen=True)
class PlannedProblem:
    """What plan_problem did: the problem, its row, where the PDDL task went, and the recording if asked."""

    problem: Problem
    row: ProblemRun
    write_dir: Path  # RUN/pddl/problems/NAME: a PDDL planner's task files (absent for the in-process planners)
    gif: Path | None = None
    filmstrip: Path | None = None
    frames: int = 0  # recorded frames: the start and one after each executed action


def record_paths(record: Path | None) -> tuple[Path | None, Path | None]:
    """The GIF to record and its filmstrip (.png beside it), checked: two paths, neither a folder nor a file of
    another kind (e.g. RUN/transition.pt), so nothing is replaced that the user did not ask to replace."""
    from symlearn.outputs import GIF_MAGIC, PNG_MAGIC, distinct_outputs, file_output

    if not record:
        return None, None
    gif = Path(record)
    strip = gif.with_suffix(".png")
    distinct_outputs({"--record": gif, "its filmstrip": strip})
    return (file_output(gif, "--record", kind="a GIF", magic=GIF_MAGIC),
            file_output(strip, "--record's filmstrip", kind="a PNG", magic=PNG_MAGIC))


def check_writable(folder: Path) -> None:
    """Refuse, before any work, a folder the planner must write into (RUN/pddl/problems/NAME) that it cannot write."""
    existing = next((p for p in (folder, *folder.parents) if p.exists()), None)
    if existing is not None and not (existing.is_dir() and os.access(existing, os.W_OK | os.X_OK)):
        raise ValueError(f"cannot write the planner's tasks to {folder}: {existing} is not a writable folder "
                         f"(a read-only run? copy it somewhere writable)")


def plan_problem(run_dir: Path, problem_file: Path, planner: str = "astar",
                 config: ExecutionConfig = ExecutionConfig(), record: Path | None = None,
                 record_size: tuple[int, int] = DEFAULT_RECORD_SIZE) -> PlannedProblem:
    """Plan `problem_file` with `planner` on RUN's models (the risk planners with config.risk_weight), execute it
    in the simulator and, with `record`, save the executed plan as that GIF and a filmstrip PNG beside it. Refusals (a bad path, an unknown planner, a
    malformed problem) are one-line ValueErrors raised before the simulator starts."""
    from symlearn.planning.execution import run_problem
    from symlearn.problems.paths import path_under
    from symlearn.planning.planners import make_planners
    from symlearn.problems.problem import load_problem
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    run_dir = Path(run_dir)
    gif, strip = record_paths(record)  # refused before any work
    problem = load_problem(Path(problem_file))
    write_dir = path_under(run_dir / "pddl" / "problems", problem.name)  # the name is checked at load
    check_writable(write_dir)
    fn = make_planners([planner], run_dir, write_dir=write_dir, risk_weight=config.risk_weight)[planner]
    encoder, transition = planning_models(run_dir)
    recorder = None
    if gif is not None:
        from symlearn.planning.recording import PlanRecorder

        recorder = PlanRecorder(width=record_size[0], height=record_size[1])
    with TabletopSimulator() as sim:
        row = run_problem(sim, encoder, transition, problem, planner, fn, config, recorder=recorder)
    if recorder is None:
        return PlannedProblem(problem, row, write_dir)
    return PlannedProblem(problem, row, write_dir, recorder.save_gif(gif), recorder.save_filmstrip(strip),
                          len(recorder.frames))
