"""Every stage in order, resumable: collect (and collect-extra), train, evaluate, table1, symbols,
train-transition, export-pddl, problems, benchmark, report, into OUT/data (OUT/data_extra), OUT/run and
OUT/problems.

The presets (PRESETS; each names its stages' presets, defined beside their config classes): `recommended`, the
default, is the recipe that plans best (its run is shipped as
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

This module runs the stages and keeps their records; the presets and settings are symlearn.pipeline_presets, the
stage configs and their builders symlearn.pipeline_configs, the stages' library calls and the paths they read and
write symlearn.pipeline_stages. The pipeline calls the library, never the command line: `symlearn pipeline`
(symlearn.cli.pipeline) is a thin front end to run_pipeline, and tests/test_layout.py keeps imports going that one
way.

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
from pathlib import Path
from typing import Any, Callable

from pddl_export.bounded_json import AnyJson, JsonFileError, Map, Num, Obj, Opt, Str, check, read_json_file
from symlearn.folder_lock import folder_lock
from symlearn.pipeline_presets import PipelineSettings
from symlearn.pipeline_stages import Stage, pipeline_stages
from symlearn.provenance import atomic_write_json, sha256_bytes, sha256_file

RECORD_FILE = "pipeline.json"
RECORD_KIND = "symlearn-pipeline"


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
