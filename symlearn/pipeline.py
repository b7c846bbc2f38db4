"""Every stage in order, resumable: collect, train, evaluate, table1, symbols, train-transition, export-pddl,
problems, benchmark, report, into OUT/data, OUT/run and OUT/problems.

Each stage is one or more `symlearn` command lines run in this process (symlearn.cli.main.main), their
output kept in OUT/logs/<stage>.log. OUT/pipeline.json (written atomically after every finished stage)
records each stage's command lines, the hashes of its inputs and of its outputs. A stage is skipped when
its record holds the same command lines and input hashes and its outputs are still there unchanged;
so an interrupted pipeline, run again, redoes only what did not finish (and what depends on a change).

    >>> run_pipeline(PipelineSettings(preset="quick", out=Path("pipe"), n=2000))   # doctest: +SKIP
    [1/10] collect ... done in 61.3 s
"""
from __future__ import annotations

import contextlib
import time
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from pddl_export.bounded_json import JsonFileError, List, Map, Num, Obj, Opt, Str, check, read_json_file
from symlearn.folder_lock import folder_lock
from symlearn.provenance import atomic_write_json, sha256_bytes, sha256_file

RECORD_FILE = "pipeline.json"
RECORD_KIND = "symlearn-pipeline"
PRESETS = {
    "quick": dict(n=1000, problems=5, planners="astar", max_objects=2, fidelity_cases=100, min_count=20),
    "paper": dict(n=12000, problems=20, planners="astar,astar-ucs,astar-outcomes,rules-outcomes", max_objects=3, fidelity_cases=500,
                  min_count=100),
}


@dataclass(frozen=True)
class PipelineSettings:
    """What the pipeline runs: a preset, the output folder, and the overrides of the preset."""

    preset: str
    out: Path
    n: int | None = None
    seed: int = 0
    epochs: int | None = None
    transition_epochs: int | None = None
    problems: int | None = None
    workers: int = 1
    shard_size: int = 250
    stop_after: str | None = None  # stop after this stage (tests simulate an interruption with it)

    def __post_init__(self) -> None:
        if self.preset not in PRESETS:
            raise ValueError(f"unknown preset {self.preset!r}; known: {', '.join(PRESETS)}")
        for name in ("n", "epochs", "transition_epochs", "problems", "workers", "shard_size", "seed"):
            v, least = getattr(self, name), 0 if name == "seed" else 1
            if v is not None and not (isinstance(v, int) and not isinstance(v, bool) and v >= least):
                raise ValueError(f"--{name.replace('_', '-')} {v!r} must be an integer of at least {least}")
        if self.stop_after is not None and self.stop_after not in STAGE_NAMES:
            raise ValueError(f"unknown stage {self.stop_after!r}; stages: {', '.join(STAGE_NAMES)}")

    def get(self, key: str):
        """An override when given, else the preset's value."""
        v = getattr(self, key, None)
        return PRESETS[self.preset][key] if v is None else v


@dataclass(frozen=True)
class Stage:
    """A named step: its command lines (built when it runs), the paths it reads and the paths it writes."""

    name: str
    commands: Callable[[PipelineSettings], list[list[str]]]
    inputs: tuple[str, ...]  # relative to OUT; a folder hashes all its files
    outputs: tuple[str, ...]


def _opt(flag: str, v) -> list[str]:
    return [] if v is None else [flag, str(v)]


def _bf16() -> list[str]:
    import torch

    return [] if torch.cuda.is_available() else ["--no-bf16"]


def _first_problem(s: PipelineSettings) -> str:
    files = sorted((s.out / "problems").glob("*.json"))
    if not files:
        raise RuntimeError(f"no problems in {s.out / 'problems'}")
    return str(files[0])


def _stages() -> list[Stage]:
    D, R, P = "data", "run", "problems"  # noqa: N806

    def p(s: PipelineSettings, rel: str) -> str:
        return str(s.out / rel)

    return [
        Stage("collect", lambda s: [["collect", "--out", p(s, D), "--n", str(s.get("n")), "--seed", str(s.seed),
                                     "--workers", str(s.workers), "--shard-size", str(s.shard_size), "--quiet"]],
              (), (f"{D}/manifest.json",)),
        Stage("train", lambda s: [["train", "--data", p(s, D), "--out", p(s, R), "--preset", s.preset, "--seed",
                                   str(s.seed), *_opt("--epochs", s.epochs), *_bf16(), "--quiet"]],
              (f"{D}/manifest.json",), (f"{R}/best.pt", f"{R}/metrics.json")),
        Stage("evaluate", lambda s: [["evaluate", "--run", p(s, R), "--data", p(s, D)]],
              (f"{D}/manifest.json", f"{R}/best.pt"), (f"{R}/eval.json",)),
        Stage("table1", lambda s: [["table1", "--run", p(s, R)]], (f"{R}/best.pt",), (f"{R}/table1.json",)),
        Stage("symbols", lambda s: [["symbols", "--run", p(s, R), "--data", p(s, D), "--min-count",
                                     str(s.get("min_count"))]],
              (f"{D}/manifest.json", f"{R}/best.pt"), (f"{R}/symbols.json", f"{R}/symbols.png")),
        Stage("train-transition", lambda s: [["train-transition", "--run", p(s, R), "--data", p(s, D), "--preset",
                                              s.preset, "--seed", str(s.seed),
                                              *_opt("--epochs", s.transition_epochs), "--quiet"]],
              (f"{D}/manifest.json", f"{R}/best.pt"), (f"{R}/transition.pt", f"{R}/transition_metrics.json")),
        Stage("export-pddl", lambda s: [["export-pddl", "--run", p(s, R), "--data", p(s, D), "--max-objects",
                                         str(s.get("max_objects")), "--pddl-fidelity-cases",
                                         str(s.get("fidelity_cases")), "--seed", str(s.seed)]],
              (f"{D}/manifest.json", f"{R}/best.pt", f"{R}/transition.pt"),
              (f"{R}/pddl/domain.pddl", f"{R}/pddl/rules.json")),
        # a stage runs again only when its settings changed, so the old problem set is replaced, never mixed
        Stage("problems", lambda s: [["problems", "--out", p(s, P), "--n", str(s.get("problems")), "--seed",
                                      str(s.seed), "--overwrite"]], (), (P,)),
        Stage("benchmark", lambda s: [["benchmark", "--run", p(s, R), "--problems", p(s, P), "--planners",
                                       s.get("planners"), "--out", p(s, f"{R}/benchmark.json"), "--record",
                                       p(s, f"{R}/recordings"), "--quiet"],
                                      ["plan", "--run", p(s, R), "--problem", _first_problem(s), "--record",
                                       p(s, f"{R}/plan.gif")]],
              (f"{R}/best.pt", f"{R}/transition.pt", f"{R}/pddl/rules.json", P),
              (f"{R}/benchmark.json", f"{R}/plan.gif")),
        Stage("report", lambda s: [["report", "--run", p(s, R), "--data", p(s, D), "--benchmark",
                                    p(s, f"{R}/benchmark.json")]],
              (f"{R}/eval.json", f"{R}/table1.json", f"{R}/symbols.json", f"{R}/transition_metrics.json",
               f"{R}/benchmark.json", f"{R}/plan.gif"), (f"{R}/report.html", f"{R}/report.md")),
    ]


STAGES = _stages()
STAGE_NAMES = tuple(s.name for s in STAGES)


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
# One finished stage as run_pipeline records it; is_done compares argv, inputs and outputs.
STAGE_RECORD = Obj(optional={"argv": List(List(Str(4096), 200), 20), "inputs": _HASHES, "outputs": _HASHES,
                             "wall_s": Opt(Num()), "finished": Str(100), "out": Str(4096)})
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


def is_done(stage: Stage, rec: dict | None, argv: list[list[str]] | None, inputs: dict) -> bool:
    """Whether a recorded stage can be skipped: same command lines, same inputs, outputs there and unchanged."""
    if not rec or (argv is not None and rec.get("argv") != argv) or rec.get("inputs") != inputs:
        return False
    outputs = rec.get("outputs") or {}
    return set(outputs) == set(stage.outputs) and all(
        h is not None and path_hash(Path(rec["out"]) / r) == h for r, h in outputs.items())


def _run_commands(argv: list[list[str]], log: Path) -> None:
    """Run each command line with symlearn.cli.main.main, its stdout and stderr appended to `log`."""
    from symlearn.cli.main import main

    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "a") as fh, contextlib.redirect_stdout(fh), contextlib.redirect_stderr(fh):
        for cmd in argv:
            print(f"$ symlearn {' '.join(cmd)}", flush=True)
            try:
                rc = main(cmd)
            except SystemExit as e:  # argparse refused a flag (its one line is in the log)
                rc = e.code if isinstance(e.code, int) else 2
            except Exception as e:  # noqa: BLE001 - a stage's bug: the traceback to its log, one line to the terminal
                traceback.print_exc()
                first = (str(e).strip().splitlines() or [""])[0]
                raise RuntimeError(f"'symlearn {cmd[0]}' failed: {type(e).__name__}: {first}; see {log}") from None
            if rc == 130:  # the command caught Ctrl-C: stop here too; the next run resumes
                raise KeyboardInterrupt
            if rc != 0:
                fh.flush()
                reason = _last_error(log, cmd[0])
                raise RuntimeError(f"'symlearn {cmd[0]}' exited {rc}{': ' + reason if reason else ''}; see {log}")


def _last_error(log: Path, command: str, tail_bytes: int = 65536) -> str:
    """The last 'symlearn COMMAND: error: ...' (or 'interrupted') line in the end of a log, without its prefix; ''."""
    with open(log, "rb") as f:
        f.seek(max(f.seek(0, 2) - tail_bytes, 0))
        lines = f.read().decode("utf-8", errors="replace").splitlines()
    for line in reversed(lines):
        for prefix in (f"symlearn {command}: error: ", f"symlearn {command}: "):
            if line.startswith(prefix):
                return line[len(prefix):].strip()
        if line.startswith("symlearn: error: "):  # argparse's refusal of a flag
            return line[len("symlearn: error: "):].strip()
    return ""


def run_pipeline(s: PipelineSettings, echo: Callable[[str], None] = print) -> dict:
    """Run (or resume) every stage; returns the record written to OUT/pipeline.json."""
    out = Path(s.out)
    with folder_lock(out):  # one writer: a second pipeline into this folder is refused at once
        return _run_stages(s, out, echo)


def _run_stages(s: PipelineSettings, out: Path, echo: Callable[[str], None]) -> dict:
    """run_pipeline's work, inside OUT's lock."""
    record = load_record(out)
    record.update(kind=RECORD_KIND, out=str(out), preset=s.preset)
    n = len(STAGES)
    for i, stage in enumerate(STAGES, 1):
        inputs = _hashes(out, stage.inputs)
        rec = record["stages"].get(stage.name)
        prefix = f"[{i}/{n}] {stage.name} ..."
        # the benchmark's commands name a problem file, so compare them once the problems exist
        argv = stage.commands(s) if all(h is not None for h in inputs.values()) or not stage.inputs else None
        if argv is not None and is_done(stage, rec and {**rec, "out": str(out)}, argv, inputs):
            echo(f"{prefix} skipped (done)")
        else:
            if argv is None:
                missing = [r for r, h in inputs.items() if h is None]
                raise RuntimeError(f"stage {stage.name} needs {out / missing[0]}, which an earlier stage did not write")
            record["stages"].pop(stage.name, None)
            t0 = time.perf_counter()
            _run_commands(argv, out / "logs" / f"{stage.name}.log")
            wall = time.perf_counter() - t0
            outputs = _hashes(out, stage.outputs)
            lost = [r for r, h in outputs.items() if h is None]
            if lost:
                raise RuntimeError(f"stage {stage.name} finished without writing {out / lost[0]}")
            record["stages"][stage.name] = {"argv": argv, "inputs": inputs, "outputs": outputs,
                                            "wall_s": round(wall, 2), "finished": time.strftime("%Y-%m-%dT%H:%M:%S")}
            atomic_write_json(out / RECORD_FILE, record)
            echo(f"{prefix} done in {wall:.1f} s")
        if stage.name == s.stop_after:
            echo(f"stopped after {stage.name} (--stop-after)")
            break
    return record
