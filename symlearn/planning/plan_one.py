"""Planning and executing one problem file with one planner, optionally recorded (`symlearn plan`, the pipeline).

plan_problem loads the problem, checks every path it will write before any work (the recorded GIF, its
filmstrip and its task folder beside it), builds the planner and the run's models, executes the plan in a
fresh simulator and saves the recording. The run is only read (symlearn.planning.run_folder): a PDDL
planner writes its task files into a work folder removed afterwards, and with a recording they are kept
beside it (plan.gif -> plan_tasks/), so a shipped run such as pretrained/recommended is planned on as it
is. The command line and the pipeline both call it, so `symlearn plan` and the pipeline's recorded plan
are the same code.

    >>> done = plan_problem(Path("runs/paper"), Path("problems/p13/problem_0000.json"), "astar",
    ...                     ExecutionConfig(closed_loop=True), record=Path("runs/paper/plan.gif"))  # doctest: +SKIP
    >>> done.row.success, done.gif                                                            # doctest: +SKIP
    (True, PosixPath('runs/paper/plan.gif'))
"""
from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

from symlearn.planning.execution import ExecutionConfig, ProblemRun
from symlearn.planning.planner_catalogue import PlannerConfig
from symlearn.problems.problem import Problem

DEFAULT_RECORD_SIZE = (320, 240)  # recorded frame width x height


@dataclass(frozen=True)
class PlannedProblem:
    """What plan_problem did: the problem, its row, where the PDDL task was kept, and the recording if asked."""

    problem: Problem
    row: ProblemRun
    write_dir: Path | None  # the task folder beside the recording (plan_tasks/), None when no task file was kept
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


TASKS_SUFFIX = "_tasks"  # plan.gif's task folder: plan_tasks/ beside it
TASK_FILE_SUFFIXES = (".pddl",)  # what a planner writes into its task folder (domain and problem)


def task_folder(gif: Path | None) -> Path | None:
    """Where a recorded plan keeps its planner's task files: beside the GIF, plan.gif -> plan_tasks/ (None without
    a recording), checked before any work: not a file, not under one, and holding nothing but task files, since a
    new plan replaces it whole."""
    from symlearn.outputs import distinct_outputs, folder_output

    if gif is None:
        return None
    tasks = folder_output(gif.with_name(gif.stem + TASKS_SUFFIX), "--record's task folder")
    distinct_outputs({"--record": gif, "its task folder": tasks})
    if tasks.is_dir():
        other = next((p for p in tasks.iterdir() if not (p.is_file() and p.suffix in TASK_FILE_SUFFIXES)), None)
        if other is not None:
            raise ValueError(f"--record's task folder {tasks} holds {other.name}, which is no planner's task file; "
                             f"refusing to replace it")
    return tasks


def keep_tasks(work: Path, tasks: Path | None) -> Path | None:
    """Move what the planner wrote in its work folder to `tasks` as one unit (replacing an earlier plan's; none
    stays when this planner wrote nothing); returns the folder kept, or None."""
    from pddl_export.files import atomic_write_folder

    if tasks is None:
        return None
    files = {p.name: p.read_bytes() for p in sorted(work.iterdir()) if p.is_file()}
    if not files:
        if tasks.is_dir():
            shutil.rmtree(tasks)  # an earlier plan's tasks, not this recording's (task_folder checked its files)
        return None
    return atomic_write_folder(tasks, files)


def plan_problem(run_dir: Path, problem_file: Path, planner: str = "astar",
                 config: ExecutionConfig = ExecutionConfig(), record: Path | None = None,
                 record_size: tuple[int, int] = DEFAULT_RECORD_SIZE,
                 planner_config: PlannerConfig = PlannerConfig()) -> PlannedProblem:
    """Plan `problem_file` with `planner` (built with `planner_config`) on RUN's models, execute it
    in the simulator and, with `record`, save the executed plan as that GIF and a filmstrip PNG beside it, and the
    planner's task files, if it wrote any, in the task folder beside them (task_folder). RUN is only read. Refusals
    (a bad path, an unknown planner, a malformed problem) are one-line ValueErrors raised before the simulator starts."""
    from search.processes import temp_dir
    from symlearn.planning.execution import run_problem
    from symlearn.planning.planners import make_planners
    from symlearn.planning.run_folder import Run
    from symlearn.problems.problem import load_problem
    from symlearn.sim.simulator import TabletopSimulator

    run = Run(run_dir)  # only read: nothing is written into it
    gif, strip = record_paths(record)  # refused before any work
    tasks = task_folder(gif)
    problem = load_problem(Path(problem_file))
    with temp_dir("symlearn-plan-") as work:  # the planner's task files, removed afterwards unless kept
        fn = make_planners([planner], run.path, write_dir=work, config=planner_config)[planner]
        encoder, transition = run.planning_models()
        recorder = None
        if gif is not None:
            from symlearn.planning.recording import PlanRecorder

            recorder = PlanRecorder(width=record_size[0], height=record_size[1])
        with TabletopSimulator() as sim:
            row = run_problem(sim, encoder, transition, problem, planner, fn, config, recorder=recorder)
        if recorder is None:
            return PlannedProblem(problem, row, None)
        return PlannedProblem(problem, row, keep_tasks(work, tasks), recorder.save_gif(gif),
                              recorder.save_filmstrip(strip), len(recorder.frames))
