"""Settings of the lifted export side by side: accuracy on the validation splits, stock Fast Downward's time.

The lifted export (symlearn/export/lifted_export.py) trades how often its rules predict what the robot saw next
against the time Fast Downward's translator spends on the domain; the presets `fast` and `accurate` are two points
of that trade. This script puts any settings beside them, on one reading of the run's training moves:

- each setting's rules are checked on the data sets' validation splits (the test splits stay for export-pddl's
  report), against the observed next codes, beside m(z)'s own accuracy;
- each setting's domain is solved with stock lama-first on every problem of one set (problems/dev: the set the
  recipe is chosen on), the settings interleaved problem by problem in one process, the order rotated, so that
  the ratios of their medians to the first setting's share the machine's load;
- with --probe-sticks, each setting also runs as its domain without the stick moves (the cube rules alone, the
  same problems): not a domain to plan with, a measure of what the stick schemas cost the translator.

    symlearn export-pddl ... (once, for the run's data), then
    python experiments/preset_sweep.py --run RUN --data data/paper_a data/k15 --problems problems/dev \
        --setting fast= --setting accurate=pool_min_count:20,end_min_count:6,pair_min_count:8 \
        --setting cubes20=pool_min_count:20,pool_classes:cube,pool_structure_min:20 --probe-sticks \
        --out bench/results/preset_sweep_dev.json

A setting is NAME=FIELD:VALUE,... over LiftedConfig's fields (pool_classes joined with +); empty: the defaults.
An interrupted run resumes from --out (the calls of the same run, problems, settings and domain texts are kept).
"""
from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import statistics
from pathlib import Path

from search.stock_planners import call_record

STICK_PROBE = "{}-without-sticks"


def parse_setting(spec: str):
    """NAME=FIELD:VALUE,... -> (NAME, LiftedConfig); SystemExit naming the bad part."""
    from symlearn.export.lifted_export import LiftedConfig

    name, sep, body = spec.partition("=")
    if not sep or not name:
        raise SystemExit(f"preset_sweep: --setting {spec!r} must be NAME=FIELD:VALUE,...")
    fields = {f.name: f.type for f in dataclasses.fields(LiftedConfig)}
    kw: dict = {}
    for item in filter(None, body.split(",")):
        key, sep, value = item.partition(":")
        if not sep or key not in fields:
            raise SystemExit(f"preset_sweep: --setting {name}: {item!r} is no FIELD:VALUE of LiftedConfig "
                             f"({', '.join(fields)})")
        if key == "pool_classes":
            kw[key] = tuple(value.split("+"))
        elif key == "source":
            kw[key] = value
        else:
            try:
                kw[key] = float(value) if key in ("min_gain", "min_info") else int(value)
            except ValueError:
                raise SystemExit(f"preset_sweep: --setting {name}: {key} needs a number, not {value!r}") from None
    try:
        return name, LiftedConfig(**kw)
    except ValueError as e:
        raise SystemExit(f"preset_sweep: --setting {name}: {e}") from None


def parse_settings(specs: list[str], script: str) -> dict:
    """Several --setting values -> {NAME: LiftedConfig}; SystemExit if two share a name, or if they differ in
    source or min_info (the settings are distilled from one reading of the training moves)."""
    settings = dict(parse_setting(s) for s in specs)
    if len(settings) != len(specs):
        raise SystemExit(f"{script}: two --setting share a name")
    first = next(iter(settings.values()))
    if any((c.source, c.min_info) != (first.source, first.min_info) for c in settings.values()):
        raise SystemExit(f"{script}: every setting needs the same source and min_info (one reading of the moves)")
    return settings


def cubes_only(rules):
    """The same rules without any stick move (the --probe-sticks form)."""
    keep = tuple(r for r in rules.rules if dict(r.key)["cls"] == "cube")
    return dataclasses.replace(rules, rules=keep, end_rules=())


def fast_downward_summary(calls: list[dict], names: list[str], settings) -> dict:
    """Per form: its calls' statuses, translate + search median and max, translator median, median operators at
    the most objects, the ratio of its median to the first form's on the problems both timed, and for a stick
    probe its translator time beside its setting's on the same ground tasks."""
    report: dict = {}
    base = names[0]
    by_problem: dict = {}
    for c in calls:
        by_problem.setdefault(c["problem"], {})[c["form"]] = c
    for form in names:
        mine = [c for c in calls if c["form"] == form]
        ts = [c["translate_plus_search_s"] for c in mine if c["translate_plus_search_s"] is not None]
        tr = [c["fd_translate_time_s"] for c in mine if c["fd_translate_time_s"] is not None]
        top = max(c["objects"] for c in mine)
        ops = [c["translator_operators"] for c in mine if c["objects"] == top and c["translator_operators"]]
        both = [(p[form]["translate_plus_search_s"], p[base]["translate_plus_search_s"]) for p in by_problem.values()
                if form in p and base in p and None not in (p[form]["translate_plus_search_s"],
                                                            p[base]["translate_plus_search_s"])]
        entry = {"calls": len(mine), "status": {s: sum(c["status"] == s for c in mine)
                                                for s in ("solved", "unsolvable", "timeout", "error")},
                 "translate_plus_search_s": {"median": round(statistics.median(ts), 4), "max": round(max(ts), 4)}
                 if ts else None,
                 "translate_s_median": round(statistics.median(tr), 4) if tr else None,
                 f"operators_median_at_{top}_objects": statistics.median(ops) if ops else None,
                 f"median_over_{base}": round(statistics.median(a for a, _ in both)
                                              / max(statistics.median(b for _, b in both), 1e-9), 3) if both else None}
        owner = next((s for s in settings if STICK_PROBE.format(s) == form), None)
        if owner is not None:  # the probe refuses what needs a stick at once: compare the same ground tasks, the
            # problems both solve with the same operators (no stick action applies: the schemas ground to nothing)
            same = [(p[form], p[owner]) for p in by_problem.values()
                    if form in p and owner in p and p[form]["status"] == p[owner]["status"] == "solved"
                    and p[form]["translator_operators"] == p[owner]["translator_operators"]]
            entry["same_ground_task"] = {
                "problems": len(same),
                "translate_s_median": round(statistics.median(a["fd_translate_time_s"] for a, _ in same), 4),
                f"translate_s_median_of_{owner}": round(statistics.median(b["fd_translate_time_s"] for _, b in same), 4),
            } if same else None
        report[form] = entry
    return report


def print_report(report: dict, base: str) -> None:
    """One line per form: validation accuracy beside m(z)'s, lama-first's median and max, its ratio to base."""
    for form, r in report.items():
        fd = r["fast_downward"]
        acc = "; ".join(f"{d} {v['all']['rules']:.3f} (m(z) {v['all']['m(z)']:.3f})"
                        for d, v in r.get("val_accuracy", {}).items())
        t = fd["translate_plus_search_s"] or {}
        both = fd.get("same_ground_task")
        probe = "" if not both else (f"; on the {both['problems']} same ground tasks the translator takes "
                                     f"{both['translate_s_median']} s, with the stick schemas "
                                     f"{next(v for k, v in both.items() if k.startswith('translate_s_median_of_'))} s")
        print(f"{form}: {acc or 'probe'}; lama-first median {t.get('median')} s, max {t.get('max')} s, "
              f"x{fd[f'median_over_{base}']} of {base}, {fd['status']}{probe}")


def solve_all(problems, forms: dict, texts: dict, reader, planner: str, timeout: float, calls: list[dict],
              checkpoint) -> None:
    """Every form (forms: name -> rules; texts: name -> (domain, static facts)) on every problem the calls do not
    hold yet, the order rotated from problem to problem; each call appended to calls, checkpoint() after each
    problem."""
    from pddl_export.lifted_problem import problem_pddl
    from search.stock_planners import solve_texts
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.scenes import scene_codes, symbolic_goal

    done = {(c["problem"], c["form"]) for c in calls}
    sim = TabletopSimulator()
    try:
        for n, (path, problem) in enumerate(problems):
            todo = [f for f in forms if (path.name, f) not in done]
            if not todo:
                continue
            goal = symbolic_goal(sim, reader, problem)
            start = [int(c) for c in scene_codes(sim, reader, problem.initial)]
            shift = n % len(todo)
            for form in todo[shift:] + todo[:shift]:  # the order rotates from problem to problem
                domain, statics = texts[form]
                text = problem_pddl(forms[form], start, goal, f"p{n + 1:02d}", statics=statics)
                rec = call_record(solve_texts(domain, text, planner, timeout))
                calls.append({"problem": path.name, "objects": problem.k, "form": form,
                              **{k: rec.get(k) for k in ("status", "translate_plus_search_s", "fd_translate_time_s",
                                                         "translator_operators", "call_time_s")}})
            checkpoint()  # resumable per problem
    finally:
        sim.close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True, type=Path, help="a run with m(z) on 9 location bits")
    ap.add_argument("--data", required=True, type=Path, nargs="+", help="the data sets export-pddl reads")
    ap.add_argument("--problems", required=True, type=Path, help="a problem folder (symlearn problems)")
    ap.add_argument("--setting", action="append", required=True, help="NAME=FIELD:VALUE,... (repeat; the first "
                    "is the baseline of the ratios)")
    ap.add_argument("--probe-sticks", action="store_true", help="also each domain without its stick moves")
    ap.add_argument("--planner", default="fd-lama-first", help="a search.stock_planners name")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds per call")
    ap.add_argument("--out", required=True, type=Path)
    args = ap.parse_args(argv)
    settings = parse_settings(args.setting, "preset_sweep")
    for d in args.data:
        if not d.is_dir():
            raise SystemExit(f"preset_sweep: no data set at {d}")

    from pddl_export.bounded_json import read_json_file
    from pddl_export.files import sha256_file
    from pddl_export.lifted_domain import domain_pddl, schemas, static_facts
    from pddl_export.lifted_moves import moves
    from symlearn.export.lifted_export import check_lifted, distil_rules, network_steps, split_codes, \
        training_moves
    from symlearn.problems.problem import load_problems
    from symlearn.provenance import atomic_write_json, bench_context
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    problems = load_problems(args.problems)  # refuses a missing or empty folder before any work
    reader, transition = planning_models(args.run)
    model_hash = sha256_file(args.run / TRANSITION_FILE)[:16]
    key = {"run_model_hash": model_hash, "problems": str(args.problems), "planner": args.planner,
           "timeout_s": args.timeout, "settings": {n: dataclasses.asdict(c) for n, c in settings.items()},
           "data": [str(d) for d in args.data], "probe_sticks": args.probe_sticks}

    seen = training_moves(reader, transition, list(args.data), next(iter(settings.values())))
    val = [(d, split_codes(reader, d, "val")) for d in args.data]
    val_net = [network_steps(transition, s.before, s.action, s.mask) for _, s in val]
    forms, texts, report = {}, {}, {}  # texts: each form's domain and static facts, written once
    for name, cfg in settings.items():
        rules = distil_rules(seen, cfg, model_hash)
        checks = {d.name: check_lifted(rules, s, n) for (d, s), n in zip(val, val_net)}
        forms[name] = rules
        if args.probe_sticks:
            forms[STICK_PROBE.format(name)] = cubes_only(rules)
        texts[name] = (domain_pddl(rules), static_facts(moves(rules)))
        report[name] = {"domain_bytes": len(texts[name][0].encode()), "schemas": len(schemas(rules)),
                        "rules": len(rules.rules),
                        "pooled_rules": sum(r.pool is not None for r in rules.rules),
                        "end_rules": len(rules.end_rules),
                        "val_accuracy": {d: {g: {"rules": c[g]["accuracy_rules"], "m(z)": c[g]["accuracy_net"],
                                                 "cases": c[g]["cases"]} for g in c} for d, c in checks.items()}}
    texts.update({f: (domain_pddl(r), static_facts(moves(r))) for f, r in forms.items() if f not in texts})
    names = list(forms)
    # a resumed run keeps the calls of the same forms as written now (another writer's domain is another form)
    key["domains_sha256"] = {f: hashlib.sha256(texts[f][0].encode()).hexdigest()[:16] for f in names}
    old = read_json_file(args.out, what="sweep", max_bytes=64 << 20) if args.out.is_file() else {}
    key = json.loads(json.dumps(key))  # as the file holds it (tuples as lists), so that a resumed run matches
    calls = old.get("calls", []) if all(old.get(k) == v for k, v in key.items()) else []
    solve_all(problems, forms, texts, reader, args.planner, args.timeout, calls,
              lambda: atomic_write_json(args.out, {**key, "calls": calls, **bench_context()}))

    for form, entry in fast_downward_summary(calls, names, settings).items():
        report.setdefault(form, {})["fast_downward"] = entry
    atomic_write_json(args.out, {**key, "summary": report, "calls": calls, **bench_context()})
    print_report(report, names[0])
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
