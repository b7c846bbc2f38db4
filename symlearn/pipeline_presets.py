"""The pipeline's presets and settings: PipelinePreset (per stage, the name of that stage's preset, defined beside
its config class, and what is the pipeline's own: its stages, planners and sizes), PRESETS (`recommended`, `demo`,
`paper`; symlearn.pipeline says what each runs), and PipelineSettings, what one `symlearn pipeline` runs: a preset,
OUT, and the overrides of flags and a settings file. Nothing here imports a stage's library.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from symlearn.config_file import RECIPE
from symlearn.planning.planner_catalogue import DEFAULT_PLANNER

DATA, DATA_EXTRA, RUN, PROBLEMS = "data", "data_extra", "run", "problems"  # OUT's folders


@dataclass(frozen=True)
class PipelinePreset:
    """One named preset of the whole pipeline: per stage, the name of that stage's preset in the table beside its
    config class (TRAIN_PRESETS, TRANSITION_PRESETS, LIFTED_PRESETS, EXECUTION_PRESETS), and only what is the
    pipeline's own: which stages run (the extra data set, the lifted or the rules export, stratified or random-walk
    problems), which planners, and the sizes, where a value left None is the default of the config (or library
    function) that holds it. `demo` is `recommended` with smaller sizes and the lifted preset for small data.
    """

    train: str  # TrainConfig.from_preset name (training.TRAIN_PRESETS, models.PRESETS)
    transition: str  # TransitionConfig.from_preset name (transition_model.TRANSITION_PRESETS)
    execution: str  # execution.EXECUTION_PRESETS name: how the benchmark and the recorded plan execute
    # the lifted domain with this lifted_export.LIFTED_PRESETS name (m(z) then needs its preset's location bits);
    # None: the rules export (export_pddl) with ExportConfig's defaults
    lifted: str | None = None
    # problems stratified by shortest-plan length (generate_stratified; `problems` per cell) instead of
    # random walks (generate_problems, ProblemConfig's ranges)
    stratified: bool = False
    planners: tuple[str, ...] = ("astar",)  # benchmarked planners; the first plans the recorded RUN/plan.gif
    # a second set of scenes with this range of objects, read by m(z) and the export only (not the effect model)
    extra_objects: tuple[int, int] | None = None
    # sizes: None is the holder's default
    samples: int | None = None  # CollectConfig.n of the main set (the paper's exploration: 1-3 objects)
    extra_samples: int | None = None  # CollectConfig.n of the extra set
    epochs: int | None = None  # TrainConfig.epochs
    transition_epochs: int | None = None  # TransitionConfig.epochs
    min_count: int | None = None  # analyse_symbols' min_count (symbols.FREQUENT_MIN_COUNT)
    problem_objects: tuple[int, int] | None = None  # stratified: the object range (stratified.OBJECTS if None)
    problems: int | None = None  # problems (per cell when stratified); None: N_PROBLEMS, stratified PER_CELL

    @property
    def stage_names(self) -> tuple[str, ...]:
        """The stages this preset runs, in order (symlearn.pipeline_stages.pipeline_stages builds each): the extra
        collection only with an extra data set."""
        extra = ("collect-extra",) if self.extra_objects else ()
        return ("collect", *extra, "train", "evaluate", "table1", "symbols", "train-transition", "export-pddl",
                "problems", "benchmark", "report")


# The recipe that plans best (pretrained/recommended/README.md), at full scale: 12,000 samples of the
# paper's exploration and 12,000 of 1-5 objects, the recipe's network, export and execution presets, 10 problems
# per cell of 1-5 objects.
RECOMMENDED = PipelinePreset(RECIPE, RECIPE, RECIPE, lifted="fast", stratified=True,
                             planners=(DEFAULT_PLANNER, "fast-downward-lifted"), extra_objects=(1, 5))

PRESETS = {
    RECIPE: RECOMMENDED,
    # the recipe in minutes on 2 busy cores (`make demo`): fewer samples and epochs, 2 problems per cell of 1-3
    # objects; symbols need fewer training objects to count as frequent, lifted rules fewer moves
    "demo": dataclasses.replace(RECOMMENDED, lifted="small", samples=1500, extra_samples=750, epochs=10,
                                transition_epochs=20, min_count=20, problem_objects=(1, 3), problems=2),
    # the paper-faithful setup: the paper's model sizes, learned codes only (no location bits), the rules export,
    # random-walk problems planned open loop
    "paper": PipelinePreset("paper", "paper", "paper", planners=("astar", "astar-ucs", "astar-outcomes",
                                                                 "rules-outcomes")),
}
DEFAULT_PRESET = RECIPE


@dataclass(frozen=True)
class PipelineSettings:
    """What the pipeline runs: a preset, the output folder, and the overrides of the preset."""

    out: Path
    preset: str = DEFAULT_PRESET
    n: int | None = None  # samples of each collected set (the main one and the extra one)
    # every stage's seed; None: a settings-file table's `seed` for its stage ([collect], [train], [export]), else 0
    seed: int | None = None
    epochs: int | None = None
    transition_epochs: int | None = None
    problems: int | None = None  # problems, per cell with a stratified preset
    workers: int = 1
    # the tables of a settings file (symlearn.config_file.read_config_file), over the preset's values and under the
    # fields above: {"train": {"batch_size": 32}, "collect": {"shard_size": 100}, ...}
    overrides: Mapping[str, Mapping[str, Any]] = dataclasses.field(default_factory=dict)
    stop_after: str | None = None  # stop after this stage (tests simulate an interruption with it)

    def __post_init__(self) -> None:
        if self.preset not in PRESETS:
            raise ValueError(f"unknown preset {self.preset!r}; known: {', '.join(PRESETS)}")
        for name in ("n", "epochs", "transition_epochs", "problems", "workers", "seed"):
            v, least = getattr(self, name), 0 if name == "seed" else 1
            if v is not None and not (isinstance(v, int) and not isinstance(v, bool) and v >= least):
                raise ValueError(f"--{name.replace('_', '-')} {v!r} must be an integer of at least {least}")
        names = self.preset_values.stage_names
        if self.stop_after is not None and self.stop_after not in names:
            raise ValueError(f"unknown stage {self.stop_after!r}; stages: {', '.join(names)}")

    def table(self, name: str) -> Mapping[str, Any]:
        """The settings file's table `name` (symlearn.config_file.TABLES), {} where it has none."""
        return self.overrides.get(name, {})

    @property
    def preset_values(self) -> PipelinePreset:
        """The preset this run starts from."""
        return PRESETS[self.preset]

