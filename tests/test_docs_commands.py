"""Every command the README and docs/ give is one the code accepts: a figure must stay re-runnable by its command.

Commands are read from fenced blocks (backslash continuations joined) and from inline code that starts with
`symlearn ` or `python bench/`. Each flag must be one its sub-command (or bench script) defines, each value of a
flag with choices one of them, each planner of `--planners` a registered one. Placeholders (COPY, RUN, S,
{walks,structures}, `...`) and the flags' required-ness are not judged: docs often show a fragment such as
`problems --kind walks`.
"""
from __future__ import annotations

import argparse
import ast
import re
from pathlib import Path

import pytest

from symlearn.cli.main import build_parser
from search.stock_planners import STOCK_PLANNERS
from symlearn.planning.planners import PLANNERS

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "experiments" / "README.md", ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
STARTS = ("symlearn ", "python bench/", "python experiments/")


def doc_commands(text: str) -> list[str]:
    """The `symlearn ...` and `python bench/...` commands of a Markdown text, one string each."""
    out = []
    for block in re.findall(r"```[^\n]*\n(.*?)```", text, re.S):
        for line in re.sub(r"\\\n\s*", " ", block).splitlines():
            for part in re.split(r"&&|;", line.split("  #")[0]):
                if part.strip().startswith(STARTS):
                    out.append(part.strip())
    for span in re.findall(r"`([^`]+)`", re.sub(r"```.*?```", "", text, flags=re.S)):
        span = " ".join(span.split())
        if span.startswith(STARTS) and len(span.split()) > 2:
            out.append(span)
    return out


def _placeholder(value: str) -> bool:
    return value.isupper() or any(ch in value for ch in "{|…") or "..." in value or value.startswith("<")


def _subcommands() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices


def _script_flags(script: Path) -> set[str]:
    """The option strings a bench script passes to add_argument (read from its source, nothing imported)."""
    flags = set()
    for node in ast.walk(ast.parse(script.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "add_argument":
            flags |= {a.value for a in node.args if isinstance(a, ast.Constant) and isinstance(a.value, str)}
    return flags


def _script_planner_names(script: Path) -> set[str]:
    """The keys of the bench script's UP_PLANNERS map: the unified-planning engines it runs beside the stock ones
    (read from its source, nothing imported)."""
    for node in ast.walk(ast.parse(script.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "UP_PLANNERS" for t in node.targets):
            return {k.value for k in node.value.keys if isinstance(k, ast.Constant)}
    return set()


STOCK_FD_PLANNERS = set(STOCK_PLANNERS) | _script_planner_names(Path(__file__).resolve().parents[1] / "bench" /
                                                                 "stock_fd.py")


def command_problems(command: str, subcommands: dict[str, argparse.ArgumentParser]) -> list[str]:
    """What in one documented command the code would refuse; [] when nothing."""
    toks = [t.strip("[]") for t in command.split()]
    if toks[0] == "symlearn":
        if toks[1] not in subcommands:
            return [f"no sub-command {toks[1]!r}"]
        actions = {o: a for a in subcommands[toks[1]]._actions for o in a.option_strings}
    else:
        script = ROOT / toks[1]
        if not script.is_file():
            return [f"no script {toks[1]}"]
        actions = {o: None for o in _script_flags(script)}
    problems = []
    for i, tok in enumerate(toks):
        if not tok.startswith("--"):
            continue
        flag, _, inline = tok.partition("=")
        value = inline or (toks[i + 1] if i + 1 < len(toks) else "")
        if flag not in actions:
            problems.append(f"unknown flag {flag}")
            continue
        if flag == "--planners" and not _placeholder(value):
            known = STOCK_FD_PLANNERS if toks[1] == "bench/stock_fd.py" else PLANNERS  # it runs stock configurations
            problems += [f"unknown planner {n!r}" for n in value.split(",") if n and n not in known]
        action = actions[flag]
        if action is not None and action.choices and value and not _placeholder(value):
            try:
                ok = (action.type(value) if callable(action.type) else value) in action.choices
            except (TypeError, ValueError):
                ok = False
            if not ok:
                problems.append(f"{flag} {value}: not one of {list(action.choices)}")
    return problems


def test_the_docs_hold_commands_to_check():
    found = {d.name: len(doc_commands(d.read_text(encoding="utf-8"))) for d in DOCS}
    assert found["README.md"] >= 10 and found["RESULTS.md"] >= 12 and found["BENCHMARKS.md"] >= 10, found


@pytest.mark.parametrize("doc", DOCS, ids=lambda d: d.name)
def test_every_documented_command_is_accepted(doc):
    subs = _subcommands()
    bad = [f"{c[:90]}: {'; '.join(p)}" for c in doc_commands(doc.read_text(encoding="utf-8"))
           if (p := command_problems(c, subs))]
    assert not bad, f"{doc.name}:\n" + "\n".join(bad)


@pytest.mark.parametrize("command, expected", [
    ("symlearn benchmark --run R --problems P --planners astar,astar-magic", "unknown planner 'astar-magic'"),
    ("symlearn problems --out P --kind deep", "--kind deep: not one of"),
    ("symlearn train-transition --run R --location-bits 9", "unknown flag --location-bits"),
    ("symlearn train --data D --out R --preset huge", "--preset huge: not one of"),
    ("symlearn train --data D --out R --epoch 3", "unknown flag --epoch"),
    ("symlearn teach --run R", "no sub-command 'teach'"),
    ("python bench/stock_fd.py --domain D --problems P --floor --out x.json", "unknown flag --floor"),
    ("python bench/no_such_script.py --out x.json", "no script bench/no_such_script.py"),
])
def test_the_check_refuses_what_the_code_would(command, expected):
    assert any(expected in p for p in command_problems(command, _subcommands())), command


def test_the_check_accepts_placeholders_and_fragments():
    subs = _subcommands()
    for command in ("symlearn problems --kind {walks,structures} [--n 4]",
                    "symlearn train-transition --run COPY --config C.toml --seed S",
                    "symlearn benchmark --run COPY --problems A,B --planners P --timeout 10",
                    "python bench/stock_fd.py --domain D --problems A,B --planners fd-lama-first --out x.json"):
        assert command_problems(command, subs) == [], command
