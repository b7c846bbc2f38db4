"""The pipeline's stages: each stage's call of the library function its `symlearn` sub-command calls (taking OUT, its
config and the settings; what it prints goes to the stage's log), and Stage, the table of a preset's stages with
their config builders (symlearn.pipeline_configs) and the paths each reads and writes in OUT.
"""
from __future__ import annotations

import contextlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterator

from symlearn.pipeline_configs import (BenchmarkStageConfig, EmptyStageConfig, LiftedStageConfig, ProblemsStageConfig,
                                       StratifiedStageConfig, SymbolsStageConfig, TransitionStageConfig,
                                       benchmark_config, collect_config, collect_extra_config, export_config,
                                       lifted_config, problems_config, stratified_config, symbols_config,
                                       train_config, transition_config)
from symlearn.pipeline_presets import DATA, DATA_EXTRA, PROBLEMS, RUN, PipelinePreset, PipelineSettings

if TYPE_CHECKING:  # the configs' modules load torch (and the simulator)
    from symlearn.export.rules_export import ExportConfig
    from symlearn.learning.training import TrainConfig
    from symlearn.sim.collect import CollectConfig

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
    from symlearn.planning.benchmark import benchmark
    from symlearn.planning.benchmark_summary import format_table
    from symlearn.planning.plan_one import plan_problem

    run, ex = out / RUN, cfg.execution
    with _torch_threads(cfg.threads):
        res = benchmark(run, out / PROBLEMS, list(cfg.planners), run / "benchmark.json", execution=ex,
                        show_progress=False, record_dir=run / "recordings", planner_config=cfg.planner)
        print(format_table(res))
        planner = cfg.planners[0]
        done = plan_problem(run, _first_problem(out), planner, ex, record=run / "plan.gif", planner_config=cfg.planner)
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
    """The stages a preset runs, in the order of PipelinePreset.stage_names: the extra collection only with extra data,
    the lifted export or the rules export, stratified or random-walk problems."""
    D, X, R, P = DATA, DATA_EXTRA, RUN, PROBLEMS  # noqa: N806
    empty = lambda s: EmptyStageConfig()  # noqa: E731
    data = (f"{D}/manifest.json",)
    extra = (f"{X}/manifest.json",) if p.extra_objects else ()  # read by m(z) and the export only
    nets = (f"{R}/best.pt", f"{R}/transition.pt")
    if p.lifted:
        domain = f"{R}/pddl/lifted.json"
        export = Stage("export-pddl", lifted_config, _export_lifted, data + extra + nets,
                       (f"{R}/pddl/lifted/domain.pddl", domain), (f"{R}/pddl/lifted",))
    else:
        domain = f"{R}/pddl/rules.json"
        export = Stage("export-pddl", export_config, _export_pddl, data + nets, (f"{R}/pddl/domain.pddl", domain),
                       (f"{R}/pddl/report.json", f"{R}/pddl/outcomes.json"))
    problems = (Stage("problems", stratified_config, _stratified, (), (P,)) if p.stratified
                else Stage("problems", problems_config, _problems, (), (P,)))
    stages = [
        Stage("collect", collect_config, _collect_into(D), (), data, (D,)),
        Stage("collect-extra", collect_extra_config, _collect_into(X), (), extra, (X,)),
        Stage("train", train_config, _train, data, (f"{R}/best.pt", f"{R}/metrics.json"),
              (f"{R}/last.pt", f"{R}/config.json")),
        Stage("evaluate", empty, _evaluate, data + (f"{R}/best.pt",), (f"{R}/eval.json",)),
        Stage("table1", empty, _table1, (f"{R}/best.pt",), (f"{R}/table1.json",), (f"{R}/table1_attention.png",)),
        Stage("symbols", symbols_config, _symbols, data + (f"{R}/best.pt",), (f"{R}/symbols.json", f"{R}/symbols.png"),
              (f"{R}/symbol_examples.png",)),
        Stage("train-transition", transition_config, _train_transition, data + extra + (f"{R}/best.pt",),
              (f"{R}/transition.pt", f"{R}/transition_metrics.json")),
        export,
        problems,
        Stage("benchmark", benchmark_config, _benchmark, nets + (domain, P), (f"{R}/benchmark.json", f"{R}/plan.gif"),
              (f"{R}/benchmark.json.rows.jsonl", f"{R}/plan.png", f"{R}/recordings", f"{R}/plan_tasks")),
        Stage("report", empty, _report,
              (f"{R}/eval.json", f"{R}/table1.json", f"{R}/symbols.json", f"{R}/transition_metrics.json",
               f"{R}/benchmark.json", f"{R}/plan.gif"), (f"{R}/report.html", f"{R}/report.md"), (f"{R}/report_files",)),
    ]
    by_name = {stage.name: stage for stage in stages}
    return [by_name[name] for name in p.stage_names]
