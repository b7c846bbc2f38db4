"""Faults of the files the tools read (issue 36, the readers' half), each reproduced and now refused in one line.

Every JSON goes through one bounded, typed reader (pddl_export.bounded_json): a FIFO or /dev/zero is refused
at once, a file over its size cap is not read, deep nesting, huge integers, NaN and 1e999 are refused naming
the file, and each file kind has a schema whose refusal names the field. Recordings are read with pixel caps
(a tiny GIF declaring huge frames is refused before decoding), report.md escapes what it copies from the run's
JSON, a wrong-shaped row of OUT.rows.jsonl is refused before any row runs, a goal's `"version": true` is not
version 1, and a damaged best.pt is named as such. The last tests are a property test over the readers:
random wrong types, missing and extra fields and non-finite numbers give the one-line refusal, never a
traceback.
"""
from __future__ import annotations

import copy
import io
import json
import os
import random
import shutil
import struct
import sys
import threading
from pathlib import Path

import pytest

from conftest import cli

ROOT = Path(__file__).resolve().parents[1]
PRETRAINED = ROOT / "pretrained" / "quick-authors12k"
GOAL = ROOT / "examples" / "goals" / "fig6_composite.json"
PROBLEM = PRETRAINED / "problems" / "tower_of_two.json"


def _one_line(e: BaseException, *words: str) -> str:
    text = str(e)
    assert "\n" not in text, text
    for w in words:
        assert w in text, text
    return text


def _cli_error(capsys, command: str, *words: str) -> str:
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith(f"symlearn {command}: error: ") and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    return err


# ------------------------------------------------------------------------------- the bounded reader itself


def test_reader_refuses_a_fifo_at_once(tmp_path):
    from pddl_export.bounded_json import JsonFileError, read_json_file

    fifo = tmp_path / "hang.json"
    os.mkfifo(fifo)
    with pytest.raises(JsonFileError) as info:
        read_json_file(fifo)  # no writer: a blocking open would wait forever
    _one_line(info.value, str(fifo), "FIFO")


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_reader_refuses_devices_before_reading(device):
    from pddl_export.bounded_json import JsonFileError, read_json_file

    with pytest.raises(JsonFileError) as info:
        read_json_file(device)
    _one_line(info.value, device, "device")


def test_reader_refuses_a_folder_and_a_file_over_its_cap(tmp_path):
    from pddl_export.bounded_json import JsonFileError, read_json_file

    with pytest.raises(JsonFileError, match="folder"):
        read_json_file(tmp_path)
    big = tmp_path / "big.json"
    big.write_text(json.dumps({"x": "a" * 5000}))
    assert read_json_file(big, max_bytes=6000)["x"] == "a" * 5000
    with pytest.raises(JsonFileError) as info:
        read_json_file(big, max_bytes=1000)
    _one_line(info.value, str(big), "more than the 1000 bytes")


@pytest.mark.parametrize("text, words", [
    ("[" * 100_000 + "]" * 100_000, ["nested deeper"]),  # Python's parser itself gives up: RecursionError
    ("[" * 40 + "]" * 40, ["nested deeper than 32"]),
    ('{"n": ' + "9" * 5000 + "}", ["not valid JSON"]),  # beyond Python's 4300-digit limit
    ('{"n": ' + "9" * 4000 + "}", ["field n", "outside 64 bits"]),
    ('{"n": [1, 18446744073709551616]}', ["field n[1]", "outside 64 bits"]),
    ('{"x": NaN}', ["NaN is not a JSON number"]),
    ('{"x": -Infinity}', ["Infinity is not a JSON number"]),
    ('{"x": 1e999}', ["1e999 is not a finite number"]),
    ('{"x": 1', ["not valid JSON (line 1"]),
])
def test_reader_refuses_deep_huge_and_non_finite_values_naming_the_file(tmp_path, text, words):
    from pddl_export.bounded_json import JsonFileError, read_json_file

    path = tmp_path / "f.json"
    path.write_text(text)
    with pytest.raises(JsonFileError) as info:
        read_json_file(path)
    _one_line(info.value, f"{path}: ", *words)


def test_reader_refuses_bytes_that_are_not_utf8(tmp_path):
    from pddl_export.bounded_json import JsonFileError, read_json_file

    path = tmp_path / "f.json"
    path.write_bytes(b'{"x": "\xff"}')
    with pytest.raises(JsonFileError, match="not UTF-8"):
        read_json_file(path)


def test_schema_refusals_name_the_field_and_bool_is_not_int():
    from pddl_export.bounded_json import (Bool, Const, Int, JsonFileError, List, Map, Num, Obj, Opt, Str, Tuple,
                                          check)

    schema = Obj({"version": Const(1), "n": Int(0, 10), "xs": List(Num(), 3), "name": Str(5)},
                 optional={"m": Map(Opt(Bool()), 2), "pair": Tuple((Int(), Str()))}, extra=False)
    good = {"version": 1, "n": 3, "xs": [1, 2.5], "name": "ab", "m": {"a": None, "b": True}, "pair": [1, "x"]}
    check(good, schema, "f.json")
    for bad, words in [({**good, "version": True}, ["field version", "expected 1, got True"]),
                       ({**good, "version": 1.0}, ["field version"]),
                       ({**good, "n": True}, ["field n", "integer in 0..10"]),
                       ({**good, "n": 11}, ["field n"]),
                       ({**good, "xs": [1, 2, 3, 4]}, ["field xs", "4 items"]),
                       ({**good, "xs": [1, "2"]}, ["field xs[1]", "finite number"]),
                       ({**good, "name": "abcdef"}, ["field name", "at most 5"]),
                       ({k: v for k, v in good.items() if k != "n"}, ["field n: missing"]),
                       ({**good, "extra": 1}, ["field extra: unknown"]),
                       ({**good, "m": {"a": 1}}, ["field m.a"]),
                       ({**good, "m": {"a": None, "b": None, "c": None}}, ["field m", "3 entries"]),
                       ({**good, "pair": [1, 2]}, ["field pair[1]"]),
                       ([1, 2], ["field (top)", "expected an object"])]:
        with pytest.raises(JsonFileError) as info:
            check(bad, schema, "f.json")
        _one_line(info.value, "f.json: ", *words)


# ------------------------------------------------------------------------------- 5, 16, 17: goals and problems


def _goal(tmp_path: Path, **change) -> Path:
    d = {**json.loads(GOAL.read_text()), **change}
    path = tmp_path / "g.json"
    path.write_text(json.dumps(d))
    return path


def test_goal_version_true_is_not_version_1(tmp_path):
    from symlearn.problems.goals import load_goal

    assert load_goal(_goal(tmp_path, version=1)).plan  # the file itself is fine
    with pytest.raises(ValueError) as info:
        load_goal(_goal(tmp_path, version=True))
    _one_line(info.value, "g.json", "not a symlearn goal file")


def test_goal_reference_plan_has_a_length_cap(tmp_path):
    from symlearn.problems.goals import MAX_PLAN_STEPS, load_goal

    plan = [[4, 1], [1, 4]] * (MAX_PLAN_STEPS // 2)
    assert len(load_goal(_goal(tmp_path, reference_plan=plan)).plan) == MAX_PLAN_STEPS
    with pytest.raises(ValueError) as info:
        load_goal(_goal(tmp_path, reference_plan=plan + [[4, 1]]))
    _one_line(info.value, "g.json", f"{MAX_PLAN_STEPS + 1} steps")


@pytest.mark.parametrize("text, words", [
    ('{"format": "symlearn-goal", "version": 1, "objects": ' + "[" * 50_000 + "]" * 50_000 + "}", ["nested deeper"]),
    ('{"format": "symlearn-goal", "version": 1, "seed": ' + "7" * 5000 + "}", ["not valid JSON"]),
    ('{"format": "symlearn-goal", "version": 1, "seed": ' + "7" * 400 + "}", ["field seed", "outside 64 bits"]),
])
def test_goal_deep_or_huge_values_are_refused_naming_the_file(tmp_path, text, words):
    from symlearn.problems.goals import load_goal

    path = tmp_path / "g.json"
    path.write_text(text)
    with pytest.raises(ValueError) as info:
        load_goal(path)
    _one_line(info.value, str(path), *words)


def _refusal_within(loader, path: Path, seconds: float = 10.0) -> str:
    """loader(path)'s one-line refusal, failing (not hanging) if it blocks: a reader stuck opening a FIFO is
    released by opening the FIFO for writing."""
    out: list = []
    t = threading.Thread(target=lambda: out.append(_refusal(loader, path)), daemon=True)
    t.start()
    t.join(seconds)
    if t.is_alive():
        os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
        t.join(seconds)
        pytest.fail(f"{getattr(loader, '__name__', loader)} blocked on {path}")
    return out[0]


def _refusal(loader, path) -> str:
    try:
        loader(path)
    except ValueError as e:
        return str(e)
    return "accepted"


def test_goal_and_problem_files_that_are_fifos_do_not_hang(tmp_path):
    """A FIFO named *.json: refused at once."""
    from symlearn.problems.goals import load_goal
    from symlearn.problems.problem import load_problem

    for loader in (load_goal, load_problem):
        fifo = tmp_path / f"{loader.__name__}.json"
        os.mkfifo(fifo)
        text = _refusal_within(loader, fifo)
        assert "FIFO" in text and str(fifo) in text and "\n" not in text, text


def test_plan_problem_dev_zero_is_refused_at_once(tmp_path):
    """`plan --problem /dev/zero` reads nothing (a child with a 2 GB address-space cap, so a reader without
    bound fails fast instead of filling the machine)."""
    import subprocess

    code = ("import resource, sys; resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30)); "
            "from symlearn.cli.main import main; sys.exit(main(sys.argv[1:]))")
    r = subprocess.run([sys.executable, "-c", code, "plan", "--run", str(tmp_path / "run"), "--problem", "/dev/zero"],
                       cwd=ROOT, capture_output=True, text=True, timeout=120)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr[-2000:]
    assert lines[0].startswith("symlearn plan: error: /dev/zero") and "device" in lines[0], lines


@pytest.mark.parametrize("change, words", [
    ({"version": True}, ["problem version True"]),
    ({"actions": [19] * 101, "generator_length": 101}, ["101 actions"]),
    ({"seed": 10 ** 30}, ["field seed", "outside 64 bits"]),
    ({"task": "t" * 20_000}, ["task must be"]),
])
def test_problem_files_have_typed_bounded_fields(tmp_path, change, words):
    from symlearn.problems.problem import load_problem

    path = tmp_path / "p.json"
    path.write_text(json.dumps({**json.loads(PROBLEM.read_text()), **change}))
    with pytest.raises(ValueError) as info:
        load_problem(path)
    _one_line(info.value, str(path), *words)


# ------------------------------------------------------------------------------- 11: rules.json, outcomes.json


def _pddl_copy(tmp_path: Path) -> Path:
    run = tmp_path / "run"
    (run / "pddl").mkdir(parents=True)
    for f in ("rules.json", "outcomes.json"):
        shutil.copy(PRETRAINED / "pddl" / f, run / "pddl" / f)
    return run


def _sub(text: str, field: str) -> str:
    """The file with its max_objects entry replaced (it must be there)."""
    import re

    out, n = re.subn(r'"max_objects": \d+', field, text, count=1)
    assert n == 1
    return out


@pytest.mark.parametrize("fname", ["rules.json", "outcomes.json"])
@pytest.mark.parametrize("mutate, words", [
    (lambda t: _sub(t, '"max_objects": Infinity'), ["Infinity is not a JSON number"]),
    (lambda t: _sub(t, '"max_objects": 1e999'), ["not a finite number"]),
    (lambda t: _sub(t, '"max_objects": 1e300'), ["max_objects"]),
    (lambda t: _sub(t, '"max_objects": ' + "9" * 30), ["max_objects", "outside 64 bits"]),
    (lambda t: t.replace('"bits": 8', '"bits": 300', 1), ["'bits'", "outside 1..28"]),
    (lambda t: json.dumps({**json.loads(t), "vocabulary": ["1" * 300]}), ["is not a string of 8 bits"]),
    (lambda t: json.dumps({**json.loads(t), "vocabulary": ["0b101010"]}), ["is not a string of 8 bits"]),
])
def test_non_finite_numbers_and_over_long_codes_are_refused(tmp_path, fname, mutate, words):
    from pddl_export.outcome_rules import load_outcomes
    from pddl_export.rules_io import load_rules

    run = _pddl_copy(tmp_path)
    path = run / "pddl" / fname
    load = load_rules if fname == "rules.json" else load_outcomes
    load(run)  # the unmutated file loads
    path.write_text(mutate(path.read_text()))
    with pytest.raises(ValueError) as info:
        load(run)
    _one_line(info.value, f"{path}: ", *words)


@pytest.mark.parametrize("mutate, words", [
    (lambda d: {**d, "costs": [{**d["costs"][0], "from": "1" * 300}]}, ["is not a string of 8 bits"]),
    (lambda d: {**d, "costs": [{**d["costs"][0], "action": 10 ** 18}]}, ["not an action id"]),
    (lambda d: {**d, "costs": [{**d["costs"][0], "action": True}]}, ["not an action id"]),
    (lambda d: {**d, "min_ratio": "x"}, ["malformed outcomes file", "'min_ratio'"]),
    (lambda d: {**d, "costs": [{**d["costs"][0], "cost": "1"}]}, ["malformed outcomes file", "'cost'"]),
])
def test_outcome_costs_are_checked(tmp_path, mutate, words):
    from pddl_export.outcome_rules import load_outcomes

    run = _pddl_copy(tmp_path)
    path = run / "pddl" / "outcomes.json"
    path.write_text(json.dumps(mutate(json.loads(path.read_text()))))
    with pytest.raises(ValueError) as info:
        load_outcomes(run)
    _one_line(info.value, f"{path}: ", *words)


# ------------------------------------------------------------------------------- 8: benchmark row logs

ROW = {"problem": "p0", "planner": "astar", "found": True, "status": "solved", "plan_length": 1,
       "planning_time_s": 0.1, "expansions": 2, "success": True, "symbolic_match": True, "max_distance_m": 0.01,
       "closed_loop": False, "replans": 0, "failure_stage": None, "generator_length": 1}


@pytest.mark.parametrize("bad, words", [
    ({"key": ["p1.json", "astar", False], "row": {**ROW, "found": [1, 2]}}, ["line 3", "field row.found"]),
    ({"key": ["p1.json", "astar", False], "row": {**ROW, "bogus": 1}}, ["line 3", "field row.bogus: unknown"]),
    ({"key": ["p1.json", "astar"], "row": ROW}, ["line 3", "field key"]),
    ({"key": ["p1.json", "astar", False], "row": {**ROW, "failure_stage": "nowhere"}}, ["line 3", "failure stage"]),
    ([1, 2], ["line 3", "expected an object"]),
])
def test_wrong_shaped_row_is_refused_naming_file_and_line(tmp_path, bad, words):
    from symlearn.planning.benchmark_rows import RowLog

    path = tmp_path / "b.json.rows.jsonl"
    settings = {"planners": ["astar"], "timeout_s": 10.0}
    log = RowLog(path, settings)
    log.open()
    log.append(("p0.json", "astar", False), ROW)
    log.close()
    with open(path, "a") as f:
        f.write(json.dumps(bad) + "\n")
        f.write(json.dumps({"key": ["p2.json", "astar", False], "row": ROW}) + "\n")
    before = path.read_bytes()
    with pytest.raises(ValueError) as info:
        RowLog(path, settings).open()
    _one_line(info.value, f"{path}: line 3", *words)
    assert path.read_bytes() == before  # nothing cut or appended


def test_benchmark_refuses_a_wrong_shaped_row_before_running_any(tiny_run, tmp_path, capsys):
    from symlearn.planning.benchmark import _settings
    from symlearn.planning.benchmark_rows import RowLog, load_sets, problem_sets
    from symlearn.planning.execution import ExecutionConfig

    problems = tmp_path / "problems"
    problems.mkdir()
    shutil.copy(PROBLEM, problems / "a.json")
    shutil.copy(PRETRAINED / "problems" / "three_objects_two_actions.json", problems / "b.json")
    out = tmp_path / "bench.json"
    sets = problem_sets(problems)
    settings = _settings(tiny_run.path, sets, load_sets(sets), ["astar"],
                         ExecutionConfig(closed_loop=True, timeout_s=10.0))
    log = RowLog(out.with_name(out.name + ".rows.jsonl"), settings)
    log.open()
    log.append(("a.json", "astar", False), {**ROW, "replans": "three"})
    log.close()
    before = log.path.read_bytes()
    rc, _ = cli("benchmark", "--run", tiny_run.path, "--problems", problems, "--planners", "astar",
                "--timeout", "10", "--out", out)
    assert rc == 2
    _cli_error(capsys, "benchmark", f"{log.path}: line 2", "field row.replans")
    assert log.path.read_bytes() == before and not out.exists()  # no row ran


# ------------------------------------------------------------------------------- 4, 12, 14: report inputs


def _gif(path: Path, n_frames: int, declared: tuple[int, int] | None = None) -> Path:
    """An animated GIF of n distinct 2x2 frames; `declared` overwrites its logical screen size (bytes 6-9)."""
    from PIL import Image

    frames = [Image.new("RGB", (2, 2), (20 * i, 255 - 20 * i, 0)) for i in range(n_frames)]
    buf = io.BytesIO()
    frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:], duration=100, loop=0)
    data = bytearray(buf.getvalue())
    if declared is not None:
        data[6:10] = struct.pack("<HH", *declared)
    path.write_bytes(bytes(data))
    return path


def _report_notes(run: Path) -> dict[str, str]:
    """Section title -> the 'not run' note of report.md (and the report was written)."""
    md = (run / "report.md").read_text()
    notes, title = {}, None
    for line in md.splitlines():
        if line.startswith("## "):
            title = line[3:]
        elif line.startswith("*not run: ") and title:
            notes[title] = line[len("*not run: "):-1]
    return notes


@pytest.mark.parametrize("declared, words", [
    ((5000, 5000), ["5000 x 5000 pixels"]),  # 25 M pixels a frame: refused before any is decoded
    ((65535, 65535), ["too many pixels"]),  # Pillow's decompression-bomb error, as the one-line refusal
])
def test_report_refuses_a_gif_declaring_huge_frames(tmp_path, capsys, declared, words):
    run = tmp_path / "run"
    run.mkdir()
    gif = _gif(run / "plan.gif", 2, declared)
    assert gif.stat().st_size < 200
    rc, out = cli("report", "--run", run)
    assert rc == 0, out
    note = _report_notes(run)["An executed plan"]
    assert note.startswith(f"{gif} cannot be read: ") and all(w in note for w in words), note
    assert not (run / "report_files" / "plan_filmstrip.png").exists()


def test_recording_frames_are_capped_in_total(tmp_path, monkeypatch):
    from symlearn.planning import recording

    gif = _gif(tmp_path / "r.gif", 5)
    assert len(recording.read_gif_frames(gif)) == 5
    monkeypatch.setattr(recording, "MAX_TOTAL_PIXELS", 3 * 4)  # three 2x2 frames
    with pytest.raises(recording.RecordingError) as info:
        recording.read_gif_frames(gif)
    _one_line(info.value, str(gif), "more than 3 frames of 2 x 2")
    (tmp_path / "x.gif").write_bytes(b"GIF89a" + b"\x00" * 30)
    with pytest.raises(recording.RecordingError, match="not a readable GIF"):
        recording.read_gif_frames(tmp_path / "x.gif")


@pytest.mark.parametrize("fname, doc, words", [
    ("benchmark.json", {"summary": [1, 2]}, ["field summary"]),
    ("benchmark.json", {"summary": {"astar": {"success_rate": "high"}}}, ["field summary.astar.success_rate"]),
    ("eval.json", {"effect_mae_mm": {"x": "8.1", "y": 1, "z": 1}}, ["field effect_mae_mm.x"]),
    ("eval.json", {"ablations": {"a": [1]}}, ["field ablations.a"]),
    ("symbols.json", {"symbols": "many", "n_symbols_for_95pct": 3}, ["field symbols"]),
    ("symbols.json", {"n_symbols_for_95pct": "3"}, ["field n_symbols_for_95pct"]),
    ("table1.json", {"cases": [{"objects": [{"predicted_mm": [1, 2, 3]}]}]}, ["field cases[0].objects[0].truth_mm"]),
    ("config.json", {"data": 7}, ["field data"]),
    ("metrics.json", {"history": [{"epoch": 1, "val_mae_mm": {"x": 1}}]}, ["field history[0].val_mae_mm.y"]),
    ("transition_metrics.json", {"history": {"epoch": 1}}, ["field history"]),
])
def test_report_survives_wrong_shaped_run_files(tmp_path, fname, doc, words):
    run = tmp_path / "run"
    run.mkdir()
    (run / fname).write_text(json.dumps(doc))
    rc, out = cli("report", "--run", run)
    assert rc == 0, out
    md = (run / "report.md").read_text().replace("\\", "")  # Markdown escapes of brackets
    assert f"{run / fname} cannot be read: " in md and all(w in md for w in words), md


@pytest.mark.parametrize("special", ["/dev/zero", "fifo"])
def test_report_refuses_a_run_file_that_is_not_regular(tmp_path, special):
    run = tmp_path / "run"
    run.mkdir()
    if special == "fifo":
        os.mkfifo(run / "eval.json")
    else:
        os.symlink(special, run / "eval.json")
    rc, out = cli("report", "--run", run)
    assert rc == 0, out
    assert "not a regular run file" in _report_notes(run)["Effect prediction error (test split)"]


def test_report_md_escapes_names_from_the_run_json(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    evil = "<script>alert(1)</script>"
    (run / "eval.json").write_text(json.dumps({"effect_mae_mm": {"x": 1.0, "y": 2.0, "z": 3.0},
                                               "ablations": {evil: {"effect_mae_mm": {"x": 1.0}}}}))
    (run / "benchmark.json").write_text(json.dumps({"summary": {f"<img src=x onerror=alert(2)>": {"n_problems": 1}},
                                                    "problems": "[a](javascript:alert(3))"}))
    rc, out = cli("report", "--run", run)
    assert rc == 0, out
    md = (run / "report.md").read_text()
    html = (run / "report.html").read_text()
    for raw in ("<script>", "<img"):
        assert raw not in md and raw not in html, raw
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in md and "&lt;img src=x onerror=alert(2)&gt;" in md
    assert "\\[a\\](javascript:alert(3))" in md and "[a](" not in md  # a link's brackets are escaped


# ------------------------------------------------------------------------------- 12: pipeline records


@pytest.mark.parametrize("stages, words", [
    ({"collect": ["argv", 1]}, ["field stages.collect", "expected an object"]),
    ({"collect": {"config": "n=5"}}, ["field stages.collect.config"]),
    ({"collect": {"inputs": {"a": 5}}}, ["field stages.collect.inputs.a"]),
])
def test_pipeline_record_of_the_wrong_shape_is_refused(tmp_path, stages, words):
    from symlearn.pipeline import RECORD_FILE, RECORD_KIND, load_record

    (tmp_path / RECORD_FILE).write_text(json.dumps({"kind": RECORD_KIND, "stages": stages}))
    with pytest.raises(ValueError) as info:
        load_record(tmp_path)
    _one_line(info.value, str(tmp_path / RECORD_FILE), *words)


# ------------------------------------------------------------------------------- 17: a damaged best.pt


@pytest.mark.parametrize("damage", ["truncate", "garbage"])
def test_damaged_best_pt_is_named_not_transition_pt(tiny_run_copy, damage):
    from symlearn.learning.checkpoint import CheckpointError
    from symlearn.symbolic.learned_transition import planning_models

    best = tiny_run_copy / "best.pt"
    data = best.read_bytes()
    best.write_bytes(data[: len(data) // 2] if damage == "truncate" else b"\x80\x04garbage" + data[100:])
    with pytest.raises(CheckpointError) as info:
        planning_models(tiny_run_copy)
    text = _one_line(info.value, str(best))
    assert "transition.pt" not in text


# ------------------------------------------------------------------------------- property test over the readers


def _wrong_values(rng: random.Random) -> list:
    """Values of every JSON type, some huge or deep, for random substitution."""
    return [None, True, False, 0, -1, 7, 2 ** 62, 10 ** 30, 0.5, -1e308, "", "x", "0" * 40, "<b>", [], [1, "a"],
            {}, {"a": 1}, [[[[[[1]]]]]], {"a": {"b": {"c": [None]}}}, rng.random(), rng.randrange(-1000, 1000),
            "".join(rng.choice("01ab<>[]|`") for _ in range(rng.randrange(1, 30)))]


def _paths(doc, prefix=()):
    """Every (path to a value) in a JSON document, containers included."""
    yield prefix
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc[:4]):  # the first few items of long lists
            yield from _paths(v, prefix + (i,))


def _mutate(doc, rng: random.Random):
    """One random mutation: a value of a wrong type, a missing field, an extra field, or a NaN / Infinity."""
    doc = copy.deepcopy(doc)
    paths = list(_paths(doc))
    path = rng.choice(paths[1:] or paths)
    parent = doc
    for k in path[:-1]:
        parent = parent[k]
    key = path[-1] if path else None
    kind = rng.randrange(4)
    if key is None:
        return rng.choice(_wrong_values(rng)), None
    if kind == 0 or not isinstance(parent, dict):
        parent[key] = rng.choice(_wrong_values(rng))
        return doc, None
    if kind == 1:
        del parent[key]
        return doc, None
    if kind == 2:
        parent[f"extra_{rng.randrange(100)}"] = rng.choice(_wrong_values(rng))
        return doc, None
    parent[key] = "__NONFINITE__"
    return doc, rng.choice(["NaN", "Infinity", "-Infinity", "1e999"])


def _write(path: Path, doc, literal: str | None) -> None:
    text = json.dumps(doc)
    if literal is not None:
        text = text.replace('"__NONFINITE__"', literal)
    path.write_text(text)


def _load_rules_kind(fname):
    def load(path: Path):
        from pddl_export.outcome_rules import load_outcomes
        from pddl_export.rules_io import load_rules

        return (load_rules if fname == "rules.json" else load_outcomes)(path.parent.parent)
    return load


def _small_rules(fname: str) -> dict:
    d = json.loads((PRETRAINED / "pddl" / fname).read_text())
    d["rules"] = d["rules"][:20]
    if "costs" in d:
        d["costs"] = d["costs"][:20]
    return d


def _open_row_log(path: Path) -> None:
    """The document at `path` as the one row of a benchmark log there (after the settings line), opened."""
    from symlearn.planning.benchmark_rows import ROWS_FORMAT, RowLog

    settings = {"planners": ["astar"]}
    entry = path.read_text()
    path.write_text(json.dumps({"format": ROWS_FORMAT, "version": 1, "settings": settings}) + "\n" + entry + "\n")
    log = RowLog(path, settings)
    try:
        log.open()
    finally:
        log.close()


READERS = {  # kind -> (a valid document, where it is written under tmp, the loader given that path)
    "goal": (lambda: json.loads(GOAL.read_text()), "g.json",
             lambda p: __import__("symlearn.problems.goals", fromlist=["x"]).load_goal(p)),
    "problem": (lambda: json.loads(PROBLEM.read_text()), "p.json",
                lambda p: __import__("symlearn.problems.problem", fromlist=["x"]).load_problem(p)),
    "rules": (lambda: _small_rules("rules.json"), "run/pddl/rules.json", _load_rules_kind("rules.json")),
    "outcomes": (lambda: _small_rules("outcomes.json"), "run/pddl/outcomes.json", _load_rules_kind("outcomes.json")),
    "pipeline": (lambda: {"kind": "symlearn-pipeline", "out": "x", "preset": "quick", "stages": {
        "collect": {"config": {"n": 5, "exploration": {"k_values": [1, 2]}}, "inputs": {}, "outputs": {"data/manifest.json": "ab" * 8},
                    "wall_s": 1.5, "finished": "2026-01-01T00:00:00"}}}, "pipeline.json",
                 lambda p: __import__("symlearn.pipeline", fromlist=["x"]).load_record(p.parent)),
    "benchmark-row": (lambda: {"key": ["p0.json", "astar", False],
                               "row": {**ROW, "message": "m", "timings": {"planner_time_s": 0.1}, "task": "goal",
                                       "attribution": {"steps": [1, 2]}, "goal_off_locations": 0, "n_objects": 2}},
                      "b.json.rows.jsonl", _open_row_log),
}


@pytest.mark.parametrize("kind", sorted(READERS))
def test_property_readers_refuse_in_one_line_never_a_traceback(tmp_path, kind):
    make, rel, load = READERS[kind]
    rng = random.Random(f"issue-36-{kind}")
    path = tmp_path / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    valid = make()
    _write(path, valid, None)
    load(path)  # the valid document loads
    refused = 0
    for _ in range(150):
        doc, literal = _mutate(valid, rng)
        _write(path, doc, literal)
        try:
            load(path)
        except ValueError as e:
            refused += 1
            text = str(e)
            assert "\n" not in text and str(path) in text, (kind, text)
        # any other exception type fails the test with its traceback
    assert refused >= 50, refused  # the mutations do reach the checks


def test_property_report_never_raises_on_wrong_shaped_run_files(tmp_path, monkeypatch):
    """Every run file the report reads, mutated at random (all at once): the report is written and nothing
    raises. (Plots are not drawn: what is under test is reading, and matplotlib takes a second a plot.)"""
    from symlearn.report import build

    monkeypatch.setattr(build, "plot_png", lambda plot: b"\x89PNG\r\n\x1a\n")
    run = tmp_path / "run"
    rng = random.Random("issue-36-report")
    names = ("eval.json", "table1.json", "symbols.json", "metrics.json", "transition_metrics.json", "config.json")
    valid = {n: json.loads((PRETRAINED / n).read_text()) for n in names}
    valid["config.json"].pop("data")  # no data set to read
    valid["benchmark.json"] = {"summary": {"astar": {"n_problems": 3, "success_rate": 0.5, "found_rate": 1.0,
                                                     "median_time_s": 0.1, "success_rate_closed_loop": None,
                                                     "mean_plan_length": 2.0}},
                               "n_problems": 3, "problems": "p", "timeout_s": 10.0,
                               "goal_placement": {"astar": {"on_locations": {"n_problems": 2, "success_rate": 0.5,
                                                                             "success_rate_closed_loop": None}}}}
    for _ in range(20):
        shutil.rmtree(run, ignore_errors=True)
        run.mkdir(parents=True)
        for n, d in valid.items():
            doc, literal = _mutate(d, rng) if rng.random() < 0.8 else (d, None)
            _write(run / n, doc, literal)
        rc, out = cli("report", "--run", run)
        assert rc == 0, out
        md = (run / "report.md").read_text()
        assert md.startswith("# symlearn report")


@pytest.mark.parametrize("which", ["best.pt", "transition.pt"])
def test_checkpoint_that_is_a_fifo_or_device_is_refused_at_once(tmp_path, which):
    from symlearn.learning.checkpoint import load_checkpoint
    from symlearn.symbolic.transition_checkpoint import load_transition

    load = load_checkpoint if which == "best.pt" else load_transition
    os.mkfifo(tmp_path / which)
    os.symlink("/dev/zero", tmp_path / f"zero_{which}")
    for path in (tmp_path / which, tmp_path / f"zero_{which}"):
        text = _refusal_within(load, path)
        assert str(path) in text and "not a regular file" in text and "\n" not in text, text


@pytest.mark.parametrize("text, words", [
    ('{"kind": "symlearn-lifted-rules", "version": true, "rules": []}', ["not a lifted rules file"]),
    ('{"kind": "symlearn-lifted-rules", "version": 1, "code_bits": Infinity}', ["Infinity is not a JSON number"]),
    ('{"kind": "symlearn-lifted-rules", "version": 1, "code_bits": 1e400}', ["not a finite number"]),
    ('{"kind": "symlearn-lifted-rules", "version": 1, "code_bits": ' + "[" * 50 + "]" * 50 + "}",
     ["nested deeper"]),
    (None, ["FIFO"]),
])
def test_lifted_rules_file_goes_through_the_bounded_reader(tmp_path, text, words):
    from pddl_export.lifted_rules_io import load_lifted

    path = tmp_path / "lifted.json"
    if text is None:
        os.mkfifo(path)
    else:
        path.write_text(text)
    out = _refusal_within(load_lifted, path)
    assert out.startswith(f"{path}") and "\n" not in out and all(w in out for w in words), out



# ----------------------------------------------------------- issue 59: data shards, overlapping objects, --length


def _command_refusal(*args):
    """A loader for _refusal_within: `symlearn ARGS` in this process; its error line (the last on stderr, after
    any banner) as a ValueError when it exits 2 (a refusal), None (accepted) otherwise."""
    import contextlib

    def run(_path):
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            rc, _ = cli(*args)
        lines = err.getvalue().strip().splitlines()
        if rc == 2:
            ok = lines and lines[-1].startswith(f"symlearn {args[0]}: error: ")
            raise ValueError(lines[-1] if ok else f"no error line: {err.getvalue()}")
        return None

    run.__name__ = f"symlearn {args[0]}"
    return run


@pytest.mark.parametrize("command", ["collect", "train", "load_split"])
def test_fifo_in_place_of_a_data_shard_is_refused_at_once(tiny_data, tmp_path, command):
    """A FIFO named like a shard: resuming `collect`, `train` and the shard reader (load_split, what evaluate and
    symbols read with too) refuse it in one line naming it, instead of blocking on it forever."""
    from conftest import TINY_DATA_ARGS, TINY_TRAIN_ARGS
    from symlearn.data.dataset import load_split

    data = tmp_path / "data"
    shutil.copytree(tiny_data.path, data)
    shard = data / "shard_00000.npz"  # a train shard
    shard.unlink()
    os.mkfifo(shard)
    loader = {"collect": _command_refusal("collect", "--out", data, *TINY_DATA_ARGS, "--quiet"),
              "train": _command_refusal("train", "--data", data, "--out", tmp_path / "run", *TINY_TRAIN_ARGS,
                                        "--quiet"),
              "load_split": lambda _: load_split(data, "train")}[command]
    text = _refusal_within(loader, shard, seconds=60)
    assert str(shard) in text and "FIFO" in text and "\n" not in text, text
    assert not (tmp_path / "run" / "best.pt").exists()


def _overlapping(tmp_path: Path, scene: str, i: int, j: int) -> Path:
    doc = json.loads(PROBLEM.read_text())
    objects = doc[scene]["objects"]
    objects[j]["position"] = list(objects[i]["position"])  # two objects at one position
    path = tmp_path / "p.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("scene", ["initial", "goal"])
def test_problem_with_two_objects_at_one_position_is_refused(tmp_path, scene):
    """Two objects at one position (the lifted start then says two blocks stand at one location and level):
    refused when the problem file is read, naming the file and both objects; real problems still load."""
    from symlearn.problems.problem import load_problem, load_problems

    path = _overlapping(tmp_path, scene, 0, 1)
    with pytest.raises(ValueError) as info:
        load_problem(path)
    _one_line(info.value, str(path), f"{scene} scene", "objects 0 (cube) and 1 (cube) overlap")
    # nudged apart by less than a cube's width still overlaps; the shipped problems (centres >= 7.5 cm) all load
    doc = json.loads(path.read_text())
    doc[scene]["objects"][1]["position"][0] += 0.03
    path.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match="overlap"):
        load_problem(path)
    for folder in (PRETRAINED / "problems", ROOT / "pretrained" / "recommended" / "problems"):
        assert len(load_problems(folder)) >= 3


def test_problems_length_beyond_what_a_problem_may_list_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    """`problems --length 150-150` wrote problems that plan and benchmark then refuse (more than 100 actions):
    now refused at the flag, before any problem is drawn; ProblemConfig (a settings file's [problems]) too."""
    from symlearn.problems import problem_generation
    from symlearn.problems.problem import MAX_ACTIONS
    from symlearn.problems.problem_generation import ProblemConfig

    drawn = []
    monkeypatch.setattr(problem_generation, "_generate", lambda *a, **k: drawn.append(a) or [])
    out = tmp_path / "problems"
    rc, _ = cli("problems", "--kind", "walks", "--out", out, "--n", "1", "--length", "150-150")
    assert rc == 2 and not drawn and not out.exists()
    _cli_error(capsys, "problems", "150-150", f"1-{MAX_ACTIONS}")
    with pytest.raises(ValueError) as info:
        ProblemConfig(length=(MAX_ACTIONS + 1, MAX_ACTIONS + 1))
    _one_line(info.value, f"1-{MAX_ACTIONS}")
    assert ProblemConfig(length=(MAX_ACTIONS, MAX_ACTIONS)).length == (MAX_ACTIONS, MAX_ACTIONS)
