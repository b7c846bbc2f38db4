"""Writing a Report as one self-contained HTML page (images inlined as base64 PNG) or as Markdown.

Numbers are printed the same way in both: floats with at most three decimals, None as '-'.
Each HTML section is <section id=KEY data-status=ok|not run>, each table carries data-table=KEY
and each mark's verdict cell class="verdict": readers (and the tests) can find them.
"""
from __future__ import annotations

import base64
import html

from symlearn.report.model import NOT_RUN, Report, Section

CSS = """body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}
th{background:#f3f3f3}td:first-child{text-align:left}.met{color:#1a7f37;font-weight:bold}
.not-met,.invalid{color:#c62828;font-weight:bold}.not-run{color:#888}img{max-width:100%;border:1px solid #ddd}
section{margin-bottom:2em}caption{text-align:left;font-style:italic}"""


def fmt(v) -> str:
    """A cell value as text: floats with at most three decimals, booleans as yes/no, None as '-'."""
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        s = f"{v:.3f}".rstrip("0").rstrip(".")
        return "0" if s in ("-0", "") else s
    if isinstance(v, dict):
        return ", ".join(f"{k} {fmt(x)}" for k, x in v.items())
    return str(v)


def _css_class(verdict: str) -> str:
    return {"met": "met", "not met": "not-met", "invalid": "invalid"}.get(verdict, "not-run")


def _html_table(t, verdict_col: int | None = None) -> str:
    e = html.escape
    head = "".join(f"<th>{e(h)}</th>" for h in t.header)
    body = []
    for row in t.rows:
        cells = []
        for i, v in enumerate(row):
            cls = f' class="verdict {_css_class(str(v))}"' if i == verdict_col else ""
            cells.append(f"<td{cls}>{e(fmt(v))}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return (f'<table data-table="{e(t.key)}"><caption>{e(t.caption)}</caption><thead><tr>{head}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody></table>")


def _html_section(s: Section, pngs: dict[str, bytes]) -> str:
    e = html.escape
    parts = [f'<section id="{e(s.key)}" data-status="{e(s.status)}"><h2>{e(s.title)}</h2>']
    if s.status == NOT_RUN:
        parts.append(f'<p class="not-run">not run: {e(s.note)}</p></section>')
        return "".join(parts)
    parts += [f"<p>{e(t)}</p>" for t in s.text]
    if s.marks:
        rows = "".join(f"<tr><td>{e(m.claim)}</td><td>{e(fmt(m.ours))}</td><td>{e(fmt(m.paper))}</td>"
                       f"<td>{e(m.criterion)}</td><td class=\"verdict {_css_class(m.verdict)}\">{e(m.verdict)}</td></tr>"
                       for m in s.marks)
        parts.append(f'<table data-table="{e(s.key)}-marks"><thead><tr><th>claim</th><th>ours</th><th>paper</th>'
                     f"<th>criterion</th><th>verdict</th></tr></thead><tbody>{rows}</tbody></table>")
    for t in s.tables:
        parts.append(_html_table(t, verdict_col=4 if t.key == "scorecard" else None))
    for name, caption in [(p.name, p.title) for p in s.plots] + [(i.name, i.caption) for i in s.images]:
        if name in pngs:
            b64 = base64.b64encode(pngs[name]).decode("ascii")
            parts.append(f'<figure data-figure="{e(name)}"><img alt="{e(caption)}" src="data:image/png;base64,{b64}">'
                         f"<figcaption>{e(caption)}</figcaption></figure>")
    parts.append("</section>")
    return "".join(parts)


def to_html(report: Report, pngs: dict[str, bytes]) -> str:
    """The whole report as one HTML page; `pngs` maps figure names to PNG bytes (inlined)."""
    title = f"symlearn report: {report.run.name}"
    body = "".join(_html_section(s, pngs) for s in report.sections)
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
            f"<style>{CSS}</style></head><body><h1>{html.escape(title)}</h1>"
            f"<p>Run directory: <code>{html.escape(str(report.run))}</code>. Every number comes from the run's own "
            f"outputs; sections whose stage has not run say so.</p>{body}</body></html>\n")


def md_text(s: str) -> str:
    """Text from a run's files made inert in Markdown: HTML escaped (as report.html does), on one line, and
    backslash, backticks and brackets escaped so that it opens no code span or link."""
    s = html.escape(" ".join(str(s).split()), quote=False)
    for c in "\\`[]":
        s = s.replace(c, "\\" + c)
    return s


def _md_table(header, rows) -> list[str]:
    cell = lambda v: md_text(fmt(v)).replace("|", "\\|")  # noqa: E731
    return ["| " + " | ".join(cell(h) for h in header) + " |", "|" + "---|" * len(header),
            *("| " + " | ".join(cell(v) for v in r) + " |" for r in rows), ""]


def to_markdown(report: Report, image_files: dict[str, str]) -> str:
    """The whole report as Markdown; `image_files` maps figure names to paths relative to the .md file."""
    out = [f"# symlearn report: {md_text(report.run.name)}", "", f"Run directory: {md_text(str(report.run))}", ""]
    for s in report.sections:
        out += [f"## {md_text(s.title)}", ""]
        if s.status == NOT_RUN:
            out += [f"*not run: {md_text(s.note)}*", ""]
            continue
        out += [*(f"{md_text(t)}\n" for t in s.text)]
        if s.marks:
            out += _md_table(("claim", "ours", "paper", "criterion", "verdict"),
                             [(m.claim, m.ours, m.paper, m.criterion, m.verdict) for m in s.marks])
        for t in s.tables:
            out += [f"*{md_text(t.caption)}*", "", *_md_table(t.header, t.rows)]
        for name, caption in [(p.name, p.title) for p in s.plots] + [(i.name, i.caption) for i in s.images]:
            if name in image_files:
                out += [f"![{md_text(caption)}]({image_files[name]})", ""]
    return "\n".join(out) + "\n"
