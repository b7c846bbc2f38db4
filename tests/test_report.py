"""What a newcomer sees: the run report (HTML and Markdown), recorded plans (GIF, filmstrip), the pipeline.

The report is built for the session's tiny run after evaluate, table1, symbols, a benchmark and a recorded
plan have written into a copy of it; the HTML is parsed and every number checked against the JSON file it
comes from. Recorded GIFs are read back with Pillow. The pipeline runs on 48 samples, is interrupted
with the hidden --stop-after flag and resumed: finished stages are skipped and their files left untouched.
"""
from __future__ import annotations

import json
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from conftest import cli

SECTIONS = ("scorecard", "data", "effect", "table1", "symbols", "curves", "benchmark", "plan")


class ReportParser(HTMLParser):
    """Sections (id -> status), tables (data-table -> rows of cell texts), figures and images of a report page."""

    def __init__(self) -> None:
        super().__init__()
        self.sections: dict[str, str] = {}
        self.tables: dict[str, list[list[str]]] = {}
        self.figures: list[str] = []
        self.images: list[str] = []
        self.notes: list[str] = []
        self._table = self._row = self._cell = None
        self._in_note = False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "section":
            self.sections[a["id"]] = a["data-status"]
        elif tag == "table":
            self._table = a.get("data-table")
            self.tables[self._table] = []
        elif tag == "tr" and self._table is not None:
            self._row = []
        elif tag in ("td", "th") and self._row is not None:
            self._cell = ""
        elif tag == "figure":
            self.figures.append(a["data-figure"])
        elif tag == "img":
            self.images.append(a["src"])
        elif tag == "p" and a.get("class") == "not-run":
            self._in_note = True
            self.notes.append("")

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._row.append(self._cell)
            self._cell = None
        elif tag == "tr" and self._row is not None:
            self.tables[self._table].append(self._row)
            self._row = None
        elif tag == "table":
            self._table = None
        elif tag == "p":
            self._in_note = False

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data
        if self._in_note:
            self.notes[-1] += data


def parse(path: Path) -> ReportParser:
    p = ReportParser()
    p.feed(path.read_text())
    return p


def _rows(p: ReportParser, key: str) -> dict[str, list[str]]:
    """A table's body rows keyed by their first cell."""
    return {r[0]: r[1:] for r in p.tables[key][1:]}


@pytest.fixture(scope="module")
def full_run(tiny_run, tmp_path_factory) -> Path:
    """A copy of the tiny run after evaluate, table1, symbols, a 2-problem benchmark (failures recorded) and a plan."""
    run = tmp_path_factory.mktemp("report") / "run"
    shutil.copytree(tiny_run.path, run)
    probs = run.parent / "problems"
    for args in (("evaluate", "--run", run, "--data", tiny_run.data), ("table1", "--run", run),
                 ("symbols", "--run", run, "--data", tiny_run.data, "--min-count", 5),
                 ("problems", "--kind", "walks", "--out", probs, "--n", 2, "--objects", "1-2", "--length", "1-2",
                  "--seed", 3),
                 ("plan", "--run", run, "--problem", probs / "problem_0000.json", "--record", run / "plan.gif",
                  "--record-size", "160x120")):
        rc, out = cli(*args)
        assert rc == 0, (args[0], out)
    # open loop, each failed plan recorded as a GIF (the pipeline's benchmark stage records them so)
    from symlearn.planning.benchmark import benchmark

    benchmark(run, probs, ["astar"], run / "benchmark.json", closed_loop=False, record_dir=run / "recordings",
              show_progress=False)
    return run


@pytest.fixture(scope="module")
def report(full_run) -> tuple[Path, ReportParser, str]:
    rc, out = cli("report", "--run", full_run)
    assert rc == 0, out
    return full_run, parse(full_run / "report.html"), out


def test_report_has_every_section_and_is_self_contained(report):
    run, p, out = report
    assert list(p.sections) == list(SECTIONS)
    assert all(status == "ok" for status in p.sections.values()), p.sections
    # one file: every image inlined as a base64 PNG, nothing fetched from elsewhere
    assert p.images and all(src.startswith("data:image/png;base64,") for src in p.images)
    assert {"effect_loss", "transition_loss", "symbols", "symbol_examples", "plan_filmstrip",
            "table1_attention"} <= set(p.figures)
    md = (run / "report.md").read_text()
    for name in re.findall(r"\]\((report_files/[^)]+)\)", md):
        assert (run / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    assert "wrote" in out and "met" in out


def test_report_effect_numbers_equal_eval_json(report):
    run, p, _ = report
    ev = json.loads((run / "eval.json").read_text())
    rows = _rows(p, "effect")
    ours = [float(v) for v in rows["attentive (ours)"]]
    assert ours == pytest.approx([ev["effect_mae_mm"][a] for a in "xyz"], abs=5e-4)
    assert [float(v) for v in rows["paper"]] == [8.6, 15.0, 6.0]
    marks = _rows(p, "effect-marks")
    for a, paper in zip("xyz", (8.6, 15.0, 6.0)):
        ours_cell, paper_cell, _, verdict = marks[f"effect MAE {a} (mm)"]
        assert float(ours_cell) == pytest.approx(ev["effect_mae_mm"][a], abs=5e-4) and float(paper_cell) == paper
        assert verdict == ("met" if ev["effect_mae_mm"][a] < paper else "not met")


def test_report_table1_rows_equal_table1_json(report):
    run, p, _ = report
    t1 = json.loads((run / "table1.json").read_text())
    vec = lambda v: "(" + ", ".join(f"{x:.0f}" for x in v) + ")"  # noqa: E731
    rows = _rows(p, "table1")
    for key, label in (("predicted_mm", "predicted"), ("truth_mm", "truth")):
        for i, case in enumerate(t1["cases"]):
            cells = rows[f"case {i + 1} {label}"]
            for col, j in enumerate((1, 0, 2)):
                assert cells[2 * col] == vec(case["objects"][j][key])
                assert cells[2 * col + 1] == vec(t1["paper"][key][i][j])
    marks = _rows(p, "table1-marks")
    c = t1["criteria"]
    assert marks["Table I: every object's motion right"][0] == c["objects_motion_right"]
    assert marks["Table I: every object's motion right"][3] == ("met" if c["motion_right"] else "not met")
    assert marks["Table I: riders' y within 50 mm of the truth"][3] == ("met" if c["riders_within_50mm"] else "not met")


def test_report_symbols_benchmark_and_data_equal_their_sources(report, tiny_run):
    from symlearn.data.dataset import load_split, summarize
    from symlearn.data.statistics import object_shares

    run, p, _ = report
    sy = json.loads((run / "symbols.json").read_text())
    stats = _rows(p, "symbols")
    assert int(stats["n_distinct"][0]) == sy["n_distinct"]
    assert int(stats["n_symbols_for_95pct"][0]) == sy["n_symbols_for_95pct"]
    mark = _rows(p, "symbols-marks")["symbols covering 95% of objects"]
    assert (int(mark[0]), int(mark[1]), mark[3]) == (sy["n_symbols_for_95pct"], 35,
                                                     "met" if sy["n_symbols_for_95pct"] <= 35 else "not met")
    bench = json.loads((run / "benchmark.json").read_text())
    brow = _rows(p, "benchmark")["astar"]
    s = bench["summary"]["astar"]
    assert (int(brow[0]), float(brow[1]), float(brow[2])) == (s["n_problems"], s["success_rate"], s["found_rate"])
    assert float(brow[3]) == pytest.approx(s["median_time_s"], abs=5e-4)
    placed = [r for r in p.tables["goal_placement"][1:]]  # (planner, goals, problems, success, closed-loop success)
    parts = bench["goal_placement"]["astar"]
    assert sorted(r[1] for r in placed) == sorted(k.replace("_", " ") for k in parts)
    assert sum(int(r[2]) for r in placed) == s["n_problems"]
    for r in placed:
        assert float(r[3]) == pytest.approx(parts[r[1].replace(" ", "_")]["success_rate"], abs=5e-4)
    summary, shares = summarize(tiny_run.data), object_shares(load_split(tiny_run.data, "all"))
    data = _rows(p, "data")
    assert data["path"][0] == str(tiny_run.data)  # found through RUN/config.json
    assert [int(data[f"{k} samples"][0]) for k in ("train", "val", "test")] == [40, 4, 4]
    assert int(data["objects"][0]) == summary["objects"]
    assert int(_rows(p, "shares")["sticks"][0]) == shares["sticks"]
    # the scorecard repeats every mark of the sections
    card = _rows(p, "scorecard")
    assert len(card) == 6 and card["effect MAE x (mm)"] == _rows(p, "effect-marks")["effect MAE x (mm)"]


def test_report_with_missing_inputs_says_not_run(tiny_run_copy, tmp_path):
    (tiny_run_copy / "transition_metrics.json").unlink()
    (tiny_run_copy / "table1.json").write_text("{not json")  # unreadable: named, not a crash
    rc, out = cli("report", "--run", tiny_run_copy, "--data", tmp_path / "no_data")
    assert rc == 0, out
    p = parse(tiny_run_copy / "report.html")
    assert p.sections["effect"] == p.sections["symbols"] == p.sections["benchmark"] == "not run"
    assert p.sections["data"] == p.sections["table1"] == p.sections["plan"] == "not run"
    assert p.sections["curves"] == "ok"  # the effect model's history is there
    notes = " ".join(p.notes)
    assert "symlearn evaluate" in notes and f"{tiny_run_copy / 'table1.json'} cannot be read" in notes
    assert str(tmp_path / "no_data") in notes
    assert "effect_loss" in p.figures and "transition_loss" not in p.figures
    verdicts = [r[-1] for r in p.tables["scorecard"][1:]]
    assert verdicts == ["invalid", "invalid"]  # nothing measured; the refused table1.json's two criteria: invalid
    assert "not run" in (tiny_run_copy / "report.md").read_text()


def test_report_refuses_a_missing_run(tmp_path, capsys):
    rc, _ = cli("report", "--run", tmp_path / "nope")
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and str(tmp_path / "nope") in err[0]
    assert not (tmp_path / "nope").exists()


# ------------------------------------------------------------------------------------ recorded plans


@pytest.mark.parametrize("actions,size", [((19,), (160, 120)), ((19, 24, 3), (96, 64))])
def test_recorded_gif_has_one_frame_per_action_plus_start(sim, tiny_run, actions, size, tmp_path):
    from PIL import Image

    from search.result import PlanResult, PlanStatus
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.planning.execution import execute_plan
    from symlearn.problems.problem import Problem
    from symlearn.planning.recording import PlanRecorder, location_pixels
    from symlearn.world import ObjectState, ObjectType, Scene

    enc, _ = load_effect_model(tiny_run.path)
    scene = Scene((ObjectState(ObjectType.CUBE, (0.5, -0.3, 0.45)), ObjectState(ObjectType.CUBE, (0.8, 0.18, 0.45))))
    problem = Problem("manual", 0, ((ObjectType.CUBE, 3), (ObjectType.CUBE, 2)), scene, (), scene)
    plan = PlanResult("manual", PlanStatus.SOLVED, tuple(actions), (), None, 0.0)
    rec = PlanRecorder(*size)
    ex = execute_plan(sim, problem, plan, enc, np.zeros(2, int), recorder=rec)
    assert ex.executed == tuple(actions)
    gif = rec.save_gif(tmp_path / "plan.gif")
    with Image.open(gif) as im:
        assert (im.n_frames, im.size) == (len(actions) + 1, size)
        im.seek(1)
        frame = np.asarray(im.convert("RGB")).astype(int)
    # the first action's arrow is drawn in red between its pick and release pixels
    view, proj = sim.rgb_camera(*size)
    px = location_pixels(view, proj, *size)
    mid = np.rint((px[actions[0] // 6] + px[actions[0] % 6]) / 2).astype(int)
    r, g, b = frame[mid[1], mid[0]]
    assert r > 150 and g < 100 and b < 100, (r, g, b)
    strip = rec.save_filmstrip(tmp_path / "plan.png")
    with Image.open(strip) as im:
        assert im.size == (len(actions) * (size[0] + 4) + size[0], size[1])


def test_plan_and_benchmark_recordings(report):
    from PIL import Image

    run, _, _ = report
    bench = json.loads((run / "benchmark.json").read_text())
    failed = [r for r in bench["rows"] if not r["success"]]
    gifs = sorted(p.name for p in (run / "recordings").glob("*.gif"))
    assert gifs == sorted(f"{r['problem']}_{r['planner']}.gif" for r in failed)
    with Image.open(run / "plan.gif") as im:
        assert im.size == (160, 120)
        plan_row = [r for r in bench["rows"] if r["problem"] == "problem_0000"][0]
        assert im.n_frames == (plan_row["plan_length"] or 0) + 1


# ------------------------------------------------------------------------------------------ pipeline

# The demo preset at a test's size: 48 samples per set, one epoch, 1-object problems, 2 s per planner call.
PIPE_ARGS = ("--preset", "tiny", "--n", 48, "--epochs", 1, "--config", Path(__file__).resolve().parent / "pipe.toml",
             "--problems", 1, "--seed", 5)
STAGE_LINE = re.compile(r"^\[(\d+)/(\d+)\] (\S+) \.\.\. (skipped \(done\)|done in [\d.]+ s)$", re.M)


def _stages(out: str) -> dict[str, str]:
    return {m.group(3): "skipped" if m.group(4).startswith("skipped") else "done" for m in STAGE_LINE.finditer(out)}


def test_pipeline_resumes_without_redoing_finished_stages(tmp_path, tiny_preset):
    names = tiny_preset.stage_names
    out = tmp_path / "pipe"
    rc, text = cli("pipeline", "--out", out, *PIPE_ARGS, "--stop-after", "symbols")
    assert rc == 0, text
    first = names[:names.index("symbols") + 1]
    assert _stages(text) == dict.fromkeys(first, "done")
    kept = [out / "data" / "manifest.json", out / "data_extra" / "manifest.json", out / "run" / "best.pt",
            out / "run" / "eval.json", out / "run" / "table1.json", out / "run" / "symbols.json"]
    mtimes = [p.stat().st_mtime_ns for p in kept]
    assert not (out / "run" / "transition.pt").exists()

    rc, text = cli("pipeline", "--out", out, *PIPE_ARGS)
    assert rc == 0, text
    assert _stages(text) == {**dict.fromkeys(first, "skipped"), **dict.fromkeys(names[len(first):], "done")}
    assert [p.stat().st_mtime_ns for p in kept] == mtimes
    record = json.loads((out / "pipeline.json").read_text())
    assert list(record["stages"]) == list(names)
    configs = {name: rec["config"] for name, rec in record["stages"].items()}
    assert configs["evaluate"] == {}  # nothing to set: it reads best.pt and the data set
    train = configs["train"]  # the TrainConfig the stage ran with: the recipe's, overridden
    assert (train["preset"], train["epochs"], train["seed"], train["model"]["crop"]) == ("recommended", 1, 5, 32)
    assert train["stability_weight"] == 0.1 and train["model"]["action_per_object"]
    assert configs["collect-extra"]["exploration"]["k_values"] == [1, 2, 3, 4, 5]
    assert configs["train-transition"]["transition"]["location_bits"] == 9
    assert configs["train-transition"]["transition"]["epochs"] == 2  # tests/pipe.toml's [transition]
    assert configs["collect"]["shard_size"] == configs["collect-extra"]["shard_size"] == 4  # and its [collect]
    assert configs["problems"] == {"n": 1, "seed": 5, "objects": [1, 1]}
    assert (out / "run" / "pddl" / "lifted" / "domain.pddl").is_file()
    bench = json.loads((out / "run" / "benchmark.json").read_text())
    assert {(r["planner"], r["closed_loop"]) for r in bench["rows"]} == {  # --closed-loop runs both loops
        (p, loop) for p in ("astar-outcomes", "fast-downward-lifted") for loop in (False, True)}
    assert parse(out / "run" / "report.html").sections["benchmark"] == "ok"

    (out / "run" / "report.html").unlink()  # a lost output: only its stage runs again
    rc, text = cli("pipeline", "--out", out, *PIPE_ARGS)
    assert rc == 0 and _stages(text) == {**dict.fromkeys(names[:-1], "skipped"), "report": "done"}

    # other settings for a stage: it and what depends on its outputs run again; collect stays
    n_problems = len(list((out / "problems").glob("*.json")))
    rc, text = cli("pipeline", "--out", out, *PIPE_ARGS[:-4], "--seed", 5, "--problems", 2, "--stop-after", "problems")
    assert rc == 0 and _stages(text) == {**dict.fromkeys(names[:names.index("problems")], "skipped"), "problems": "done"}
    assert len(list((out / "problems").glob("*.json"))) > n_problems


def test_the_default_preset_is_the_recommended_recipe(tmp_path):
    """`symlearn pipeline --out X` runs the recipe that plans best, at full scale; demo is it at a small scale."""
    import dataclasses

    from symlearn.cli.main import build_parser
    from symlearn.pipeline import config_json, stage_configs
    from symlearn.pipeline_presets import PRESETS, PipelineSettings

    assert build_parser().parse_args(["pipeline", "--out", "x"]).preset == "recommended"
    s = PipelineSettings(out=tmp_path / "pipe")
    configs = {name: config_json(cfg) for name, cfg in stage_configs(s).items()}
    assert s.preset == "recommended" and not (tmp_path / "pipe").exists()
    assert list(configs) == ["collect", "collect-extra", "train", "evaluate", "table1", "symbols", "train-transition",
                             "export-pddl", "problems", "benchmark", "report"]
    main, extra = configs["collect"], configs["collect-extra"]
    assert (main["n"], main["seed"], main["exploration"]["k_values"]) == (12000, 0, [1, 2, 3])
    assert (extra["n"], extra["seed"], extra["exploration"]["k_values"]) == (12000, 2, [1, 2, 3, 4, 5])
    train = configs["train"]
    assert (train["preset"], train["epochs"], train["stability_weight"]) == ("recommended", 40, 0.1)
    assert train["model"]["crop"] == 32  # the quick model's sizes
    assert train["model"]["action_per_object"]  # the held object's token alone carries the action (Table I)
    transition = configs["train-transition"]
    assert (transition["transition"]["preset"], transition["transition"]["location_bits"]) == ("recommended", 9)
    assert transition["transition"]["hidden"] == 64  # the quick network
    assert transition["extra_data"] == ["data_extra"]
    assert set(configs["export-pddl"]) == {"lifted", "extra_data"} and configs["export-pddl"]["extra_data"] == [
        "data_extra"]
    assert configs["problems"] == {"n": 10, "seed": 0, "objects": [1, 5]}  # stratified by shortest-plan length
    bench = configs["benchmark"]
    assert bench["planners"] == ["astar-outcomes", "fast-downward-lifted"] and bench["threads"] == 1
    assert (bench["execution"]["closed_loop"], bench["execution"]["timeout_s"]) == (True, 10.0)
    from symlearn.planning.execution import ExecutionConfig  # what plan and benchmark do by default

    assert bench["execution"] == dataclasses.asdict(ExecutionConfig())
    sizes = dict.fromkeys(("samples", "extra_samples", "epochs", "transition_epochs", "min_count", "problem_objects",
                           "problems"))
    # the recipe, smaller: its lifted rules need fewer moves (LIFTED_PRESETS["small"])
    assert dataclasses.replace(PRESETS["demo"], lifted="fast", **sizes) == PRESETS["recommended"]
    paper = PipelineSettings(out=tmp_path / "paper", preset="paper")
    assert "collect-extra" not in paper.preset_values.stage_names
    assert config_json(stage_configs(paper)["train-transition"])["transition"]["location_bits"] == 0


@pytest.mark.parametrize("setup,args,message", [
    ("foreign", (), "is not a symlearn pipeline record"),
    ("", ("--stop-after", "nothing"), "unknown stage 'nothing'"),
    ("", ("--n", "0"), "argument --n: '0' must be a positive integer"),  # argparse's, before OUT is made
])
def test_pipeline_refusals_exit_2_with_one_line(setup, args, message, tmp_path, capsys):
    out = tmp_path / "pipe"
    if setup == "foreign":
        out.mkdir()
        (out / "pipeline.json").write_text('{"kind": "other"}')
    try:
        rc, _ = cli("pipeline", "--out", out, "--preset", "demo", *args)
    except SystemExit as e:  # a flag's value refused by argparse
        rc = e.code
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and message in err[0], err
    assert not (out / "data").exists()
