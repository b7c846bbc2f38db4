"""Stock planners on PDDL files (search.stock_planners): solved, validated, refused and killed as they should be.

The task is a hand-written lifted toy of the table, written here: 3 blocks on 3 locations, typed objects
(block, location, tier: a height), one `pick-release ?o ?from ?to ?hf ?hf1 ?ht ?ht1` schema that moves the top block
of ?from onto ?to, with a negative precondition (`(not (at ?o ?to))`: ?from and ?to differ). Plans are
checked with pyval (pddl-pyvalidator, a validator on unified-planning's parser, not Fast Downward's),
and optimal lengths against a breadth-first search over stacks written in this file. Every variable carries
its own type (`?a - t ?b - t`, not `?a ?b - t`), which pddlgym's parser needs; no type shares a predicate's
name (`level`), which unified-planning's parser, and so pyval, refuses.
"""
from __future__ import annotations

import os
import tempfile
from collections import deque
from pathlib import Path

import pytest

from search.result import PlanResult, PlanStatus
from search.stock_planners import STOCK_PLANNERS, fast_downward_driver, solve_files, solve_texts

pytestmark = pytest.mark.skipif(fast_downward_driver() is None, reason="up-fast-downward is not installed")

DOMAIN = """(define (domain toy-table)
  (:requirements :strips :typing :negative-preconditions{costreq})
  (:types block location tier)
  (:predicates (at ?o - block ?l - location) (level ?o - block ?h - tier) (height ?l - location ?h - tier)
               (succ ?h - tier ?h2 - tier){pred})
  {functions}(:action pick-release
    :parameters (?o - block ?from - location ?to - location ?hf - tier ?hf1 - tier ?ht - tier ?ht1 - tier)
    :precondition (and (at ?o ?from) {differ} (level ?o ?hf) (succ ?hf ?hf1) (height ?from ?hf1)
                       (height ?to ?ht) (succ ?ht ?ht1))
    :effect (and (not (at ?o ?from)) (at ?o ?to) (not (level ?o ?hf)) (level ?o ?ht)
                 (not (height ?from ?hf1)) (height ?from ?hf) (not (height ?to ?ht)) (height ?to ?ht1){cost})))
"""
NEG_DOMAIN = DOMAIN.format(costreq="", pred="", functions="", differ="(not (at ?o ?to))", cost="")
COST_DOMAIN = DOMAIN.format(costreq=" :action-costs", pred="", functions="(:functions (total-cost) - number)\n  ",
                            differ="(not (at ?o ?to))", cost=" (increase (total-cost) 2)")
# pyperplan takes no negative preconditions: "?from and ?to differ" as a static predicate instead
POS_DOMAIN = DOMAIN.format(costreq="", pred=" (differ ?a - location ?b - location)", functions="",
                           differ="(differ ?from ?to)", cost="").replace(" :negative-preconditions", "")
DIFFER = " ".join(f"(differ l{i} l{j})" for i in range(3) for j in range(3) if i != j)

# the tower b1 (bottom), b2, b3 at l0, rebuilt in reverse at l0: 7 moves (tower_optimum)
START = {"l0": ("b1", "b2", "b3"), "l1": (), "l2": ()}
REVERSED = "(at b3 l0) (level b3 h0) (at b2 l0) (level b2 h1) (at b1 l0) (level b1 h2)"


def problem(goal: str, *, metric: bool = False, differ: bool = False) -> str:
    """The toy problem from START (levels h0..h3) to `goal`; with metric, its total cost is minimised."""
    init = " ".join(f"(at {o} {loc}) (level {o} h{i})" for loc, stack in START.items() for i, o in enumerate(stack))
    init += " " + " ".join(f"(height {loc} h{len(stack)})" for loc, stack in START.items())
    init += (" (= (total-cost) 0)" if metric else "") + (" " + DIFFER if differ else "")
    return (f"(define (problem tower) (:domain toy-table)\n  (:objects b1 b2 b3 - block l0 l1 l2 - location "
            f"h0 h1 h2 h3 - tier)\n  (:init (succ h0 h1) (succ h1 h2) (succ h2 h3) {init})\n"
            f"  (:goal (and {goal})){' (:metric minimize (total-cost))' if metric else ''})\n")


def tower_optimum(start: dict, goal_stack: tuple, at: str) -> int:
    """Fewest moves of a top block from one location to another that leave goal_stack (bottom first) at `at`."""
    locs = sorted(start)
    s0 = tuple(start[loc] for loc in locs)
    dist, queue = {s0: 0}, deque([s0])
    while queue:
        s = queue.popleft()
        if s[locs.index(at)] == goal_stack:
            return dist[s]
        for f in range(len(s)):
            for t in range(len(s)):
                if f != t and s[f]:
                    n = list(s)
                    n[f], n[t] = s[f][:-1], s[t] + (s[f][-1],)
                    if tuple(n) not in dist:
                        dist[tuple(n)] = dist[s] + 1
                        queue.append(tuple(n))
    return -1


def action_id(step: str) -> int:
    """The robot action of a toy step: pick location * 6 + release location."""
    name, _o, frm, to, *_ = step.strip("()").split()
    if name != "pick-release":
        raise ValueError(f"unknown action {name!r}")
    return int(frm[1:]) * 6 + int(to[1:])


def action_ids(steps) -> list[int]:
    """The robot actions of a toy plan, one per step."""
    return [action_id(s) for s in steps]


@pytest.fixture(scope="module")
def toy(tmp_path_factory) -> Path:
    """A folder with the toy's domains and problems."""
    d = tmp_path_factory.mktemp("toy")
    files = {"domain.pddl": NEG_DOMAIN, "cost-domain.pddl": COST_DOMAIN, "pos-domain.pddl": POS_DOMAIN,
             "reverse.pddl": problem(REVERSED), "reverse-cost.pddl": problem(REVERSED, metric=True),
             "reverse-pos.pddl": problem(REVERSED, differ=True),
             # a block at level 3 needs three below it: there are only two others
             "unsolvable.pddl": problem("(level b1 h3)"), "unsolvable-pos.pddl": problem("(level b1 h3)", differ=True)}
    for name, text in files.items():
        (d / name).write_text(text)
    return d


@pytest.fixture(scope="module")
def validator():
    pyval = pytest.importorskip("pyval", reason="pddl-pyvalidator is not installed (the dev extra has it)")
    return pyval.PDDLValidator()


def validate(validator, domain: Path, problem_file: Path, steps, tmp_path: Path) -> str:
    """pyval's verdict ("VALID", "INVALID", ...) on the plan, written as a plan file."""
    plan = tmp_path / f"plan-{len(list(tmp_path.glob('plan-*')))}.txt"
    plan.write_text("".join(s + "\n" for s in steps))
    return validator.validate(str(domain), str(problem_file), str(plan)).status


def test_the_toy_optimum_is_seven_moves():
    assert tower_optimum(START, ("b3", "b2", "b1"), "l0") == 7
    assert tower_optimum(START, ("b3", "b2", "b1"), "l1") == 3  # the tower moved block by block ends reversed
    assert tower_optimum(START, ("b1", "b2", "b3"), "l1") == 5  # in order: the top two wait elsewhere
    assert tower_optimum(START, ("b1", "b1"), "l1") == -1


@pytest.mark.parametrize("planner", ["fd-lama-first", "fd-lmcut"])
def test_stock_fast_downward_solves_the_toy_and_its_plan_validates(toy, validator, tmp_path, planner):
    before = sorted(p.name for p in toy.iterdir())
    res = solve_files(toy / "domain.pddl", toy / "reverse.pddl", planner, timeout_s=30, action_ids=action_ids)
    assert res.status is PlanStatus.SOLVED, res.message
    assert validate(validator, toy / "domain.pddl", toy / "reverse.pddl", res.steps, tmp_path) == "VALID"
    assert res.plan == tuple(action_id(s) for s in res.steps) and all(s.startswith("(pick-release ") for s in res.steps)
    optimum = tower_optimum(START, ("b3", "b2", "b1"), "l0")
    assert len(res.steps) == optimum if STOCK_PLANNERS[planner].optimal else len(res.steps) >= optimum
    assert res.extra["plan_cost"] == len(res.steps) and res.extra["optimal"] is STOCK_PLANNERS[planner].optimal
    e = res.extra
    assert e["planner_time_s"] >= e["fd_translate_time_s"] >= 0 and e["fd_total_time_s"] >= e["fd_search_time_s"] >= 0
    # the translator sees one location, one level per block and one height per location: 9 variables, no axioms
    assert (e["translator_variables"], e["translator_uncovered_facts"], e["translator_axioms"]) == (9, 0, 0)
    assert res.expansions is not None and res.expansions >= 1
    assert sorted(p.name for p in toy.iterdir()) == before  # nothing written beside the inputs


def test_the_translator_statistics_tell_when_invariants_are_lost(toy, tmp_path):
    """Without the negative precondition a block may 'move' onto its own location, and the one-value-per-object
    invariants of at/level/height no longer hold: the counts reported are the translator's, not constants."""
    loose = tmp_path / "loose.pddl"
    loose.write_text(NEG_DOMAIN.replace("(not (at ?o ?to))", ""))
    res = solve_files(loose, toy / "reverse.pddl", "fd-lama-first", timeout_s=30)
    assert res.status is PlanStatus.SOLVED, res.message
    assert res.extra["translator_uncovered_facts"] > 0 and res.extra["translator_variables"] > 9


def test_action_costs_come_back_as_the_plan_cost(toy, validator, tmp_path):
    opt = solve_files(toy / "cost-domain.pddl", toy / "reverse-cost.pddl", "fd-lmcut", timeout_s=30)
    assert opt.status is PlanStatus.SOLVED, opt.message
    assert opt.extra["plan_cost"] == 2 * 7 == 2 * len(opt.steps)
    assert validate(validator, toy / "cost-domain.pddl", toy / "reverse-cost.pddl", opt.steps, tmp_path) == "VALID"
    sat = solve_files(toy / "cost-domain.pddl", toy / "reverse-cost.pddl", "fd-lama-first", timeout_s=30)
    assert sat.status is PlanStatus.SOLVED and sat.extra["plan_cost"] == 2 * len(sat.steps) >= opt.extra["plan_cost"]


def test_the_validator_rejects_wrong_plans(toy, validator, tmp_path):
    good = solve_files(toy / "domain.pddl", toy / "reverse.pddl", "fd-lmcut", timeout_s=30).steps
    d, p = toy / "domain.pddl", toy / "reverse.pddl"
    assert validate(validator, d, p, good, tmp_path) == "VALID"
    assert validate(validator, d, p, good[:-1], tmp_path) == "INVALID"  # every step applies; the goal is missed
    # b1 lies under b2 and b3: it cannot be picked
    assert validate(validator, d, p, ("(pick-release b1 l0 l1 h0 h1 h0 h1)",) + tuple(good), tmp_path) == "INVALID"
    assert validate(validator, d, p, tuple(reversed(good)), tmp_path) == "INVALID"


@pytest.mark.parametrize("planner", ["fd-lama-first", "fd-lmcut"])
def test_an_unsolvable_task_is_reported_unsolvable(toy, planner):
    res = solve_files(toy / "domain.pddl", toy / "unsolvable.pddl", planner, timeout_s=30)
    assert res.status is PlanStatus.UNSOLVABLE and res.steps == () and res.plan == (), res.message


def _live_cmdlines(*needles: str) -> list[str]:
    """Command lines of live processes that contain any of the needles."""
    found = []
    for pid in os.listdir("/proc"):
        if pid.isdigit():
            try:
                cmd = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if any(n in cmd for n in needles):
                found.append(cmd)
    return found


def _stock_folders() -> set[str]:
    """The planners' temporary folders in the temporary directory (a test's private one where it set one)."""
    return {p.name for p in Path(tempfile.gettempdir()).glob("symlearn-stock-*")}


@pytest.mark.skipif(not Path("/proc/self/cmdline").exists(), reason="needs /proc to list processes")
@pytest.mark.parametrize("limit", [0.05, 1.0])
def test_a_time_limit_reports_timeout_and_leaves_no_process_or_folder(tmp_path, limit, monkeypatch):
    """0.05 s stops the driver starting up; 1 s stops the translator or a blind search of a large task (8 blocks
    on 5 locations: about 20 million states), whatever the machine's speed.

    The call's temporary folder goes into a private directory, so its planner processes (whose command lines name
    files in it) and its folder are told apart from other runs' on the same machine."""
    private = tmp_path / "tmp"
    private.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(private))
    blocks, locs = [f"b{i}" for i in range(8)], [f"l{i}" for i in range(5)]
    levels = [f"h{i}" for i in range(10)]
    init = " ".join(f"(at {b} l0) (level {b} h{i})" for i, b in enumerate(blocks))
    init += " (height l0 h8) " + " ".join(f"(height {loc} h0)" for loc in locs[1:])
    init += " " + " ".join(f"(succ h{i} h{i + 1})" for i in range(9))
    # two blocks at one level of one location: unreachable, but not in the relaxation the translator computes (so it
    # cannot prove it at once), and blind search must exhaust the whole state space to say so
    goal = "(at b0 l4) (level b0 h1) (at b1 l4) (level b1 h1)"
    (tmp_path / "domain.pddl").write_text(NEG_DOMAIN)
    (tmp_path / "big.pddl").write_text(
        f"(define (problem big) (:domain toy-table) (:objects {' '.join(blocks)} - block {' '.join(locs)} - location "
        f"{' '.join(levels)} - tier) (:init {init}) (:goal (and {goal})))")
    assert _stock_folders() == set()
    res = solve_files(tmp_path / "domain.pddl", tmp_path / "big.pddl", "fd-blind", timeout_s=limit)
    assert res.status is PlanStatus.TIMEOUT, (res.status, res.message)
    assert f"{limit:g} s time limit" in res.message and "\n" not in res.message
    # where it stopped, as the closed loop reads it (a call stopped before search says its objects cannot be grounded
    # in that time): before search at 0.05 s, after the driver's start-up at 1 s
    assert res.extra["phase"] in (("start-up", "translation") if limit < 0.5 else ("translation", "search"))
    assert res.message.endswith(f"during {res.extra['phase']} (process group killed)")
    assert _live_cmdlines(str(tmp_path)) == []  # the private folder holds the planners' task files
    assert _stock_folders() == set()


def test_pyperplan_solves_the_strips_toy(toy, validator, tmp_path):
    before = sorted(p.name for p in toy.iterdir())
    res = solve_files(toy / "pos-domain.pddl", toy / "reverse-pos.pddl", "pyperplan", timeout_s=60,
                      action_ids=action_ids)
    assert res.status is PlanStatus.SOLVED, res.message
    assert validate(validator, toy / "pos-domain.pddl", toy / "reverse-pos.pddl", res.steps, tmp_path) == "VALID"
    assert len(res.plan) == len(res.steps) >= 7
    assert res.expansions >= len(res.steps)  # a forward search expands every state before the goal on its plan
    e = res.extra  # both phases' times, read from its log, lie within the process's wall-clock time
    assert e["planner_time_s"] >= e["pyperplan_search_time_s"] + e["pyperplan_ground_time_s"] > 0, e
    opt = solve_files(toy / "pos-domain.pddl", toy / "reverse-pos.pddl", "pyperplan-opt", timeout_s=60)
    assert opt.status is PlanStatus.SOLVED and len(opt.steps) == 7, opt.message
    unsolvable = solve_files(toy / "pos-domain.pddl", toy / "unsolvable-pos.pddl", "pyperplan", timeout_s=60)
    assert unsolvable.status is PlanStatus.UNSOLVABLE, unsolvable.message
    assert sorted(p.name for p in toy.iterdir()) == before  # pyperplan's .soln went to the run's own folder


def test_pyperplan_refuses_negative_preconditions_in_one_line(toy):
    res = solve_files(toy / "domain.pddl", toy / "reverse.pddl", "pyperplan", timeout_s=60)
    assert res.status is PlanStatus.ERROR and "\n" not in res.message
    assert res.message.startswith("pyperplan: exited with code 1: ") and "precondition" in res.message


@pytest.mark.parametrize("broken, says", [
    (NEG_DOMAIN.rstrip()[:-1], "Missing ')'"),  # one closing parenthesis short
    (NEG_DOMAIN.replace("(level ?o ?hf) (succ", "(level ?o ?hf) (shiny ?o) (succ"), "shiny"),  # an undeclared predicate
])
def test_a_malformed_domain_gives_the_translators_reason(toy, tmp_path, broken, says):
    (tmp_path / "bad.pddl").write_text(broken)
    res = solve_files(tmp_path / "bad.pddl", toy / "reverse.pddl", "fd-lama-first", timeout_s=30)
    assert res.status is PlanStatus.ERROR and "\n" not in res.message
    assert res.message.startswith("fd-lama-first: the translator rejected the input: ") and says in res.message


def test_refusals_before_any_work(toy, tmp_path):
    with pytest.raises(ValueError, match="timeout_s"):
        solve_files(toy / "domain.pddl", toy / "reverse.pddl", "fd-lmcut", timeout_s=0)
    unknown = solve_files(toy / "domain.pddl", toy / "reverse.pddl", "fd-nonsense", timeout_s=5)
    assert unknown.status is PlanStatus.ERROR and "fd-lama-first" in unknown.message
    missing = solve_files(toy / "domain.pddl", tmp_path / "p99.pddl", "fd-lmcut", timeout_s=5)
    assert missing.status is PlanStatus.ERROR and missing.message == f"problem file not found: {tmp_path / 'p99.pddl'}"
    assert solve_files(tmp_path, toy / "reverse.pddl", "fd-lmcut", timeout_s=5).message.startswith("domain is not")


def test_steps_that_map_to_no_action_are_an_error(toy):
    def strict(step: str) -> int:
        raise KeyError(step)

    res = solve_files(toy / "domain.pddl", toy / "reverse.pddl", "fd-lmcut", timeout_s=30,
                      action_ids=lambda steps: [strict(s) for s in steps])
    assert res.status is PlanStatus.ERROR and "maps to no action" in res.message
    out_of_range = solve_files(toy / "domain.pddl", toy / "reverse.pddl", "fd-lmcut", timeout_s=30,
                               action_ids=lambda steps: [99 for _ in steps])
    assert out_of_range.status is PlanStatus.ERROR and "0..35" in out_of_range.message


def test_lmcut_refuses_conditional_effects_with_its_reason(tmp_path, toy):
    riders = NEG_DOMAIN.replace(":negative-preconditions", ":negative-preconditions :conditional-effects").replace(
        "(height ?to ?ht1)))", "(height ?to ?ht1)\n   (forall (?r - block) (when (at ?r ?to) (not (level ?r ?ht1))))))")
    (tmp_path / "riders.pddl").write_text(riders)
    res = solve_files(tmp_path / "riders.pddl", toy / "reverse.pddl", "fd-lmcut", timeout_s=30)
    assert res.status is PlanStatus.ERROR and "does not support conditional effects" in res.message
    ms = solve_files(tmp_path / "riders.pddl", toy / "reverse.pddl", "fd-ms", timeout_s=30)
    assert ms.status is PlanStatus.SOLVED and len(ms.steps) == 7, ms.message


def test_texts_plan_like_files(toy):
    files = solve_files(toy / "domain.pddl", toy / "reverse.pddl", "fd-lmcut", timeout_s=30)
    texts = solve_texts(NEG_DOMAIN, problem(REVERSED), "fd-lmcut", timeout_s=30)
    assert texts.status is PlanStatus.SOLVED and texts.steps == files.steps


def test_plan_result_keeps_steps_through_json():
    r = PlanResult(planner="fd-lmcut", status=PlanStatus.SOLVED, plan=(2,), predicted_states=(), expansions=3,
                   planning_time_s=0.1, steps=("(pick-release b1 l0 l2)",))
    assert PlanResult.from_json(r.to_json()) == r and r.to_json()["steps"] == ["(pick-release b1 l0 l2)"]
    assert "steps" not in PlanResult(planner="astar", status=PlanStatus.SOLVED, plan=(), predicted_states=(),
                                     expansions=None, planning_time_s=0.0).to_json()
    with pytest.raises(ValueError, match="must cover the plan's actions: 2 actions, 1 steps"):
        PlanResult(planner="x", status=PlanStatus.SOLVED, plan=(2, 3), predicted_states=(), expansions=None,
                   planning_time_s=0.0, steps=("(a)",))
    with pytest.raises(ValueError, match="only allowed with status solved"):
        PlanResult(planner="x", status=PlanStatus.TIMEOUT, plan=(), predicted_states=(), expansions=None,
                   planning_time_s=0.0, steps=("(a)",))


def _bench():
    import importlib.util

    path = Path(__file__).resolve().parent.parent / "bench" / "stock_fd.py"
    spec = importlib.util.spec_from_file_location("stock_fd", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_stock_fd_bench_records_each_problem_and_resumes(toy, tmp_path, monkeypatch, capsys):
    import json

    import search.stock_planners as sp

    bench, out = _bench(), tmp_path / "stock.json"
    argv = ["--domain", str(toy / "domain.pddl"), "--problems", f"{toy / 'reverse.pddl'},{toy / 'unsolvable.pddl'}",
            "--planners", "fd-lama-first,fd-lmcut", "--out", str(out)]
    assert bench.main(argv) == 0
    rec = json.loads(out.read_text())
    assert rec["complete"] and [r["problem"] for r in rec["rows"]] == [str(toy / "reverse.pddl"),
                                                                       str(toy / "unsolvable.pddl")]
    lmcut = rec["rows"][0]["planners"]["fd-lmcut"]
    assert lmcut["status"] == "solved" and lmcut["plan_length"] == 7 and lmcut["translator_uncovered_facts"] == 0
    assert lmcut["translate_plus_search_s"] == pytest.approx(lmcut["fd_translate_time_s"] + lmcut["fd_total_time_s"],
                                                             abs=1e-3)
    assert {k: rec["summary"]["fd-lmcut"][k] for k in ("problems", "solved", "unsolvable", "timeout", "error")} == \
        {"problems": 2, "solved": 1, "unsolvable": 1, "timeout": 0, "error": 0}

    def no_planning(*a, **k):
        raise AssertionError("a finished problem was planned again")

    monkeypatch.setattr(sp, "solve_files", no_planning)  # the same arguments again: every row is kept
    assert bench.main(argv) == 0 and json.loads(out.read_text())["rows"] == rec["rows"]
    capsys.readouterr()
    assert bench.main(["--domain", str(tmp_path / "none.pddl"), "--problems", str(toy), "--out", str(out)]) == 2
    assert capsys.readouterr().err.strip() == f"stock_fd: domain file not found: {tmp_path / 'none.pddl'}"


def test_the_stock_fd_bench_runs_the_up_route_and_counts_reachable_goals_reported_unsolvable(toy, tmp_path, capsys):
    import json

    bench, out = _bench(), tmp_path / "stock.json"
    # as export-learned-problems writes it: the simulator's shortest length per problem file (here: the unsolvable
    # problem is said to be reachable, as a misread learned state would make it)
    man = tmp_path / "problems.json"
    man.write_text(json.dumps({"rows": [{"file": "reverse.pddl", "shortest": 7}, {"file": "unsolvable.pddl",
                                                                                  "shortest": 3}]}))
    argv = ["--domain", str(toy / "domain.pddl"), "--problems", f"{toy / 'reverse.pddl'},{toy / 'unsolvable.pddl'}",
            "--planners", "fd-lmcut,up-fast-downward", "--shortest", str(man), "--out", str(out)]
    assert bench.main(argv) == 0
    rec = json.loads(out.read_text())
    assert [r["shortest"] for r in rec["rows"]] == [7, 3]
    for name in ("fd-lmcut", "up-fast-downward"):
        s = rec["summary"][name]
        assert (s["solved"], s["unsolvable"], s["reachable_reported_unsolvable"]) == (1, 1, 1), (name, s)
    assert rec["summary"]["fd-lmcut"]["plan_over_shortest"] == pytest.approx(1.0)
    assert rec["rows"][0]["planners"]["up-fast-downward"]["plan_length"] >= 7  # validated by UP's PlanValidator
    capsys.readouterr()
    man.write_text(json.dumps({"rows": [{"file": "reverse.pddl", "shortest": 7}]}))
    assert bench.main([*argv[:-2], "--out", str(tmp_path / "other.json")]) == 2
    assert capsys.readouterr().err.strip() == f"stock_fd: {man} has no shortest length for unsolvable.pddl"
    man.write_text("[1, 2]")
    assert bench.main([*argv[:-2], "--out", str(tmp_path / "other.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"stock_fd: {man} is not a problems.json") and not (tmp_path / "other.json").exists()


def test_the_stock_fd_bench_plans_a_focus_problem_first_and_the_whole_one_where_it_finds_none(toy, tmp_path, capsys):
    import json
    import shutil

    from symlearn.planning.learned_calls import FOCUS_SHARE

    bench, out, focus = _bench(), tmp_path / "stock.json", tmp_path / "focus"
    assert bench.FOCUS_SHARE == FOCUS_SHARE  # outside the loop as inside it
    focus.mkdir()
    # a focus problem of reverse.pddl that has no plan (as one whose goal needs another object moved would):
    # the whole problem is planned in the time left; unsolvable.pddl has no focus problem and is planned alone
    shutil.copy(toy / "unsolvable.pddl", focus / "reverse.pddl")
    argv = ["--domain", str(toy / "domain.pddl"), "--problems", f"{toy / 'reverse.pddl'},{toy / 'unsolvable.pddl'}",
            "--planners", "fd-lmcut", "--focus", str(focus), "--out", str(out)]
    assert bench.main(argv) == 0
    rows = json.loads(out.read_text())["rows"]
    first, second = (r["planners"]["fd-lmcut"] for r in rows)
    assert first["focus"] == "unsolvable" and first["status"] == "solved" and first["plan_length"] == 7
    assert first["call_time_s"] > first["fd_translate_time_s"] > 0  # two calls' clocks summed
    assert second["status"] == "unsolvable" and "focus" not in second
    # a focus problem that plans: its plan stands, and the row's key records the focus file
    shutil.copy(toy / "reverse.pddl", focus / "reverse.pddl")
    assert bench.main([*argv[:-2], "--out", str(tmp_path / "b.json")]) == 0
    rec = json.loads((tmp_path / "b.json").read_text())
    assert rec["rows"][0]["planners"]["fd-lmcut"]["focus"] == "solved" and "+" in rec["rows"][0]["sha256"]
    assert rec["summary"]["fd-lmcut"]["focus_solved"] == 1 and rec["focus"] == str(focus)
    capsys.readouterr()
    assert bench.main([*argv[:-3], str(tmp_path / "none"), "--out", str(tmp_path / "c.json")]) == 2
    assert capsys.readouterr().err.strip() == f"stock_fd: --focus folder not found: {tmp_path / 'none'}"
    # the problems' own folder, or one with no file of a problem's name: refused in one line, nothing planned
    assert bench.main([*argv[:-3], str(toy), "--out", str(tmp_path / "c.json")]) == 2
    assert "holds the problems themselves" in capsys.readouterr().err
    (tmp_path / "other").mkdir()
    assert bench.main([*argv[:-3], str(tmp_path / "other"), "--out", str(tmp_path / "c.json")]) == 2
    assert "has the name of a problem" in capsys.readouterr().err and not (tmp_path / "c.json").exists()
