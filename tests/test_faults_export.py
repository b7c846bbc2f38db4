"""Fault probes of `export-pddl` (lifted) and its standalone problem folders (issue 59, round four).

Each probe failed on the code before the fix: two problem sets of one folder name written into one folder, stale
problems left beside a rewritten index, `--problems ..` writing over the run's PDDL folder, `--out FILE` refused only
after the distillation, a failed write leaving a new domain beside an old lifted.json, out-of-range values of
lifted.json ending in a traceback, hostile strings reaching the PDDL text, and examples/generate_domain.py writing
the domain of another transition.pt. The shipped run is copied, never written.
"""
from __future__ import annotations

import dataclasses
import errno
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import cli

ROOT = Path(__file__).resolve().parents[1]
RECOMMENDED = ROOT / "pretrained" / "recommended"
LIFTED = RECOMMENDED / "pddl" / "lifted.json"
HOSTILE = ("ab\n(:action injected :parameters () :precondition (and) :effect (and))",
           "x) (:action injected", "a;b", "ünïcödé", "", "a" * 10_000, "1abc", "a b", "tab\there",
           "line\u2028(:action injected)", "cr\r(:action injected)", "nul\x00", "sha256:abc", "ok-name_2")


@pytest.fixture
def run(tmp_path) -> Path:
    """A private copy of the shipped run (its lifted.json and lifted/domain.pddl included)."""
    dst = tmp_path / "run"
    shutil.copytree(RECOMMENDED, dst)
    return dst


@pytest.fixture
def config(tmp_path) -> Path:
    """[lifted] min_count 1: the tiny data set's few moves make rules."""
    path = tmp_path / "lifted.toml"
    path.write_text("[lifted]\nmin_count = 1\n")
    return path


def _problem_set(folder: Path, names: list[str]) -> Path:
    folder.mkdir(parents=True)
    for name in names:
        shutil.copy(RECOMMENDED / "problems" / name, folder / name)
    return folder


SHIPPED = sorted(p.name for p in (RECOMMENDED / "problems").glob("*.json"))


def _one_line_refusal(err: str) -> str:
    lines = [x for x in err.splitlines() if x.strip()]
    assert len(lines) == 1 and "Traceback" not in err and "Errno" not in err, err
    return lines[0]


def test_two_problem_sets_of_one_folder_name_are_refused_naming_both_before_any_work(run, tiny_data, config, tmp_path,
                                                                                     capsys):
    a = _problem_set(tmp_path / "A" / "test", SHIPPED[:3])
    b = _problem_set(tmp_path / "B" / "test", SHIPPED[3:])
    before = (run / "pddl" / "lifted.json").read_bytes()
    rc, _ = cli("export-pddl", "--run", run, "--data", tiny_data.path, "--config", config, "--problems", a, b)
    line = _one_line_refusal(capsys.readouterr().err)
    assert rc == 2 and str(a) in line and str(b) in line, line
    assert not (run / "pddl" / "lifted" / "test").exists()
    assert (run / "pddl" / "lifted.json").read_bytes() == before  # refused before the distillation


def test_a_rewritten_problem_folder_holds_the_new_set_alone(run, tmp_path):
    from symlearn.export.lifted_export import write_problem_folder

    out = tmp_path / "folder"
    first = write_problem_folder(run, _problem_set(tmp_path / "three", SHIPPED[:3]), out)
    assert sorted(first["problems"]) == ["p01", "p02", "p03"]
    (out / "p09.pddl").write_text("left by an older export")
    index = write_problem_folder(run, _problem_set(tmp_path / "one", SHIPPED[3:]), out)
    assert sorted(index["problems"]) == ["p01"]
    files = sorted(str(p.relative_to(out)) for p in out.rglob("*"))
    assert files == ["costs", "costs/domain.pddl", "costs/p01.pddl", "domain.pddl", "index.json", "p01.pddl"]
    assert json.loads((out / "index.json").read_text())["problems"]["p01"]["file"] == SHIPPED[3]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder", "one", "run", "three"]  # no temp folder left


def test_problems_dot_dot_writes_the_sets_own_folder_not_over_the_run(run, tiny_data, config, tmp_path, monkeypatch,
                                                                      capsys):
    mine = run / "pddl" / "domain.pddl"
    mine.write_text("the rules export's domain, not to be replaced\n")
    sub = _problem_set(tmp_path / "sets" / "tower", SHIPPED[3:]) / "sub"
    sub.mkdir()
    monkeypatch.chdir(sub)
    rc, text = cli("export-pddl", "--run", run, "--data", tiny_data.path, "--config", config, "--problems", "..")
    assert rc == 0, capsys.readouterr().err
    index = json.loads((run / "pddl" / "lifted" / "tower" / "index.json").read_text())
    assert list(index["problems"]) == ["p01"] and f"wrote {run / 'pddl' / 'lifted' / 'tower'}" in text
    assert mine.read_text() == "the rules export's domain, not to be replaced\n"
    assert not (run / "pddl" / "index.json").exists() and not (run / "pddl" / "p01.pddl").exists()
    rc, _ = cli("export-pddl", "--run", run, "--data", tiny_data.path, "--problems", "/")  # a set with no name
    assert rc == 2 and "not a safe name" in _one_line_refusal(capsys.readouterr().err)


@pytest.mark.parametrize("where", ["a file", "under a file", "lifted.json a folder", "domain.pddl not ours"])
def test_out_paths_are_refused_in_one_line_before_the_distillation(run, tiny_data, config, tmp_path, monkeypatch,
                                                                   capsys, where):
    import symlearn.export.lifted_export as lifted_export

    def no_distillation(*args, **kwargs):
        raise AssertionError("the distillation ran before the output paths were checked")
    monkeypatch.setattr(lifted_export, "training_moves", no_distillation)
    afile = tmp_path / "afile"
    afile.write_text("mine")
    out = {"a file": afile, "under a file": afile / "out"}.get(where, tmp_path / "out")
    if where == "lifted.json a folder":
        (out / "lifted.json").mkdir(parents=True)
    if where == "domain.pddl not ours":
        (out / "lifted").mkdir(parents=True)
        (out / "lifted" / "domain.pddl").write_text("(define (domain mine))\n")
    rc, _ = cli("export-pddl", "--run", run, "--data", tiny_data.path, "--config", config, "--out", out)
    line = _one_line_refusal(capsys.readouterr().err)
    assert rc == 2 and "--out" in line and (str(out) in line or str(afile) in line), line
    assert afile.read_text() == "mine"
    if where == "domain.pddl not ours":
        assert (out / "lifted" / "domain.pddl").read_text() == "(define (domain mine))\n"


def test_a_failed_write_leaves_the_old_domain_and_lifted_json_together(run, tiny_data, monkeypatch):
    from symlearn.export.lifted_export import LiftedConfig, export_lifted

    files = (run / "pddl" / "lifted" / "domain.pddl", run / "pddl" / "lifted.json")
    before = [f.read_bytes() for f in files]
    calls = []
    real_fsync = os.fsync

    def full_disk_at_the_second_file(fd):
        calls.append(fd)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)
    monkeypatch.setattr(os, "fsync", full_disk_at_the_second_file)
    with pytest.raises(OSError, match="No space left"):
        export_lifted(run, tiny_data.path, cfg=LiftedConfig(min_count=1))
    assert [f.read_bytes() for f in files] == before  # both old: not a new domain beside the old rules
    leftovers = [p.name for f in files for p in f.parent.iterdir() if p.name.startswith(".")]
    assert leftovers == []
    monkeypatch.setattr(os, "fsync", real_fsync)
    export_lifted(run, tiny_data.path, cfg=LiftedConfig(min_count=1))  # the same export, written whole
    from pddl_export.lifted_rules_io import load_lifted
    from pddl_export.lifted_domain import domain_pddl
    assert files[0].read_text() == domain_pddl(load_lifted(files[1])) and files[0].read_bytes() != before[0]


def test_files_written_as_a_unit_are_all_old_or_all_new(tmp_path, monkeypatch):
    from pddl_export import files as files_module

    paths = [tmp_path / "a.txt", tmp_path / "sub" / "b.txt", tmp_path / "c.txt"]
    for p in paths[:2]:
        p.parent.mkdir(exist_ok=True)
        p.write_text("old")
    real_replace = os.replace
    renames = []

    def fail_the_third_rename(src, dst):
        renames.append(dst)
        if len(renames) == 3:
            raise OSError(errno.EIO, "Input/output error")
        real_replace(src, dst)
    monkeypatch.setattr(os, "replace", fail_the_third_rename)
    with pytest.raises(OSError, match="Input/output"):
        files_module.atomic_write_files({p: "new" for p in paths})
    monkeypatch.setattr(os, "replace", real_replace)
    assert [p.read_text() for p in paths[:2]] == ["old", "old"] and not paths[2].exists()
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a.txt", "b.txt", "sub"]
    files_module.atomic_write_files({p: "new" for p in paths})
    assert [p.read_text() for p in paths] == ["new"] * 3


def _mutated(path: Path, change) -> Path:
    d = json.loads(LIFTED.read_text())
    change(d)
    path.write_text(json.dumps(d))
    return path


def _first(d: dict, riders: bool = False) -> dict:
    return next(r for r in d["rules"] if bool(dict(r["key"])["riders.sides"]) == riders)


@pytest.mark.parametrize("change, field", [
    (lambda d: _first(d)["outcome"][0].__setitem__(1, 99), "outcome[0][1]"),  # an outcome place 99
    (lambda d: _first(d)["outcome"][0].__setitem__(2, 8), "outcome[0][2]"),  # level 8: above the 3-bit field
    (lambda d: _first(d)["outcome"][0].__setitem__(3, 4), "outcome[0][3]"),  # a kind of 3 bits, 2 are kept
    (lambda d: _first(d)["key"][2].__setitem__(1, -1), "key[2][1] (o.place)"),
    (lambda d: _first(d)["key"][0].__setitem__(1, [0, 9]), "key[0][1] (cls)"),
    (lambda d: _first(d)["key"][6].__setitem__(1, [1]), "riders"),  # a rider in the key, none in the outcome
    (lambda d: d["codebook"][0].__setitem__(3, 8), "codebook[0][3]"),
    (lambda d: d["stick_of"][0].__setitem__(0, 1 << 20), "stick_of[0][0]"),
    (lambda d: d.__setitem__("kept", [0, 8]), "kept[1]"),
    (lambda d: d.__setitem__("end_rules", [{"class": [0, 1, 3], "destination": 3, "place": 99, "kind": 0,
                                            "support": 7, "share": 0.7, "cases": []}]), "end_rules[0].place"),
])
def test_out_of_range_lifted_json_values_are_refused_naming_the_file_and_field(tmp_path, change, field):
    from pddl_export.lifted_rules_io import load_lifted
    from pddl_export.lifted_domain import domain_pddl

    path = _mutated(tmp_path / "lifted.json", change)
    with pytest.raises(ValueError) as e:
        domain_pddl(load_lifted(path), costs=True)  # refused when read, not an IndexError when written
    message = str(e.value)
    assert "\n" not in message and message.startswith(str(path)) and field in message, message


def _small_rules():
    """The shipped rules cut to a few, so that the pddl package parses each domain in a moment."""
    from pddl_export.lifted_rules_io import load_lifted
    rules = load_lifted(LIFTED)
    return dataclasses.replace(rules, rules=tuple(r for r in rules.rules if r.pool is None)[:6], end_rules=())


def _scene(rules):
    """Two cubes' codes at l0 and l1 (level 2) and a goal that stacks the first on the second."""
    from pddl_export.symbolic import SymbolicGoal
    learned = next(c for (c, level), stick in sorted(rules.stick_of.items()) if level == 2 and not stick)
    code = lambda loc, level: (learned << 9) | (loc << 6) | level  # noqa: E731
    return [code(0, 2), code(1, 2)], SymbolicGoal((code(1, 4), code(1, 2)))


def _parsed_or_refused(make, n_actions: int | None = None) -> str:
    """'refused' where make() refuses in one line, else 'parsed': every text it returns parses with the pddl
    package, and a domain has exactly n_actions actions (none injected)."""
    from pddl.parser.domain import DomainParser
    from pddl.parser.problem import ProblemParser
    try:
        texts = make()
    except ValueError as e:
        assert "\n" not in str(e) and len(str(e)) < 400, str(e)
        return "refused"
    old = getattr(sys, "tracebacklimit", None)
    try:
        for text in texts:
            if "(define (domain" in text:
                domain = DomainParser()(text)  # a comment may quote the string; no action may come of it
                assert (n_actions is None or len(domain.actions) == n_actions) and \
                    all("injected" not in a.name for a in domain.actions)
            else:
                ProblemParser()(text)
    finally:
        if old is None and hasattr(sys, "tracebacklimit"):
            del sys.tracebacklimit
    return "parsed"


@pytest.mark.parametrize("hostile", HOSTILE, ids=range(len(HOSTILE)))
def test_hostile_strings_are_refused_or_written_as_valid_names(tmp_path, hostile):
    from pddl_export import lifted_domain, lifted_problem, lifted_vocabulary, pddl_writer
    from pddl_export.lifted_rules_io import load_lifted
    from pddl_export.rules import Rule, RuleSet

    rules = _small_rules()
    start, goal = _scene(rules)
    n = len(lifted_domain.schemas(rules))
    # lifted: the model hash (in memory, and from lifted.json), the problem name, an object's index
    evil = dataclasses.replace(rules, model_hash=hostile)
    outcomes = {
        "hash": _parsed_or_refused(lambda: (lifted_domain.domain_pddl(evil),
                                            lifted_problem.problem_pddl(evil, start, goal, "p01")), n),
        "problem": _parsed_or_refused(lambda: (lifted_problem.problem_pddl(rules, start, goal, hostile),)),
        "object": _parsed_or_refused(lambda: (f"(define (problem p) (:domain d) (:objects "
                                              f"{lifted_vocabulary.object_name(hostile)}) (:init) (:goal (and)))",)),
    }
    for field, change in (("model_hash", lambda d: d.__setitem__("model_hash", hostile)),
                          ("cls", lambda d: _first(d)["key"][0].__setitem__(1, hostile)),
                          ("key name", lambda d: _first(d)["key"][-1].__setitem__(0, hostile)),
                          ("where", lambda d: _first(d, riders=True)["outcome"][3].__setitem__(0, hostile))):
        path = _mutated(tmp_path / "lifted.json", change)

        def from_file():
            loaded = dataclasses.replace(load_lifted(path), rules=rules.rules)
            return lifted_domain.domain_pddl(loaded), lifted_problem.problem_pddl(loaded, start, goal, "p01")
        outcomes[f"lifted.json {field}"] = _parsed_or_refused(from_file, n)
    # rules over whole codes: the model hash (a comment), the domain and problem names, an object's index
    rs = RuleSet(bits=2, vocabulary=(1, 2), max_objects=2, n_rules_before_generalization=1,
                 rules=(Rule(action=5, code_from=1, code_to=2),))
    outcomes["conditional"] = _parsed_or_refused(lambda: (
        pddl_writer.conditional_domain(rs, model_hash=hostile, name=hostile),
        pddl_writer.problem_pddl(rs, [1, 2], [2, None], model_hash=hostile, name=hostile, domain_name=hostile)), 1)
    outcomes["strips"] = _parsed_or_refused(lambda: (
        (t := pddl_writer.strips_pddl(rs, [1, 1], [2, 2], model_hash=hostile, name=hostile,
                                      domain_name=hostile)).domain, t.problem), 1)
    outcomes["object (rules)"] = _parsed_or_refused(lambda: (f"(define (problem p) (:domain d) (:objects "
                                                             f"{pddl_writer.object_name(hostile)}) (:init) "
                                                             f"(:goal (and)))",))
    if hostile == "ok-name_2":  # a valid name passes wherever a name goes
        assert outcomes["problem"] == outcomes["conditional"] == outcomes["strips"] == "parsed", outcomes
    hex_digits = re.fullmatch(r"[0-9a-f]{0,64}", hostile) is not None  # a hash lifted.json may hold ("": none)
    assert outcomes["lifted.json model_hash"] == ("parsed" if hex_digits else "refused"), outcomes
    assert outcomes["lifted.json cls"] == "refused", outcomes
    assert outcomes["lifted.json key name"] == outcomes["lifted.json where"] == "refused", outcomes
    assert outcomes["object"] == outcomes["object (rules)"] == "refused", outcomes


def test_generate_domain_refuses_the_lifted_rules_of_another_transition_model(run, tmp_path):
    path = run / "pddl" / "lifted.json"
    d = json.loads(path.read_text())
    assert d["model_hash"] != "0123456789abcdef"
    path.write_text(json.dumps(dict(d, model_hash="0123456789abcdef")))
    out = tmp_path / "domain_folder"
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "generate_domain.py"), "--run", str(run), "--out",
                        str(out)], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert r.returncode != 0 and not out.exists(), r.stdout[-2000:]
    line = _one_line_refusal(r.stderr)
    assert "another transition.pt" in line and str(path) in line, line
