"""The pipeline's stage configs and their builders: each stage's frozen config (the library's own config class, or
one of these holding the arguments the pipeline passes), built from the settings over the stage's preset and a
settings file's table. A builder imports its config's module when called: those load torch and the simulator.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

from symlearn.config_file import flat_overrides, replace_nested
from symlearn.pipeline_presets import DATA_EXTRA, PipelineSettings
from symlearn.planning.planner_catalogue import PlannerConfig

if TYPE_CHECKING:  # the configs' modules load torch (and the simulator): imported where a stage is built
    from symlearn.export.lifted_export import LiftedConfig
    from symlearn.export.rules_export import ExportConfig
    from symlearn.learning.training import TrainConfig
    from symlearn.planning.execution import ExecutionConfig
    from symlearn.problems.problem_generation import ProblemConfig
    from symlearn.sim.collect import CollectConfig
    from symlearn.symbolic.transition_model import TransitionConfig

# The extra set is drawn from seed + 2, as the recipe's data/k15 (seed 2) beside the paper-size set (seed 0).
EXTRA_SEED_OFFSET = 2

# A stage whose library function takes a config dataclass records that config (CollectConfig, TrainConfig,
# ExportConfig); the others record one of these, holding the arguments the pipeline passes.


@dataclass(frozen=True)
class EmptyStageConfig:
    """The config of a stage with nothing to set: it reads its inputs and writes its outputs (evaluate, table1,
    report)."""


@dataclass(frozen=True)
class SymbolsStageConfig:
    """analyse_symbols' arguments: a symbol is frequent from min_count training objects."""

    min_count: int


@dataclass(frozen=True)
class TransitionStageConfig:
    """train_transition's arguments: m(z)'s config, the training seed, and the extra data sets (OUT's folders)
    whose train and val splits join the main set's."""

    transition: TransitionConfig
    seed: int
    extra_data: tuple[str, ...] = ()


@dataclass(frozen=True)
class LiftedStageConfig:
    """export_lifted's arguments: its config, and the extra data sets (OUT's folders) whose scenes m(z) is asked
    about beside the main set's."""

    lifted: LiftedConfig
    extra_data: tuple[str, ...] = ()


@dataclass(frozen=True)
class ProblemsStageConfig:
    """generate_problems' arguments: n random-walk problems drawn from `seed` with `problem`'s ranges."""

    n: int
    seed: int
    problem: ProblemConfig


@dataclass(frozen=True)
class StratifiedStageConfig:
    """generate_stratified's arguments: n problems per cell of `objects` x shortest-plan length, from `seed`."""

    n: int
    seed: int
    objects: tuple[int, int]


@dataclass(frozen=True)
class BenchmarkStageConfig:
    """The benchmark's planners and execution settings; the first planner plans the first problem, recorded as
    RUN/plan.gif for the report."""

    planners: tuple[str, ...]
    execution: ExecutionConfig
    planner: PlannerConfig = PlannerConfig()  # the planners' own settings ([planner]: risk_weight)
    # search-time inference runs the networks on small batches, many times slower on 2 threads than on 1 when
    # another busy process shares the cores (docs/BENCHMARKS.md): the benchmark command's default
    threads: int = 1


def _given(**values) -> dict:
    """The keyword arguments that are set: a None leaves the config's own default."""
    return {k: v for k, v in values.items() if v is not None}


def _first(*values):
    """The first value that is not None (an override before the preset's), else None."""
    return next((v for v in values if v is not None), None)


def _seed(s: PipelineSettings, table: str | None = None) -> int:
    """A stage's seed: --seed, else the `seed` of the stage's settings-file table, else 0."""
    return _first(s.seed, s.table(table).get("seed") if table else None, 0)


def _extra_data(s: PipelineSettings) -> tuple[str, ...]:
    """OUT's folders of the extra data sets this preset collects."""
    return (DATA_EXTRA,) if s.preset_values.extra_objects else ()


def collect_config(s: PipelineSettings) -> CollectConfig:
    from symlearn.sim.collect import CollectConfig

    cfg = replace_nested(CollectConfig(**_given(n=s.preset_values.samples)), s.table("collect"))
    return dataclasses.replace(cfg, seed=_seed(s, "collect"), **_given(n=s.n))


def collect_extra_config(s: PipelineSettings) -> CollectConfig:
    from symlearn.sim.collect import CollectConfig
    from symlearn.sim.exploration import ExplorationConfig

    p = s.preset_values
    cfg = replace_nested(CollectConfig(**_given(n=p.extra_samples)), s.table("collect"))
    return dataclasses.replace(cfg, seed=_seed(s, "collect") + EXTRA_SEED_OFFSET, **_given(n=s.n),
                               exploration=ExplorationConfig.with_k_range(*p.extra_objects))


def train_config(s: PipelineSettings) -> TrainConfig:
    import torch

    from symlearn.learning.training import TrainConfig

    p = s.preset_values
    # bf16 autocast on a GPU only, as the pipeline has always trained (plain float32 on a CPU)
    values = {"bf16": torch.cuda.is_available(), **_given(epochs=p.epochs), **flat_overrides(s.table("train"))}
    return TrainConfig.from_preset(p.train, **{**values, "seed": _seed(s, "train"), **_given(epochs=s.epochs)})


def symbols_config(s: PipelineSettings) -> SymbolsStageConfig:
    from symlearn.symbolic.symbols import FREQUENT_MIN_COUNT

    return SymbolsStageConfig(min_count=_first(s.preset_values.min_count, FREQUENT_MIN_COUNT))


def transition_config(s: PipelineSettings) -> TransitionStageConfig:
    from symlearn.symbolic.transition_model import TransitionConfig

    p = s.preset_values
    values = {**_given(epochs=p.transition_epochs), **s.table("transition"), **_given(epochs=s.transition_epochs)}
    cfg = TransitionConfig.from_preset(p.transition, **values)
    return TransitionStageConfig(cfg, seed=_seed(s), extra_data=_extra_data(s))


def export_config(s: PipelineSettings) -> ExportConfig:
    from symlearn.export.rules_export import ExportConfig

    return dataclasses.replace(replace_nested(ExportConfig(), s.table("export")), seed=_seed(s, "export"))


def lifted_config(s: PipelineSettings) -> LiftedStageConfig:
    from symlearn.export.lifted_export import LIFTED_PRESETS

    cfg = replace_nested(LIFTED_PRESETS[s.preset_values.lifted], s.table("lifted"))
    return LiftedStageConfig(cfg, extra_data=_extra_data(s))


def problems_config(s: PipelineSettings) -> ProblemsStageConfig:
    from symlearn.problems.problem_generation import N_PROBLEMS, ProblemConfig

    n = _first(s.problems, s.preset_values.problems, N_PROBLEMS)
    return ProblemsStageConfig(n=n, seed=_seed(s), problem=replace_nested(ProblemConfig(), s.table("problems")))


def stratified_config(s: PipelineSettings) -> StratifiedStageConfig:
    from symlearn.problems.stratified import OBJECTS, PER_CELL

    p = s.preset_values
    return StratifiedStageConfig(n=_first(s.problems, p.problems, PER_CELL), seed=_seed(s),
                                 objects=_first(p.problem_objects, OBJECTS))


def benchmark_config(s: PipelineSettings) -> BenchmarkStageConfig:
    from symlearn.planning.execution import EXECUTION_PRESETS

    p = s.preset_values
    ex = EXECUTION_PRESETS[p.execution]
    return BenchmarkStageConfig(planners=p.planners, execution=replace_nested(ex, s.table("execution")),
                                planner=replace_nested(PlannerConfig(), s.table("planner")))

