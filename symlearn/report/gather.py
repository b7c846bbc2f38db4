"""From a run's own outputs to report sections: pure functions of the loaded JSON, plus one reader.

Each `*_section` takes what a stage wrote (a dict, or None when the stage has not run) and returns a
Section; `gather_report` reads the files of a run directory and hands them over. A missing or
unreadable input becomes a "not run" section naming the file and the command that writes it.
"""
from __future__ import annotations

import math
from pathlib import Path

from pddl_export.bounded_json import JsonFileError, Schema, check, read_json_file
from symlearn.report import schemas
from symlearn.report.model import Image, Mark, Plot, Report, Section, Table, not_run
from symlearn.report.render import fmt

PAPER_EFFECT_MAE_MM = {"x": 8.6, "y": 15.0, "z": 6.0}  # the paper's test error of the attentive model
PAPER_SYMBOLS_95 = 35  # the paper: 35 symbols cover 95% of the objects
OBJECT_ORDER = (1, 0, 2)  # Table I's columns: first cube (green), stick (orange), second cube (red)
OBJECT_NAMES = ("first cube", "stick", "second cube")
RUN_FILES_ONLY = "the report reads only regular files inside the run"
SYMBOL_IMAGES = (("symbols.png", "Symbol prototypes (the paper's Fig. 4)"),
                 ("symbol_examples.png", "Examples of one symbol (the paper's Fig. 5)"))


def read_json(path: Path, schema: Schema | None = None, run: Path | None = None) -> tuple[dict | None, str]:
    """(document, '') or (None, one-line reason): missing, refused by the bounded reader (not a regular file,
    too large, not JSON, too deep, non-finite numbers) or not fitting `schema` (default: the schema of the
    run file of that name in symlearn.report.schemas, else any JSON object). With `run`, the file must also
    be a run file (outside_run): no symbolic link (opened with O_NOFOLLOW too), inside the run folder."""
    path = Path(path)
    if not path.exists() and not path.is_symlink():
        return None, f"{path} not found"
    why = outside_run(run, path) if run is not None else ""
    if why:
        return None, f"{path} cannot be read: {why}"
    schema = schema or schemas.RUN_FILES.get(path.name)
    try:
        doc = read_json_file(path, schema, what="run file", follow_symlinks=run is None)
    except JsonFileError as e:
        return None, cannot_read(path, e)
    if not isinstance(doc, dict):
        return None, f"{path} is not a JSON object"
    return doc, ""


def outside_run(run: Path, path: Path) -> str:
    """'' when `path` is no symbolic link (lstat) and lies inside the run folder once resolved (so a linked folder
    on the way is refused too); else the one-line reason. The report reads nothing else of the run: a link such as
    symbols.png -> ../secret.txt would copy its target into report.html and report_files/."""
    path = Path(path)
    if path.is_symlink():
        return f"is a symbolic link, not a regular run file ({RUN_FILES_ONLY})"
    try:
        path.resolve().relative_to(Path(run).resolve())
    except ValueError:
        return f"lies outside the run folder {run} ({RUN_FILES_ONLY})"
    return ""


def cannot_read(path: Path, e: Exception) -> str:
    """'PATH cannot be read: REASON' from a reader's one-line refusal ('PATH: REASON')."""
    return f"{path} cannot be read: {str(e).removeprefix(f'{path}: ')}"


def data_section(summary: dict | None, shares: dict | None, why: str = "") -> Section:
    """Data set counts (manifest), effect statistics and object shares."""
    title = "Data set"
    if summary is None:
        return not_run("data", title, why or "no data set given (--data) or recorded in RUN/config.json")
    counts = summary.get("counts", {})
    rows = [("path", summary.get("path")), *((f"{k} samples", v) for k, v in counts.items()),
            *((k, summary.get(k)) for k in ("samples", "objects", "objects_per_sample", "shards",
                                            "dropped_samples", "size_mb", "moved_fraction", "grasp_fraction"))]
    mae = summary.get("mean_abs_effect_mm") or {}
    rows += [(f"mean |effect| {a} (mm)", mae.get(a)) for a in "xyz"]
    s = Section("data", title, tables=[Table("Counts and effect statistics", ("quantity", "value"),
                                             tuple(rows), key="data")])
    if shares:
        keys = ("objects", "sticks", "stick_share", "stacked", "stacked_share", "riders", "rider_share",
                "riders_on_stick")
        s.tables.append(Table("Object shares (symlearn.data.statistics.object_shares)", ("quantity", "value"),
                              tuple((k, shares.get(k)) for k in keys), key="shares"))
    return s


def effect_section(ev: dict | None, why: str = "") -> Section:
    """Test-split effect MAE per axis next to the paper's 8.6 / 15 / 6 mm, with the ablation rows."""
    title = "Effect prediction error (test split)"
    if ev is None:
        return not_run("effect", title, why or "RUN/eval.json missing: run 'symlearn evaluate'",
                       _effect_marks({}, True) if refused(why) else [])
    ours = ev.get("effect_mae_mm") or {}
    marks = _effect_marks(ours)
    rows = [("attentive (ours)", *(ours.get(a) for a in "xyz")),
            ("paper", *(PAPER_EFFECT_MAE_MM[a] for a in "xyz"))]
    for name, r in (ev.get("ablations") or {}).items():
        m = r.get("effect_mae_mm") or {}
        rows.append((name, *(m.get(a) for a in "xyz")))
    mean = ev.get("mean_abs_effect_mm") or {}
    rows.append(("mean |effect|", *(mean.get(a) for a in "xyz")))
    riders = ev.get("riders") or {}
    text = [f"{ev.get('n_test_samples')} test samples; riders (objects carried by the held one): "
            f"{riders.get('count')}, MAE (mm) {fmt(riders.get('effect_mae_mm'))}"]
    return Section("effect", title, text=text, marks=marks,
                   tables=[Table("Mean absolute error per axis (mm)", ("model", "x", "y", "z"), tuple(rows),
                                 key="effect")])


def refused(why: str) -> bool:
    """Whether a section's reason says its file was refused (read_json, cannot_read), not merely missing."""
    return " cannot be read: " in why


def _effect_marks(ours: dict, invalid: bool = False) -> list[Mark]:
    """Our effect MAE per axis against the paper's; an error below zero (or a refused eval.json) is invalid."""
    return [Mark(f"effect MAE {a} (mm)", ours.get(a), PAPER_EFFECT_MAE_MM[a], "below the paper's",
                 None if ours.get(a) is None else ours[a] < PAPER_EFFECT_MAE_MM[a], invalid, (0.0, math.inf))
            for a in "xyz"]


def _vec(v) -> str:
    return "(" + ", ".join(f"{x:.0f}" for x in v) + ")" if v is not None else "-"


def table1_section(t1: dict | None, why: str = "", run: Path | None = None) -> Section:
    """Table I: predicted and true effects in the three stick cases, ours beside the paper's, and the criteria."""
    title = "Table I: the three stick cases"
    if t1 is None:
        return not_run("table1", title, why or "RUN/table1.json missing: run 'symlearn table1'",
                       _table1_marks({"motion_right": None, "riders_within_50mm": None}, True) if refused(why) else [])
    paper = t1.get("paper") or {}
    rows = []
    for key, label in (("predicted_mm", "predicted"), ("truth_mm", "truth")):
        for i, case in enumerate(t1.get("cases", [])):
            objs = case.get("objects", [])
            ref = (paper.get(key) or [[]] * 3)[i] if i < len(paper.get(key) or []) else []
            cells = []
            for j in OBJECT_ORDER:
                cells.append(_vec(objs[j][key]) if j < len(objs) else "-")
                cells.append(_vec(ref[j]) if j < len(ref) else "-")
            rows.append((f"case {i + 1} {label}", *cells))
    header = ("row",) + tuple(f"{n} {w}" for n in OBJECT_NAMES for w in ("ours", "paper"))
    marks = _table1_marks(t1.get("criteria") or {})
    mae = t1.get("mean_abs_error_mm") or {}
    text = [f"mean absolute error over the cases (mm): {fmt(mae or None)}"]
    for i, case in enumerate(t1.get("cases", [])):
        for rider in case.get("rider_attention") or []:
            if isinstance(rider, dict) and isinstance(rider.get("on_stick"), list):
                text.append(f"case {i + 1}: the rider (object {rider.get('object')}) puts "
                            f"{' / '.join(fmt(w) for w in rider['on_stick'])} of its attention on the stick, "
                            f"layer by layer")
    name = t1.get("attention_figure")  # the figure table1 drew and recorded in table1.json (a bare file name)
    figures = [("table1_attention", name, "Attention of each object on each object in the three cases (rows: who "
                "attends), per layer")] if run is not None and isinstance(name, str) and Path(name).name == name else []
    images, notes = run_images(run, figures)
    text += notes
    return Section("table1", title, marks=marks, text=text, images=images,
                   tables=[Table("Effects (mm), ours next to the paper's", header, tuple(rows), key="table1")])


def _table1_marks(c: dict, invalid: bool = False) -> list[Mark]:
    """Table I's two criteria as recorded in table1.json's `criteria` (each only when there), or invalid ones."""
    marks = []
    if "motion_right" in c:
        marks.append(Mark("Table I: every object's motion right", c.get("objects_motion_right"), "all objects",
                          "moved >= 100 mm in y the right way, or within 20 mm of still",
                          None if invalid else bool(c["motion_right"]), invalid))
    if "riders_within_50mm" in c:
        marks.append(Mark("Table I: riders' y within 50 mm of the truth", c.get("riders_right"), "all riders",
                          "|predicted y - true y| <= 50 mm", None if invalid else bool(c["riders_within_50mm"]),
                          invalid))
    return marks


def run_images(run: Path, figures) -> tuple[list[Image], list[str]]:
    """Images of the run's figure files (name, file name, caption) that are there, and a line for each refused
    (a symbolic link, or outside the run: outside_run): the report copies only the run's own files."""
    images, notes = [], []
    for name, file_name, caption in figures:
        path = Path(run) / file_name
        if not (path.is_file() or path.is_symlink()):
            continue
        why = outside_run(run, path)
        if why:
            notes.append(f"{path} not shown: {why}")
        else:
            images.append(Image(name, caption, path))
    return images, notes


def symbols_section(sy: dict | None, run: Path, why: str = "") -> Section:
    """Symbol counts next to the paper's '35 symbols cover 95%', the frequent symbols, and the figures."""
    title = "Symbols"
    if sy is None:
        return not_run("symbols", title, why or "RUN/symbols.json missing: run 'symlearn symbols'",
                       _symbols_marks(None, True) if refused(why) else [])
    n95 = sy.get("n_symbols_for_95pct")
    marks = _symbols_marks(n95)
    rows = tuple((k, sy.get(k)) for k in ("n_objects", "n_distinct", "n_symbols_for_95pct", "weighted_type_purity",
                                          "weighted_moved_purity", "example_symbol"))
    top = tuple((r.get("code"), r.get("count"), r.get("cube_fraction"), r.get("times_picked"),
                 r.get("moved_when_picked")) for r in (sy.get("symbols") or [])[:15])
    images, notes = run_images(run, [(Path(name).stem, name, cap) for name, cap in SYMBOL_IMAGES])
    return Section("symbols", title, marks=marks, images=images, text=notes,
                   tables=[Table("Symbol statistics", ("quantity", "value"), rows, key="symbols"),
                           Table("Most frequent symbols", ("code", "count", "cube fraction", "times picked",
                                                           "moved when picked"), top, key="symbol_list")])


def _symbols_marks(n95: int | None, invalid: bool = False) -> list[Mark]:
    """Symbols covering 95% of the objects against the paper's 35 (a count below zero is invalid)."""
    return [Mark("symbols covering 95% of objects", n95, PAPER_SYMBOLS_95, "at most the paper's 35",
                 None if n95 is None else n95 <= PAPER_SYMBOLS_95, invalid, (0, math.inf))]


def _series(history: list, keys: tuple[str, ...]) -> dict:
    out = {}
    for k in keys:
        pts = [(r.get("epoch", i + 1), r[k]) for i, r in enumerate(history) if isinstance(r.get(k), (int, float))]
        if pts:
            out[k] = ([p[0] for p in pts], [p[1] for p in pts])
    return out


def curves_section(effect_history: list | None, transition_history: list | None, why: str = "") -> Section:
    """Learning curves of the effect model and the transition network; `why` names history files refused."""
    title = "Learning curves"
    if not effect_history and not transition_history:
        return not_run("curves", title, why or "no training history: RUN/metrics.json (or best.pt) and "
                                               "RUN/transition_metrics.json missing")
    s = Section("curves", title)
    if effect_history:
        s.plots.append(Plot("effect_loss", "Effect model", "epoch", "loss",
                            _series(effect_history, ("train_loss", "val_loss"))))
        mae = {f"val MAE {a}": ([r.get("epoch", i + 1) for i, r in enumerate(effect_history) if r.get("val_mae_mm")],
                                [r["val_mae_mm"][a] for r in effect_history if r.get("val_mae_mm")]) for a in "xyz"}
        if any(v[0] for v in mae.values()):
            s.plots.append(Plot("effect_val_mae", "Effect model: validation MAE", "epoch", "mm", mae))
    else:
        s.text.append("effect model: not run (no history in RUN/metrics.json or RUN/best.pt)" + (f"; {why}" if why else ""))
    if transition_history:
        s.plots.append(Plot("transition_loss", "Transition network", "epoch", "loss",
                            _series(transition_history, ("train_loss", "val_loss"))))
    else:
        s.text.append("transition network: not run (RUN/transition_metrics.json missing: run 'symlearn train-transition')")
    return s


def benchmark_section(bench: dict | None, why: str = "") -> Section:
    """Per-planner success, found rate and median planning time."""
    title = "Planning benchmark"
    if bench is None:
        return not_run("benchmark", title, why or "no benchmark JSON given (--benchmark) or at RUN/benchmark.json")
    rows = tuple((name, s.get("n_problems"), s.get("success_rate"), s.get("found_rate"), s.get("median_time_s"),
                  s.get("success_rate_closed_loop"), s.get("mean_plan_length"))
                 for name, s in (bench.get("summary") or {}).items())
    text = [f"{bench.get('n_problems')} problems from {bench.get('problems')}, timeout {bench.get('timeout_s')} s"]
    tables = [Table("Success per planner", ("planner", "problems", "success", "found", "median time (s)",
                                            "closed-loop success", "mean plan length"), rows, key="benchmark")]
    placement = tuple((name, part.replace("_", " "), c.get("n_problems"), c.get("success_rate"),
                       c.get("success_rate_closed_loop"))
                      for name, parts in (bench.get("goal_placement") or {}).items() for part, c in parts.items())
    if placement:  # benchmarks written before the split have none
        tables.append(Table("Success on goals whose objects all rest on table locations, and on the rest "
                            "(a stick left across two places cannot be named by the symbols)",
                            ("planner", "goals", "problems", "success", "closed-loop success"), placement,
                            key="goal_placement"))
    shortest = bench.get("shortest_grid")
    if shortest:
        tables += _shortest_tables(shortest)
    elif bench.get("summary"):
        text.append("no grid by shortest-plan length: the benchmark was written before problems recorded their "
                    "shortest plans ('symlearn problems --kind annotate --out DIR', then benchmark again)")
    return Section("benchmark", title, text=text, tables=tables)


SHORTEST_COLUMNS = ("1-2", "3-4", "5-6", "7-8", "9-12", "off", "?")  # benchmark_summary.SHORTEST_BUCKETS


def _shortest_tables(shortest: dict) -> list[Table]:
    """The benchmark's objects x shortest-plan-length grid: success open / closed (n), then executed / shortest
    plan length and failure causes per cell (closed loop where it ran), one row per planner and object count."""
    used = [b for b in SHORTEST_COLUMNS if b in SHORTEST_COLUMNS[:5] or any(
        b in cells for by_loop in shortest.values() for loop in by_loop.values() for cells in loop.values())]
    success, detail = [], []
    for planner, by_loop in shortest.items():
        main = "closed" if "closed" in by_loop else "open"
        for k in sorted({k for loop in by_loop.values() for k in loop}, key=int):
            cells = []
            for b in used:
                c = [by_loop.get(loop, {}).get(k, {}).get(b) for loop in ("open", "closed")]
                n = next((x["n"] for x in c if x), None)
                cells.append("-" if n is None else " / ".join("-" if x is None or x.get("success_rate") is None
                                                              else f"{x['success_rate']:.2f}" for x in c) + f" ({n})")
            success.append((planner, k, *cells))
            row = []
            for b in used:
                c = by_loop.get(main, {}).get(k, {}).get(b)
                if not c:
                    row.append("-")
                    continue
                ratio = "-" if c.get("mean_length_ratio") is None else f"{c['mean_length_ratio']:.2f}"
                causes = ", ".join(f"{name} {m}" for name, m in sorted((c.get("failure_causes") or {}).items(),
                                                                       key=lambda kv: -kv[1]))
                row.append(ratio + (f"; {causes}" if causes else ""))
            detail.append((planner, main, k, *row))
    return [Table("Success open / closed (problems) by objects x shortest-plan length (off: goals off the "
                  "table locations; ?: shortest plan undecided)", ("planner", "objects", *used), tuple(success),
                  key="shortest_grid"),
            Table("Executed / shortest plan length over the successes; failure causes", ("planner", "loop",
                                                                                         "objects", *used),
                  tuple(detail), key="shortest_detail")]


def plan_section(filmstrip: Path | None, gif: Path | None, why: str = "") -> Section:
    """One executed plan as a filmstrip (start, then after each action); `why` a recording could not be read."""
    title = "An executed plan"
    if filmstrip is None:
        return not_run("plan", title, why or "no recorded plan: run 'symlearn plan ... --record RUN/plan.gif', or "
                                             "give a GIF with 'symlearn report --recording GIF'")
    return Section("plan", title, text=[f"recorded in {gif}: start, then the scene after each action "
                                        "(arrow: pick -> release)"],
                   images=[Image("plan_filmstrip", f"Filmstrip of {Path(gif).name}", filmstrip)])


def scorecard_section(report: Report) -> Section:
    """Every number the paper has, ours beside it, met or not met."""
    rows = tuple((m.claim, m.ours, m.paper, m.criterion, m.verdict) for m in report.marks())
    return Section("scorecard", "Against the paper",
                   tables=[Table("Every number the paper reports", ("claim", "ours", "paper", "criterion", "verdict"),
                                 rows, key="scorecard")])


def history_from_checkpoint(run: Path) -> list | None:
    """The effect model's per-epoch history from RUN/metrics.json, else from RUN/best.pt; None without either."""
    doc, _ = read_json(Path(run) / "metrics.json", run=run)
    if doc and isinstance(doc.get("history"), list):
        return doc["history"]
    if (Path(run) / "best.pt").is_file() and not outside_run(run, Path(run) / "best.pt"):
        from symlearn.learning.checkpoint import CheckpointError, load_checkpoint

        try:
            history = load_checkpoint(Path(run) / "best.pt").history
            check(history, schemas.HISTORY, f"{Path(run) / 'best.pt'} (history)")
            return history
        except (CheckpointError, JsonFileError):
            return None
    return None
