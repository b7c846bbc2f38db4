"""What the code says about the command line is what the command line accepts: docstrings and messages cannot drift.

The Markdown check (test_docs_commands.py) covers the docs; this one reads the texts a user meets elsewhere: every
docstring (module, class, function) and every string constant inside a `raise` or a call (error messages,
`print`s, `--help` texts; an f-string by its constant parts, each `{...}` a placeholder) of the .py files in
symlearn/, pddl_export/, search/, examples/, bench/ and experiments/, and all of pyproject.toml.

Two rules, judged against the real argparse parsers:
- a command, `symlearn SUB ...` or `SUB --flag ...` (SUB a sub-command's name) or `python bench/x.py ...`, is judged
  as the docs' commands are (its sub-command or script, its flags, their choices), up to the next backtick, quote,
  parenthesis, semicolon or line end. `symlearn WORD` is a command where it is quoted, starts an indented example
  line or is followed by a flag, so that prose ("not a symlearn data set") is not;
- any other `--flag` must be one of some sub-command, of the script it is written in, or a foreign program's
  (FOREIGN_FLAGS, each with whose it is).
"""
from __future__ import annotations

import argparse
import ast
import functools
import inspect
import re
from pathlib import Path

import pytest

from test_docs_commands import ROOT, _script_flags, _subcommands, command_problems

SOURCE_DIRS = ("symlearn", "pddl_export", "search", "examples", "bench", "experiments")  # those that exist
# Flags of other programs that the code passes or names; each is theirs, not symlearn's.
FOREIGN_FLAGS = {
    "--alias": "Fast Downward", "--search": "Fast Downward", "--overall-time-limit": "Fast Downward",
    "--overall-memory-limit": "Fast Downward", "--internal-plan-file": "Fast Downward",
    "--keep-unimportant-variables": "Fast Downward's translator",
    "--junitxml": "pytest", "--no-deps": "pip",
}
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9_-]*")
_END = r"[^`'\"();\n]*"  # a command runs to the next backtick, quote, parenthesis, semicolon or line end
SCRIPT_COMMAND = re.compile(rf"\bpython3?\s+((?:bench|experiments|examples)/[\w/.-]+\.py){_END}")
SYMLEARN_WORD = re.compile(rf"(^[ \t]+|[`'\"]\s*)?\bsymlearn\s+([a-z][a-z0-9-]*(?:/[a-z][a-z0-9-]*)*)({_END})", re.M)


def source_texts(path: Path) -> list[str]:
    """The docstrings of a Python file and the string constants inside its raise statements and calls."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs, inside, parts = [], set(), set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            docs += [inspect.cleandoc(doc)] if doc else []
        elif isinstance(node, (ast.Raise, ast.Call)):
            inside |= {id(sub) for sub in ast.walk(node)}
        if isinstance(node, ast.JoinedStr):
            parts |= {id(v) for v in node.values}  # read with their f-string, not alone
    messages = [_constant_text(n) for n in ast.walk(tree) if id(n) in inside and id(n) not in parts]
    return list(dict.fromkeys(docs + [m for m in messages if m]))  # each text once, in order


def _constant_text(node: ast.AST) -> str | None:
    """A string constant's text; an f-string's constant parts with `{}` for each formatted value."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(v.value if isinstance(v, ast.Constant) else "{}" for v in node.values)
    return None


def text_problems(text: str, own_flags: frozenset[str] = frozenset()) -> list[str]:
    """What in one text names a command, sub-command or flag the code does not have; [] when nothing."""
    subs = _parsers()
    problems, spans = [], []
    for m in SYMLEARN_WORD.finditer(text):
        words, rest = m.group(2).split("/"), m.group(3)
        if any(w in subs for w in words) or m.group(1) is not None or rest.lstrip().startswith("--"):
            problems += [p for w in words for p in _judge(f"symlearn {w} {rest}", subs)]
            spans.append(m.span())
    names = "|".join(sorted(map(re.escape, subs), key=len, reverse=True))
    for m in re.finditer(rf"(?<![\w/.-])({names})(\s+--{_END})", text):
        if not any(a <= m.start() < b for a, b in spans):
            problems += _judge(f"symlearn {m.group(1)} {m.group(2)}", subs)
            spans.append(m.span())
    for m in SCRIPT_COMMAND.finditer(text):
        problems += _judge(m.group(0), subs)
        spans.append(m.span())
    known = {o for p in subs.values() for a in p._actions for o in a.option_strings} | own_flags | set(FOREIGN_FLAGS)
    problems += [f"unknown flag {m.group(0)}" for m in FLAG.finditer(text)
                 if m.group(0) not in known and not any(a <= m.start() < b for a, b in spans)]
    return list(dict.fromkeys(problems))


def _judge(command: str, subs: dict[str, argparse.ArgumentParser]) -> list[str]:
    """command_problems on a command written in prose: a comma, full stop or colon that ends a word is the prose's."""
    return command_problems(" ".join(re.sub(r"[,.:]+(?=\s|$)", "", command).split()), subs)


@functools.cache
def _parsers() -> dict[str, argparse.ArgumentParser]:
    """The sub-commands' parsers, built once for the thousands of texts read."""
    return _subcommands()


def source_files() -> list[Path]:
    """Every .py file the drift check reads, as the tree is when the test runs."""
    return [f for d in SOURCE_DIRS if (ROOT / d).is_dir() for f in sorted((ROOT / d).rglob("*.py"))]


def file_problems(path: Path) -> list[str]:
    """Each problem of a source file (or pyproject.toml) with the text it is in, shortened."""
    if path.suffix == ".toml":
        texts, own = path.read_text(encoding="utf-8").splitlines(), frozenset()  # comments included
    else:
        texts, own = source_texts(path), frozenset(_script_flags(path))
    return [f"{'; '.join(p)}: {' '.join(t.split())[:100]!r}" for t in texts if (p := text_problems(t, own))]


def test_the_check_reads_the_texts_users_meet():
    files = source_files()
    assert {"symlearn/cli/main.py", "bench/ray_overhead.py", "symlearn/symbolic/locations.py"} <= {
        str(f.relative_to(ROOT)) for f in files}
    texts = [t for f in files for t in source_texts(f)]
    assert len(texts) > 2000, len(texts)
    commands = [t for t in texts if SYMLEARN_WORD.search(t)]
    assert len(commands) > 50, len(commands)
    ours = {o for p in _parsers().values() for a in p._actions for o in a.option_strings}
    assert not ours & set(FOREIGN_FLAGS), "a foreign flag would hide one of symlearn's"


@pytest.mark.parametrize("folder", [*(d for d in SOURCE_DIRS if (ROOT / d).is_dir()), "pyproject.toml"])
def test_no_docstring_or_message_names_a_flag_the_code_lacks(folder):
    files = [ROOT / folder] if folder.endswith(".toml") else [f for f in source_files()
                                                              if f.relative_to(ROOT).parts[0] == folder]
    assert files, folder
    bad = [f"{f.relative_to(ROOT)}: {p}" for f in files for p in file_problems(f)]
    assert not bad, "\n".join(bad)


def _problems_of_source(tmp_path: Path, source: str) -> list[str]:
    path = tmp_path / "module.py"
    path.write_text(source, encoding="utf-8")
    return file_problems(path)


@pytest.mark.parametrize("source, expected", [
    ('"""Run it as\n\n    symlearn collect --n 10 --engine ray --address auto\n"""', "unknown flag --engine"),
    ('"""Codes from `symlearn train-transition --location-bits 9`."""', "unknown flag --location-bits"),
    ('def f(n):\n    raise ValueError(f"retrain (train-transition --location-bits {n})")', "unknown flag --location"),
    ('print("run \'symlearn teach --run R\' first")', "no sub-command 'teach'"),
    ('"""Then `symlearn problems --kind deep --out P`."""', "--kind deep: not one of"),
    ('"""Bits as `train --location-bits` gives them."""', "unknown flag --location-bits"),
    ('"""    python bench/no_such_script.py --out x.json"""', "no script bench/no_such_script.py"),
    ('raise SystemExit("pass --frobnicate to go faster")', "unknown flag --frobnicate"),
])
def test_the_check_refuses_stale_texts(tmp_path, source, expected):
    problems = _problems_of_source(tmp_path, source)
    assert any(expected in p for p in problems), problems


def test_the_check_passes_real_commands_prose_and_foreign_flags(tmp_path):
    source = '''"""Collect with `symlearn collect --out D --ray auto`, then

    symlearn train --data D --out R --preset recommended
"""
import subprocess
import argparse

def f(path, ap: argparse.ArgumentParser):
    ap.add_argument("--repeats", type=int, help="runs per problem; with --timeout as for benchmark --timeout")
    subprocess.run(["fast-downward.py", "--alias", "lama-first", "--overall-time-limit", "10s", str(path)])
    raise ValueError(f"{path} is not a symlearn data set; this symlearn reads version {1} (--junitxml is pytest's)")
'''
    assert _problems_of_source(tmp_path, source) == []


def test_pyproject_is_read_as_text(tmp_path):
    path = tmp_path / "pyproject.toml"
    path.write_text('# across a cluster (symlearn collect/benchmark --engine ray)\nray = ["ray>=2.9"]\n')
    assert any("unknown flag --engine" in p for p in file_problems(path))
    path.write_text('# across a cluster (symlearn collect/benchmark --ray)\nray = ["ray>=2.9"]\n')
    assert file_problems(path) == []
