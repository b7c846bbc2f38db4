"""Reading a run's outputs into a Report and writing RUN/report.html and RUN/report.md (+ RUN/report_files/).

    >>> rep = build_report(Path("runs/paper"))                  # doctest: +SKIP
    >>> write_report(rep, Path("runs/paper"))                   # doctest: +SKIP
    (PosixPath('runs/paper/report.html'), PosixPath('runs/paper/report.md'))
"""
from __future__ import annotations

from pathlib import Path

from pddl_export.bounded_json import MiB, read_bounded_bytes
from symlearn.provenance import atomic_write_bytes, atomic_write_text
from symlearn.report import gather as g
from symlearn.report import schemas
from symlearn.report.figures import plot_png
from symlearn.report.model import NOT_RUN, Report
from symlearn.report.render import to_html, to_markdown

FILES_DIR = "report_files"
MAX_IMAGE_BYTES = 64 * MiB  # a figure of the run (symbols.png: ~150 KB)


def _data_dir(run: Path, data: Path | None) -> tuple[Path | None, str]:
    if data is not None:
        return Path(data), ""
    cfg, why = g.read_json(run / "config.json", run=run)
    if cfg and cfg.get("data"):
        return Path(cfg["data"]), ""
    return None, why and f"no --data given and {why}"


def _data_inputs(data: Path | None) -> tuple[dict | None, dict | None, str]:
    """summarize() and object_shares() of a data set, or the one-line reason they cannot be read."""
    if data is None:
        return None, None, ""
    from symlearn.data.dataset import load_split, summarize
    from symlearn.data.statistics import object_shares

    try:
        return summarize(data), object_shares(load_split(data, "all")), ""
    except (ValueError, OSError, KeyError) as e:
        return None, None, f"data set {data} cannot be read: {e}"


def find_recording(run: Path, recording: Path | None = None) -> Path | None:
    """The plan GIF to show: the one given, else RUN/plan.gif, else the first of RUN/recordings/*.gif."""
    if recording is not None:
        return Path(recording) if Path(recording).is_file() else None
    if (run / "plan.gif").is_file() or (run / "plan.gif").is_symlink():  # a link: refused by build_report
        return run / "plan.gif"
    gifs = sorted((run / "recordings").glob("*.gif")) if (run / "recordings").is_dir() else []
    return gifs[0] if gifs else None


def build_report(run: Path, data: Path | None = None, benchmark: Path | None = None,
                 recording: Path | None = None) -> Report:
    """Every section from RUN's files (and the data set, benchmark JSON and recorded GIF when there)."""
    run = Path(run)
    if not run.is_dir():
        raise ValueError(f"no run directory at {run}")
    files = files_dir(run)
    data, data_why = _data_dir(run, data)
    summary, shares, why = _data_inputs(data)
    ev, ev_why = g.read_json(run / "eval.json", run=run)
    t1, t1_why = g.read_json(run / "table1.json", run=run)
    sy, sy_why = g.read_json(run / "symbols.json", run=run)
    tm, tm_why = g.read_json(run / "transition_metrics.json", run=run)
    _, metrics_why = g.read_json(run / "metrics.json", run=run)
    curves_why = "; ".join(w for w in (metrics_why, tm_why) if "cannot be read" in w)
    bench_path = Path(benchmark) if benchmark is not None else run / "benchmark.json"
    bench, bench_why = g.read_json(bench_path, schemas.BENCHMARK, run=run if benchmark is None else None)
    if benchmark is None and not (bench_path.exists() or bench_path.is_symlink()):
        bench_why = ""
    gif = find_recording(run, recording)
    strip, gif_why = None, ""
    outside = g.outside_run(run, gif) if gif is not None and recording is None else ""
    if outside:
        gif_why = f"{gif} cannot be read: {outside}"
    elif gif is not None:
        from symlearn.planning.recording import RecordingError, filmstrip_from_gif

        try:
            strip = filmstrip_from_gif(gif, files / "plan_filmstrip.png")
        except RecordingError as e:  # beyond the pixel caps, or not a GIF: the section says so in one line
            gif_why = g.cannot_read(gif, e)
    sections = [g.data_section(summary, shares, why or data_why),
                g.effect_section(ev, _reason(ev_why, "symlearn evaluate")),
                g.table1_section(t1, _reason(t1_why, "symlearn table1"), run),
                g.symbols_section(sy, run, _reason(sy_why, "symlearn symbols")),
                g.curves_section(g.history_from_checkpoint(run), (tm or {}).get("history"), curves_why),
                g.benchmark_section(bench, bench_why),
                g.plan_section(strip, gif, gif_why)]
    rep = Report(run, sections)
    rep.sections.insert(0, g.scorecard_section(rep))
    return rep


def files_dir(run: Path) -> Path:
    """RUN/report_files, where the report writes its PNGs; ValueError (one line) when it is a symbolic link or
    lies outside the run: the report writes nothing outside its run folder."""
    files = Path(run) / FILES_DIR
    if g.outside_run(run, files):
        raise ValueError(f"{files} is a symbolic link or lies outside the run: the report writes only inside its "
                         f"run folder; remove it")
    return files


def _reason(why: str, command: str) -> str:
    return f"{why}: run '{command}'" if why.endswith("not found") else why


def write_report(report: Report, run: Path) -> tuple[Path, Path]:
    """Write RUN/report.html (self-contained) and RUN/report.md with its PNGs in RUN/report_files/."""
    run = Path(run)
    files = files_dir(run)
    files.mkdir(parents=True, exist_ok=True)
    pngs: dict[str, bytes] = {}
    for s in report.sections:
        if s.status == NOT_RUN:
            continue
        for p in s.plots:
            pngs[p.name] = plot_png(p)
        for im in s.images:
            pngs[im.name] = read_bounded_bytes(im.path, MAX_IMAGE_BYTES, "image", follow_symlinks=False)
    rel = {}
    for name, blob in pngs.items():
        target = files / f"{name}.png"
        if not (target.is_file() and target.read_bytes() == blob):
            atomic_write_bytes(target, blob)
        rel[name] = f"{FILES_DIR}/{name}.png"
    html_path, md_path = run / "report.html", run / "report.md"
    atomic_write_text(html_path, to_html(report, pngs))
    atomic_write_text(md_path, to_markdown(report, rel))
    return html_path, md_path
