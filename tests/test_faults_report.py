"""Faults of the run report (issue 59): impossible values shown as "met", and files from outside the run.

An eval.json whose effect MAE is below zero was read as a fine number and the scorecard said "met" against
the paper; now the schemas refuse impossible values (errors, times and lengths below zero, rates and
shares outside 0..1), the section says the file cannot be read, and the scorecard marks read "invalid".
A symbolic link in the run folder (symbols.png -> ../secret.txt, eval.json -> a file elsewhere, a linked
recordings/ or report_files/ folder) had its target copied into report.html and report_files/; now the
report reads only regular files inside the run and writes only there.
"""
from __future__ import annotations

import base64
import json
import os
import re
import shutil
from pathlib import Path

import pytest

from conftest import cli

ROOT = Path(__file__).resolve().parents[1]
PRETRAINED = ROOT / "pretrained" / "quick-authors12k"
SECRET = b"\x89PNG\r\n\x1a\n not a figure of the run: the user's secret"


@pytest.fixture
def no_plots(monkeypatch):
    """Plots drawn as a fixed PNG stub: what is under test is reading (matplotlib takes a second a plot)."""
    from symlearn.report import build

    monkeypatch.setattr(build, "plot_png", lambda plot: b"\x89PNG\r\n\x1a\n")


def _report(run: Path) -> tuple[str, str]:
    """Write the report of `run` through the command line; (report.html, report.md)."""
    rc, out = cli("report", "--run", run)
    assert rc == 0, out
    return (run / "report.html").read_text(), (run / "report.md").read_text()


def _scorecard(md: str) -> dict[str, list[str]]:
    """claim -> [ours, paper, criterion, verdict] from report.md's scorecard table."""
    part = md.split("## Against the paper", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in part.splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip()[1:-1])]  # cells hold escaped pipes
        if line.startswith("| ") and len(cells) == 5 and cells[0] != "claim":
            rows[cells[0]] = cells[1:]
    return rows


# ----------------------------------------------------------------------- impossible values are not "met"


@pytest.mark.parametrize("fname, doc, field, claims", [
    ("eval.json", {"effect_mae_mm": {"x": -3.0, "y": 1.0, "z": 1.0}}, "effect_mae_mm.x",
     ["effect MAE x (mm)", "effect MAE y (mm)", "effect MAE z (mm)"]),
    ("eval.json", {"effect_mae_mm": {"x": 1.0, "y": 1.0, "z": 1.0}, "riders": {"count": 3, "effect_mae_mm": -1}},
     "riders.effect_mae_mm", ["effect MAE x (mm)"]),
    ("symbols.json", {"n_symbols_for_95pct": 20, "weighted_type_purity": 1.5}, "weighted_type_purity",
     ["symbols covering 95% of objects"]),
    ("table1.json", {"cases": [], "criteria": {"motion_right": True, "riders_within_50mm": True},
                     "mean_abs_error_mm": {"x": -5.0}}, "mean_abs_error_mm",
     ["Table I: every object's motion right", "Table I: riders' y within 50 mm of the truth"]),
])
def test_impossible_values_are_invalid_not_met(tmp_path, no_plots, fname, doc, field, claims):
    """A negative error (or a purity above 1) in a run file: the file is refused naming the field, its section
    says it cannot be read, and the scorecard marks its claims "invalid" (before: "met")."""
    run = tmp_path / "run"
    run.mkdir()
    (run / fname).write_text(json.dumps(doc))
    _, md = _report(run)
    assert f"{run / fname} cannot be read: field {field}" in md.replace("\\", ""), md
    card = _scorecard(md)
    for claim in claims:
        assert card[claim][-1] == "invalid", (claim, card)
    assert "met" not in {row[-1] for row in card.values()}, card


@pytest.mark.parametrize("summary, field", [
    ({"astar": {"n_problems": 3, "success_rate": 1.5}}, "summary.astar.success_rate"),
    ({"astar": {"n_problems": 3, "found_rate": -0.1}}, "summary.astar.found_rate"),
    ({"astar": {"n_problems": 3, "median_time_s": -2.0}}, "summary.astar.median_time_s"),
])
def test_benchmark_rates_outside_0_1_are_refused(tmp_path, no_plots, summary, field):
    run = tmp_path / "run"
    run.mkdir()
    (run / "benchmark.json").write_text(json.dumps({"summary": summary, "n_problems": 3}))
    _, md = _report(run)
    assert f"{run / 'benchmark.json'} cannot be read: field {field}" in md.replace("\\", ""), md


def test_a_mark_outside_its_valid_range_is_invalid_whatever_met_says():
    from symlearn.report.model import Mark

    assert Mark("effect MAE x (mm)", -1.0, 8.6, "below the paper's", True, valid=(0.0, 1e9)).verdict == "invalid"
    assert Mark("effect MAE x (mm)", float("nan"), 8.6, "below", False, valid=(0.0, 1e9)).verdict == "invalid"
    assert Mark("effect MAE x (mm)", 1.0, 8.6, "below the paper's", True, valid=(0.0, 1e9)).verdict == "met"
    assert Mark("effect MAE x (mm)", None, 8.6, "below the paper's", None, invalid=True).verdict == "invalid"


# ----------------------------------------------------------------------- nothing from outside the run


def _run_with_symbols(tmp_path: Path) -> Path:
    run = tmp_path / "run"
    run.mkdir()
    shutil.copy(PRETRAINED / "symbols.json", run / "symbols.json")
    (tmp_path / "secret.txt").write_bytes(SECRET)
    return run


def _holds_secret(run: Path, html: str) -> bool:
    inlined = base64.b64encode(SECRET).decode("ascii") in html
    copied = any(p.is_file() and SECRET in p.read_bytes() for p in (run / "report_files").rglob("*")) \
        if (run / "report_files").is_dir() else False
    return inlined or copied


def test_report_does_not_follow_a_figure_link_out_of_the_run(tmp_path, no_plots):
    """symbols.png -> ../secret.txt: not inlined into report.html nor copied to report_files/; the section says
    the figure is not shown; the regular symbol_examples.png beside it is."""
    run = _run_with_symbols(tmp_path)
    os.symlink("../secret.txt", run / "symbols.png")
    shutil.copy(PRETRAINED / "symbol_examples.png", run / "symbol_examples.png")
    html, md = _report(run)
    assert not _holds_secret(run, html)
    assert f"{run / 'symbols.png'} not shown: is a symbolic link" in md.replace("\\", ""), md
    assert (run / "report_files" / "symbol_examples.png").read_bytes() == (run / "symbol_examples.png").read_bytes()
    assert not (run / "report_files" / "symbols.png").exists()


def test_report_does_not_read_a_run_file_linked_from_elsewhere(tmp_path, no_plots):
    """eval.json -> a valid eval.json outside the run: refused as a symbolic link (its numbers not shown)."""
    run = tmp_path / "run"
    run.mkdir()
    (tmp_path / "elsewhere.json").write_text(json.dumps({"effect_mae_mm": {"x": 1.234, "y": 2.0, "z": 3.0}}))
    os.symlink(tmp_path / "elsewhere.json", run / "eval.json")
    html, md = _report(run)
    assert "1.234" not in html and "1.234" not in md
    assert f"{run / 'eval.json'} cannot be read: is a symbolic link" in md.replace("\\", ""), md


def test_report_does_not_read_recordings_from_a_linked_folder(tmp_path, no_plots):
    """RUN/recordings -> a folder outside the run holding a GIF: the plan section says it cannot be read."""
    from PIL import Image

    run = tmp_path / "run"
    run.mkdir()
    outside = tmp_path / "outside"
    outside.mkdir()
    frames = [Image.new("RGB", (8, 8), c) for c in ("red", "blue")]
    frames[0].save(outside / "p.gif", save_all=True, append_images=frames[1:])
    os.symlink(outside, run / "recordings")
    _, md = _report(run)
    assert f"{run / 'recordings' / 'p.gif'} cannot be read: lies outside the run" in md.replace("\\", ""), md
    assert not (run / "report_files" / "plan_filmstrip.png").exists()


def test_report_writes_nothing_through_a_linked_report_files_folder(tmp_path, no_plots, capsys):
    """RUN/report_files -> a folder outside the run: refused in one line, nothing written there."""
    run = _run_with_symbols(tmp_path)
    shutil.copy(PRETRAINED / "symbols.png", run / "symbols.png")
    outside = tmp_path / "outside"
    outside.mkdir()
    os.symlink(outside, run / "report_files")
    rc, _ = cli("report", "--run", run)
    assert rc == 2 and list(outside.iterdir()) == []
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("symlearn report: error: ") and f"{run / 'report_files'} is a symbolic link" in err, err
