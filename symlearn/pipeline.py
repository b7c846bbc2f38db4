"""Every stage in order, resumable: collect (and collect-extra), train, evaluate, table1, symbols,
train-transition, export-pddl, problems, benchmark, report, into OUT/data (OUT/data_extra), OUT/run and
OUT/problems.

The presets (PRESETS): `recommended`, the default, is the recipe that plans best (its run is shipped as
pretrained/recommended, whose README gives the commands): the paper-size data set plus a set of 1-5-object
scenes that only m(z) and the export read, the quick effect model with the stability loss and the action on the
held object's token only, m(z) on 9 location bits, the lifted PDDL domain, problems stratified by shortest-plan length, astar-outcomes and stock Fast Downward
on the lifted domain, closed loop. `demo` is the same recipe at a small scale (minutes on 2 cores: `make demo`);
`paper` is the paper-faithful setup (its model sizes, learned codes only, the rules export, random-walk problems,
open loop).

Each stage is a call of the library function its `symlearn` sub-command calls, with a frozen config dataclass
built from the settings and the preset; what the stage prints, and the traceback of a crash, go to
OUT/logs/<stage>.log. OUT/pipeline.json (written atomically as every stage starts and finishes) records each stage's
config (as JSON), the hashes of its inputs and of its outputs. A stage is skipped when its record holds the same
config and input hashes and its outputs are still there unchanged; so an interrupted pipeline, run again, redoes
only what did not finish (and what depends on a change). A stage is recorded (config and inputs) before it runs: one
interrupted under the same config and inputs resumes (collect's shards, train's last.pt), while one whose record
holds another config or other inputs, or lost outputs, first removes the files it writes (Stage.written, inside OUT)
and runs as in a fresh run. So a run with other settings redoes exactly the stages whose config or inputs changed
and the stages after them that read their outputs, and ends with the files a fresh run of those settings writes.

The pipeline calls the library, never the command line: `symlearn pipeline` (symlearn.cli.pipeline) is a thin
front end to run_pipeline, and tests/test_layout.py keeps imports going that one way.

    >>> run_pipeline(PipelineSettings(preset="demo", out=Path("pipe")))   # doctest: +SKIP
    [1/11] collect ... done in 61.3 s
"""
from __future__ import annotations

import contextlib
import dataclasses
import json
import shutil
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator, Mapping

from pddl_export.bounded_json import AnyJson, JsonFileError, Map, Num, Obj, Opt, Str, check, read_json_file
from symlearn.folder_lock import folder_lock
from symlearn.planning.planner_catalogue import DEFAULT_PLANNER
from symlearn.provenance import atomic_write_json, sha256_bytes, sha256_file

if TYPE_CHECKING:  # the configs' modules load torch (and the simulator): imported where a stage is built
    from symlearn.learning.training import TrainConfig
    from symlearn.planning.execution import ExecutionConfig
    from symlearn.export.rules_export import ExportConfig
    from symlearn.export.lifted_export import LiftedConfig
    from symlearn.problems.problem_generation import ProblemConfig
    from symlearn.sim.collect import CollectConfig
    from symlearn.symbolic.transition_model import TransitionConfig

RECORD_FILE = "pipeline.json"
RECORD_KIND = "symlearn-pipeline"
DATA, DATA_EXTRA, RUN, PROBLEMS = "data", "data_extra", "run", "problems"  # OUT's folders
# The extra set is drawn from seed + 2, as the recipe's data/k15 (seed 2) beside the paper-size set (seed 0).
EXTRA_SEED_OFFSET = 2


@dataclass(frozen=True)
class PipelinePreset:
    """One named preset of the whole pipeline.

    The networks take the named presets of TrainConfig and TransitionConfig called `models`; a value left None is
    the default of the config (or library function) that holds it. Only what no config holds (which data sets
    and problems, which planners, closed loop and the time limit) and a small preset's smaller sizes are numbers
    here, and `demo` is `recommended` with smaller sizes, so each value has one definition.
    """

    models: str  # TrainConfig.from_preset and TransitionConfig.from_preset name
    samples: int | None = None  # CollectConfig.n of the main set (the paper's exploration: 1-3 objects)
    # a second set of scenes with this range of objects, read by m(z) and the export only (not the effect model)
    extra_objects: tuple[int, int] | None = None
    extra_samples: int | None = None  # its CollectConfig.n
    epochs: int | None = None  # TrainConfig.epochs
    transition_epochs: int | None = None  # TransitionConfig.epochs
    min_count: int | None = None  # analyse_symbols' min_count (symbols.FREQUENT_MIN_COUNT)
    # the lifted domain (export_lifted; m(z) then reads lifted_scene.FIELD_BITS location bits) instead of the
    # rules export (export_pddl) with these sizes
    lifted: bool = False
    lifted_min_count: int | None = None  # LiftedConfig.min_count (its default if None)
    max_objects: int | None = None  # ExportConfig.max_objects
    fidelity_cases: int | None = None  # ExportConfig.pddl_fidelity_cases
    # problems stratified by shortest-plan length (generate_stratified; `problems` per cell) instead of
    # random walks (generate_problems, ProblemConfig's ranges)
    stratified: bool = False
    problem_objects: tuple[int, int] | None = None  # stratified: the object range (stratified.OBJECTS if None)
    problems: int | None = None  # problems (per cell when stratified); None: N_PROBLEMS, stratified PER_CELL
    planners: tuple[str, ...] = ("astar",)  # benchmarked planners; the first plans the recorded RUN/plan.gif
    closed_loop: bool = False  # ExecutionConfig.closed_loop
    timeout_s: float | None = None  # ExecutionConfig.timeout_s

    @property
    def stage_names(self) -> tuple[str, ...]:
        """The stages this preset runs, in order."""
        return tuple(stage.name for stage in pipeline_stages(self))


# The recipe that plans best (pretrained/recommended/README.md), at full scale: 12,000 samples of the
# paper's exploration and 12,000 of 1-5 objects, the quick models, 10 problems per cell of 1-5 objects.
# The networks' presets of that name hold the effect model's and m(z)'s settings (TRAIN_PRESETS, TRANSITION_PRESETS);
# its execution is execution.RECOMMENDED_EXECUTION, what plan and benchmark do by default (a test keeps them equal).
RECOMMENDED = PipelinePreset(
    "recommended", extra_objects=(1, 5), lifted=True, stratified=True,
    planners=(DEFAULT_PLANNER, "fast-downward-lifted"), closed_loop=True, timeout_s=10.0)

PRESETS = {
    "recommended": RECOMMENDED,
    # the recipe in minutes on 2 busy cores (`make demo`): fewer samples and epochs, 2 problems per cell of 1-3
    # objects; symbols need fewer training objects to count as frequent, rules fewer answers of m(z)
    "demo": dataclasses.replace(RECOMMENDED, samples=1500, extra_samples=750, epochs=10, transition_epochs=20,
                                min_count=20, lifted_min_count=3, problem_objects=(1, 3), problems=2),
    # the paper-faithful setup: the paper's model sizes, learned codes only (no location bits), the rules export,
    # random-walk problems planned open loop
    "paper": PipelinePreset("paper", planners=("astar", "astar-ucs", "astar-outcomes", "rules-outcomes")),
}
DEFAULT_PRESET = "recommended"


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


# ------------------------------------------------------------------------------- stage configs
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


def _collect_config(s: PipelineSettings) -> CollectConfig:
    from symlearn.config_file import replace_nested
    from symlearn.sim.collect import CollectConfig

    cfg = replace_nested(CollectConfig(**_given(n=s.preset_values.samples)), s.table("collect"))
    return dataclasses.replace(cfg, seed=_seed(s, "collect"), **_given(n=s.n))


def _collect_extra_config(s: PipelineSettings) -> CollectConfig:
    from symlearn.sim.collect import CollectConfig
    from symlearn.sim.exploration import ExplorationConfig

    from symlearn.config_file import replace_nested

    p = s.preset_values
    cfg = replace_nested(CollectConfig(**_given(n=p.extra_samples)), s.table("collect"))
    return dataclasses.replace(cfg, seed=_seed(s, "collect") + EXTRA_SEED_OFFSET, **_given(n=s.n),
                               exploration=ExplorationConfig.with_k_range(*p.extra_objects))


def _train_config(s: PipelineSettings) -> TrainConfig:
    import torch

    from symlearn.config_file import flat_overrides
    from symlearn.learning.training import TrainConfig

    p = s.preset_values
    # bf16 autocast on a GPU only, as the pipeline has always trained (plain float32 on a CPU)
    values = {"bf16": torch.cuda.is_available(), **_given(epochs=p.epochs), **flat_overrides(s.table("train"))}
    return TrainConfig.from_preset(p.models, **{**values, "seed": _seed(s, "train"), **_given(epochs=s.epochs)})


def _symbols_config(s: PipelineSettings) -> SymbolsStageConfig:
    from symlearn.symbolic.symbols import FREQUENT_MIN_COUNT

    return SymbolsStageConfig(min_count=_first(s.preset_values.min_count, FREQUENT_MIN_COUNT))


def _transition_config(s: PipelineSettings) -> TransitionStageConfig:
    from pddl_export.lifted_scene import FIELD_BITS
    from symlearn.symbolic.transition_model import TransitionConfig

    p = s.preset_values
    values = {**_given(epochs=p.transition_epochs, location_bits=FIELD_BITS if p.lifted else None),
              **s.table("transition"), **_given(epochs=s.transition_epochs)}
    cfg = TransitionConfig.from_preset(p.models, **values)
    return TransitionStageConfig(cfg, seed=_seed(s), extra_data=_extra_data(s))


def _export_config(s: PipelineSettings) -> ExportConfig:
    from symlearn.export.rules_export import ExportConfig

    from symlearn.config_file import replace_nested

    p = s.preset_values
    cfg = ExportConfig(**_given(max_objects=p.max_objects, pddl_fidelity_cases=p.fidelity_cases))
    return dataclasses.replace(replace_nested(cfg, s.table("export")), seed=_seed(s, "export"))


def _lifted_config(s: PipelineSettings) -> LiftedStageConfig:
    from symlearn.export.lifted_export import LiftedConfig

    from symlearn.config_file import replace_nested

    cfg = replace_nested(LiftedConfig(**_given(min_count=s.preset_values.lifted_min_count)), s.table("lifted"))
    return LiftedStageConfig(cfg, extra_data=_extra_data(s))


def _problems_config(s: PipelineSettings) -> ProblemsStageConfig:
    from symlearn.problems.problem_generation import N_PROBLEMS, ProblemConfig

    from symlearn.config_file import replace_nested

    n = _first(s.problems, s.preset_values.problems, N_PROBLEMS)
    return ProblemsStageConfig(n=n, seed=_seed(s), problem=replace_nested(ProblemConfig(), s.table("problems")))


def _stratified_config(s: PipelineSettings) -> StratifiedStageConfig:
    from symlearn.problems.stratified import OBJECTS, PER_CELL

    p = s.preset_values
    return StratifiedStageConfig(n=_first(s.problems, p.problems, PER_CELL), seed=_seed(s),
                                 objects=_first(p.problem_objects, OBJECTS))


def _benchmark_config(s: PipelineSettings) -> BenchmarkStageConfig:
    from symlearn.planning.execution import ExecutionConfig

    from symlearn.config_file import replace_nested

    p = s.preset_values
    ex = ExecutionConfig(closed_loop=p.closed_loop, **_given(timeout_s=p.timeout_s))
    return BenchmarkStageConfig(planners=p.planners, execution=replace_nested(ex, s.table("execution")))


# ------------------------------------------------------------------------------- stage calls
# Each takes (OUT, its config, the settings); what it prints goes to the stage's log.


def _collect_into(folder: str) -> Callable[[Path, CollectConfig, PipelineSettings], None]:
    """The call of a collect stage writing OUT/folder."""

    def run(out: Path, cfg: CollectConfig, s: PipelineSettings) -> None:
        from symlearn.data.dataset import summarize
        from symlearn.sim.collect import collect

        collect(out / folder, cfg, workers=s.workers, show_progress=False)
        print(json.dumps(summarize(out / folder), indent=2, allow_nan=False))

    return run


def _train(out: Path, cfg: TrainConfig, s: PipelineSettings) -> None:
    from symlearn.learning.training import train

    res = train(out / DATA, out / RUN, cfg, show_progress=False)
    last = res["history"][-1] if res["history"] else {}
    print(json.dumps({"best_val_loss": res["best_val_loss"], "last_epoch": last}, indent=2, allow_nan=False))


def _evaluate(out: Path, cfg: EmptyStageConfig, s: PipelineSettings) -> None:
    from symlearn.learning.evaluation import evaluate, format_table

    print(format_table(evaluate(out / RUN, out / DATA)))


def _table1(out: Path, cfg: EmptyStageConfig, s: PipelineSettings) -> None:
    from symlearn.learning.table1 import format_table1, table1

    print(format_table1(table1(out / RUN)))


def _symbols(out: Path, cfg: SymbolsStageConfig, s: PipelineSettings) -> None:
    from symlearn.symbolic.symbols import analyse_symbols

    res = analyse_symbols(out / RUN, out / DATA, min_count=cfg.min_count)
    print(f"{res['n_objects']} training objects, {res['n_distinct']} distinct symbols, "
          f"{res['n_symbols_for_95pct']} cover 95%; weighted type purity {res['weighted_type_purity']}")


def _train_transition(out: Path, cfg: TransitionStageConfig, s: PipelineSettings) -> None:
    from symlearn.symbolic.transition_training import train_transition

    m = train_transition(out / RUN, out / DATA, cfg.transition, seed=cfg.seed, show_progress=False,
                         extra_data=tuple(out / d for d in cfg.extra_data))
    test = m["test"]
    print(json.dumps({"best_val_loss": m["best_val_loss"],
                      "test": {k: test[k] for k in ("bit_accuracy", "object_accuracy", "scene_accuracy")}}, indent=2))


def _export_pddl(out: Path, cfg: ExportConfig, s: PipelineSettings) -> None:
    from symlearn.export.rules_export import export_pddl

    rep = export_pddl(out / RUN, out / DATA, cfg)
    print(f"vocabulary {rep['vocabulary_size']} codes; {rep['n_rules']} rules over {rep['n_actions_with_rules']} "
          f"actions; fidelity (rules, every case) {rep['fidelity']:.4f}, through the PDDL {rep['pddl_fidelity']}")


def _export_lifted(out: Path, cfg: LiftedStageConfig, s: PipelineSettings) -> None:
    from symlearn.export.lifted_export import export_lifted

    rep = export_lifted(out / RUN, out / DATA, tuple(out / d for d in cfg.extra_data), cfg.lifted)
    print(f"kept learned bits {rep['kept_bits']}; {rep['moves']} moves ({rep['config']['source']} outcomes) -> "
          f"{rep['rules']} lifted rules ({rep['domain_bytes']} bytes of PDDL)")
    for data, checks in rep["checks_test_split"].items():
        for group, c in checks.items():
            print(f"  {data} test split, {group} objects ({c['cases']} steps): fidelity to m(z) "
                  f"{c['fidelity_to_net']:.3f}, accuracy {c['accuracy_rules']:.3f} (m(z) {c['accuracy_net']:.3f})")


def _problems(out: Path, cfg: ProblemsStageConfig, s: PipelineSettings) -> None:
    from symlearn.problems.problem_generation import generate_problems

    # a stage runs again only when its config changed, so the old problem set is replaced, never mixed
    paths = generate_problems(out / PROBLEMS, cfg.n, objects=cfg.problem.objects, length=cfg.problem.length,
                              seed=cfg.seed, overwrite=True, on_locations=cfg.problem.on_locations)
    print(f"wrote {len(paths)} problems to {out / PROBLEMS}")


def _stratified(out: Path, cfg: StratifiedStageConfig, s: PipelineSettings) -> None:
    from symlearn.problems.stratified import generate_stratified

    paths, cells = generate_stratified(out / PROBLEMS, cfg.n, objects=cfg.objects, seed=cfg.seed, overwrite=True,
                                       progress=lambda line: print(line, flush=True))
    print("cells (objects, shortest-plan length: problems written/asked):")
    for c in cells:
        print("  " + c.line())
    print(f"wrote {len(paths)} problems to {out / PROBLEMS}")


def _first_problem(out: Path) -> Path:
    files = sorted((out / PROBLEMS).glob("*.json"))
    if not files:
        raise RuntimeError(f"no problems in {out / PROBLEMS}")
    return files[0]


@contextlib.contextmanager
def _torch_threads(n: int) -> Iterator[None]:
    """torch uses n CPU threads inside the block, its former count after."""
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(before)


def _benchmark(out: Path, cfg: BenchmarkStageConfig, s: PipelineSettings) -> None:
    from symlearn.planning.benchmark import benchmark, format_table
    from symlearn.planning.single import plan_problem

    run, ex = out / RUN, cfg.execution
    with _torch_threads(cfg.threads):
        res = benchmark(run, out / PROBLEMS, list(cfg.planners), run / "benchmark.json", execution=ex,
                        show_progress=False, record_dir=run / "recordings")
        print(format_table(res))
        planner = cfg.planners[0]
        done = plan_problem(run, _first_problem(out), planner, ex, record=run / "plan.gif")
    row = done.row
    print(f"{done.problem.name} [{planner}]: found {row.found} ({row.status}), length {row.plan_length}, "
          f"success {row.success}; wrote {done.gif} ({done.frames} frames)")
    if row.status == "error":  # the planner could not run: not an answer about the problem
        raise RuntimeError(f"{planner} could not plan {done.problem.name}: {row.message}")


def _report(out: Path, cfg: EmptyStageConfig, s: PipelineSettings) -> None:
    from symlearn.report.build import build_report, write_report

    rep = build_report(out / RUN, out / DATA, out / RUN / "benchmark.json")
    html_path, md_path = write_report(rep, out / RUN)
    for sec in rep.sections:
        print(f"{sec.title}: {sec.status}" + (f" ({sec.note})" if sec.note else ""))
    print(f"wrote {html_path} and {md_path}")


@dataclass(frozen=True)
class Stage:
    """A named step: its config (a frozen dataclass built from the settings), the library call that runs it with
    that config, and the paths it reads and writes (relative to OUT; a folder hashes all its files)."""

    name: str
    config: Callable[[PipelineSettings], Any]
    run: Callable[[Path, Any, PipelineSettings], None]  # (OUT, config, settings)
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    # what else it writes (its resume state, side files and folders): removed with its outputs when it starts over
    owns: tuple[str, ...] = ()

    @property
    def written(self) -> tuple[str, ...]:
        """Every file and folder (relative to OUT) the stage writes, and only those: what a fresh start removes."""
        return self.outputs + self.owns


def pipeline_stages(p: PipelinePreset) -> list[Stage]:
    """The stages a preset runs, in order: the extra collection only with extra data, the lifted export or the
    rules export, stratified or random-walk problems."""
    D, X, R, P = DATA, DATA_EXTRA, RUN, PROBLEMS  # noqa: N806
    empty = lambda s: EmptyStageConfig()  # noqa: E731
    data = (f"{D}/manifest.json",)
    extra = (f"{X}/manifest.json",) if p.extra_objects else ()  # read by m(z) and the export only
    nets = (f"{R}/best.pt", f"{R}/transition.pt")
    if p.lifted:
        domain = f"{R}/pddl/lifted.json"
        export = Stage("export-pddl", _lifted_config, _export_lifted, data + extra + nets,
                       (f"{R}/pddl/lifted/domain.pddl", domain), (f"{R}/pddl/lifted",))
    else:
        domain = f"{R}/pddl/rules.json"
        export = Stage("export-pddl", _export_config, _export_pddl, data + nets, (f"{R}/pddl/domain.pddl", domain),
                       (f"{R}/pddl/report.json", f"{R}/pddl/outcomes.json"))
    problems = (Stage("problems", _stratified_config, _stratified, (), (P,)) if p.stratified
                else Stage("problems", _problems_config, _problems, (), (P,)))
    collect_extra = [Stage("collect-extra", _collect_extra_config, _collect_into(X), (), extra, (X,))] if extra else []
    return [
        Stage("collect", _collect_config, _collect_into(D), (), data, (D,)),
        *collect_extra,
        Stage("train", _train_config, _train, data, (f"{R}/best.pt", f"{R}/metrics.json"),
              (f"{R}/last.pt", f"{R}/config.json")),
        Stage("evaluate", empty, _evaluate, data + (f"{R}/best.pt",), (f"{R}/eval.json",)),
        Stage("table1", empty, _table1, (f"{R}/best.pt",), (f"{R}/table1.json",), (f"{R}/table1_attention.png",)),
        Stage("symbols", _symbols_config, _symbols, data + (f"{R}/best.pt",), (f"{R}/symbols.json", f"{R}/symbols.png"),
              (f"{R}/symbol_examples.png",)),
        Stage("train-transition", _transition_config, _train_transition, data + extra + (f"{R}/best.pt",),
              (f"{R}/transition.pt", f"{R}/transition_metrics.json")),
        export,
        problems,
        Stage("benchmark", _benchmark_config, _benchmark, nets + (domain, P), (f"{R}/benchmark.json", f"{R}/plan.gif"),
              (f"{R}/benchmark.json.rows.jsonl", f"{R}/plan.png", f"{R}/recordings", f"{R}/pddl/problems")),
        Stage("report", empty, _report,
              (f"{R}/eval.json", f"{R}/table1.json", f"{R}/symbols.json", f"{R}/transition_metrics.json",
               f"{R}/benchmark.json", f"{R}/plan.gif"), (f"{R}/report.html", f"{R}/report.md"), (f"{R}/report_files",)),
    ]


def config_json(config: Any) -> dict:
    """A stage's frozen config as the JSON object pipeline.json records (tuples as lists, as read back)."""
    return json.loads(json.dumps(dataclasses.asdict(config), allow_nan=False))


def stage_configs(s: PipelineSettings) -> dict[str, Any]:
    """Every stage's config for these settings, built before any stage runs so that a bad value is refused first."""
    return {stage.name: stage.config(s) for stage in pipeline_stages(s.preset_values)}


def path_hash(path: Path) -> str | None:
    """SHA-256 (16 hex digits) of a file, or of a folder's files (names and contents); None if missing."""
    if path.is_file():
        return sha256_file(path)[:16]
    if path.is_dir():
        parts = [f"{f.relative_to(path)}:{sha256_file(f)}" for f in sorted(path.rglob("*")) if f.is_file()]
        return sha256_bytes("\n".join(parts).encode())[:16]
    return None


def _hashes(out: Path, rels: tuple[str, ...]) -> dict[str, str | None]:
    return {r: path_hash(out / r) for r in rels}


_HASHES = Map(Opt(Str(64)), 100)  # relative path -> 16 hex digits, None where missing
# One finished stage as run_pipeline records it; is_done compares config, inputs and outputs. A record from
# before configs were recorded holds command lines ("argv") instead: it has no config, so its stage runs again.
# A stage that started and has not finished records its config and inputs, and when it started (no outputs).
STAGE_RECORD = Obj(optional={"config": Map(AnyJson(), 100), "inputs": _HASHES, "outputs": _HASHES,
                             "wall_s": Opt(Num()), "finished": Str(100), "started": Str(100), "out": Str(4096)})
RECORD_SCHEMA = Obj({"kind": Str(100), "stages": Map(STAGE_RECORD, 100)},
                    optional={"out": Str(4096), "preset": Str(100)})


def load_record(out: Path) -> dict:
    """OUT/pipeline.json, or an empty record; a foreign, unreadable or wrong-shaped file is refused in one line
    naming the file (and the field)."""
    path = out / RECORD_FILE
    if not path.exists():
        return {"kind": RECORD_KIND, "stages": {}}
    try:
        doc = read_json_file(path, what="pipeline record")
    except JsonFileError as e:
        raise ValueError(f"{e}; delete it to start over") from None
    if not isinstance(doc, dict) or doc.get("kind") != RECORD_KIND or not isinstance(doc.get("stages"), dict):
        raise ValueError(f"{path} is not a symlearn pipeline record; delete it to start over")
    try:
        check(doc, RECORD_SCHEMA, str(path))
    except JsonFileError as e:
        raise ValueError(f"{e}; delete it to start over") from None
    return doc


def is_done(stage: Stage, rec: dict | None, config: dict, inputs: dict) -> bool:
    """Whether a recorded stage can be skipped: same config, same inputs, outputs there and unchanged."""
    if not rec or rec.get("config") != config or rec.get("inputs") != inputs:
        return False
    outputs = rec.get("outputs") or {}
    return set(outputs) == set(stage.outputs) and all(
        h is not None and path_hash(Path(rec["out"]) / r) == h for r, h in outputs.items())


def starts_over(rec: dict | None, config: dict, inputs: dict) -> bool:
    """Whether a stage that is not done must start afresh, its earlier files removed: its record holds another
    config or other inputs, or says it finished (an output since lost or changed). A stage that started with this
    very config and these inputs and did not finish resumes (collect's shards, train's last.pt); one without a record
    is left to its library call, which resumes its own files or refuses foreign ones."""
    if rec is None:
        return False
    return rec.get("config") != config or rec.get("inputs") != inputs or "outputs" in rec


def clear_stage(out: Path, stage: Stage) -> list[str]:
    """Remove the files and folders `stage` writes in OUT (Stage.written), so that it starts as in a fresh run;
    returns those removed. Nothing else is touched: a symbolic link is removed as a link, and a path whose folder
    lies outside OUT (through a link) is refused in one line before anything is removed."""
    root = out.resolve()
    present = [r for r in stage.written if (out / r).is_symlink() or (out / r).exists()]
    present = [r for r in present if not any(o != r and Path(r).is_relative_to(o) for o in present)]  # in a folder
    for r in present:
        if not (out / r).parent.resolve().is_relative_to(root):
            raise ValueError(f"{out / r} lies outside {out} (through a symbolic link); stage {stage.name} must start "
                             "over and removes only files inside OUT: move it away or choose another --out")
    for r in present:
        path = out / r
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()
    return present


class StageError(RuntimeError):
    """A stage failed; the message is one line: the stage, the reason, and the log holding the details."""


def _reason(e: Exception) -> str:
    """One line for the terminal: a refusal's own message (ValueError, RuntimeError, OSError: what the command
    line prints as 'error: ...'), or a crash's exception type and first line."""
    first = (str(e).strip().splitlines() or [""])[0]
    return first if isinstance(e, (ValueError, RuntimeError, OSError)) else f"{type(e).__name__}: {first}"


def _run_stage(stage: Stage, config: Any, out: Path, s: PipelineSettings, log: Path) -> None:
    """Run one stage's library call, what it prints (and a failure's traceback) appended to `log`; a failure is
    raised as a one-line StageError naming the log, Ctrl-C as it came (the next run resumes)."""
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "a") as fh, contextlib.redirect_stdout(fh), contextlib.redirect_stderr(fh):
        print(f"== {stage.name} {time.strftime('%Y-%m-%dT%H:%M:%S')} config {json.dumps(config_json(config))}",
              flush=True)
        try:
            stage.run(out, config, s)
        except KeyboardInterrupt as e:
            print(f"interrupted{f' ({e})' if str(e) else ''}", flush=True)
            raise
        except Exception as e:  # noqa: BLE001 - the traceback to its log, one line to the terminal
            traceback.print_exc()
            raise StageError(f"stage {stage.name} failed: {_reason(e)}; see {log}") from None


def run_pipeline(s: PipelineSettings, echo: Callable[[str], None] = print) -> dict:
    """Run (or resume) every stage; returns the record written to OUT/pipeline.json."""
    out = Path(s.out)
    configs = stage_configs(s)  # a value no config accepts is refused before OUT is made
    with folder_lock(out):  # one writer: a second pipeline into this folder is refused at once
        return _run_stages(s, configs, out, echo)


def _run_stages(s: PipelineSettings, configs: dict[str, Any], out: Path, echo: Callable[[str], None]) -> dict:
    """run_pipeline's work, inside OUT's lock."""
    record = load_record(out)
    record.update(kind=RECORD_KIND, out=str(out), preset=s.preset)
    stages = pipeline_stages(s.preset_values)
    for name in set(record["stages"]) - set(configs):  # a stage of another preset: its files stay, its record goes
        record["stages"].pop(name)
    n = len(stages)
    for i, stage in enumerate(stages, 1):
        inputs = _hashes(out, stage.inputs)
        config = config_json(configs[stage.name])
        rec = record["stages"].get(stage.name)
        prefix = f"[{i}/{n}] {stage.name} ..."
        if is_done(stage, rec and {**rec, "out": str(out)}, config, inputs):
            echo(f"{prefix} skipped (done)")
        else:
            missing = [r for r, h in inputs.items() if h is None]
            if missing:
                raise RuntimeError(f"stage {stage.name} needs {out / missing[0]}, which an earlier stage did not write")
            if starts_over(rec, config, inputs):
                removed = clear_stage(out, stage)
                echo(f"{prefix} starting over" + (f": removed {', '.join(removed)}" if removed else ""))
            # recorded before it runs: an interrupted stage resumes only under this config and these inputs
            record["stages"][stage.name] = {"config": config, "inputs": inputs,
                                            "started": time.strftime("%Y-%m-%dT%H:%M:%S")}
            atomic_write_json(out / RECORD_FILE, record)
            t0 = time.perf_counter()
            _run_stage(stage, configs[stage.name], out, s, out / "logs" / f"{stage.name}.log")
            wall = time.perf_counter() - t0
            outputs = _hashes(out, stage.outputs)
            lost = [r for r, h in outputs.items() if h is None]
            if lost:
                raise RuntimeError(f"stage {stage.name} finished without writing {out / lost[0]}")
            record["stages"][stage.name] = {"config": config, "inputs": inputs, "outputs": outputs,
                                            "wall_s": round(wall, 2), "finished": time.strftime("%Y-%m-%dT%H:%M:%S")}
            atomic_write_json(out / RECORD_FILE, record)
            echo(f"{prefix} done in {wall:.1f} s")
        if stage.name == s.stop_after:
            echo(f"stopped after {stage.name} (--stop-after)")
            break
    return record
