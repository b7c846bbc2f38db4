"""Summarise training runs side by side: effect and rider errors, symbol stability, Table I, symbols, rollouts.

Reads each run folder's eval.json, table1.json, symbols.json and transition_metrics.json (whichever exist) and
writes one JSON plus a markdown table, so lever runs (bench/gpu_levers.sh) can be compared with each other and
with earlier runs.

    python bench/levers_summary.py RUNS_DIR --out bench/results/levers.json
"""
from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
from pathlib import Path

SUMMARY_STEPS = ("1", "3", "5", "8")
SEEDED = re.compile(r"(.+)_s(\d+)")  # a run of a seed series: <prefix>_s<seed>


def _read(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def run_summary(run: Path) -> dict:
    """One run's headline numbers; None where its stage did not finish."""
    cfg = (_read(run / "config.json") or {}).get("train_config", {})
    metrics = _read(run / "metrics.json") or {}
    ev, t1 = _read(run / "eval.json"), _read(run / "table1.json")
    sy, tr = _read(run / "symbols.json"), _read(run / "transition_metrics.json")
    rollout = (tr or {}).get("test", {}).get("rollout", {})
    return {
        "run": run.name, "preset": cfg.get("preset"), "seed": cfg.get("seed"),
        "attention": cfg.get("model", {}).get("attention"),
        "levers": {k: cfg.get(k) for k in ("rider_weight", "dynamics_weight", "stability_weight", "distinct_weight")},
        "epochs_done": len(metrics.get("history", [])), "epochs": cfg.get("epochs"),
        "effect_mae_mm": (ev or {}).get("effect_mae_mm"),
        "rider_mae_mm": ((ev or {}).get("riders") or {}).get("effect_mae_mm"),
        "baseline_rider_mae_mm": (((ev or {}).get("ablations", {}).get("no_attention") or {}).get("riders") or {}).get(
            "effect_mae_mm"),
        "code_stability": (ev or {}).get("code_stability"),
        "table1": (t1 or {}).get("criteria"),
        "table1_rider_y_mm": _rider_y(t1),
        "symbols_95": (sy or {}).get("n_symbols_for_95pct"), "symbols_distinct": (sy or {}).get("n_distinct"),
        "rollout_scene_accuracy": {n: rollout[n]["scene_accuracy"] for n in SUMMARY_STEPS if n in rollout} or None,
    }


def _rider_y(t1: dict | None) -> list | None:
    """Predicted y (mm) of Table I's riders (objects with a rider criterion), case by case."""
    if not t1:
        return None
    return [round(o["predicted_mm"][1]) for c in t1.get("cases", []) for o in c.get("objects", [])
            if "rider_y_within_50mm" in o.get("criteria", {})]


def _fmt(v, key=None) -> str:
    if v is None:
        return "-"
    if isinstance(v, dict) and key:
        v = v.get(key)
    if isinstance(v, dict):
        return " / ".join(f"{x:.1f}" if isinstance(x, float) else str(x) for x in v.values())
    return str(v)


def markdown(rows: list[dict]) -> str:
    """The summary as a markdown table, one row per run."""
    head = ("| run | epochs | effect MAE x/y/z mm | rider MAE x/y/z mm | baseline rider | still codes kept | "
            "Table I motion | riders y (50 mm) | symbols 95% | rollout 1/3/5/8 |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        t1 = r["table1"] or {}
        cs = r["code_stability"] or {}
        ro = r["rollout_scene_accuracy"] or {}
        lines.append(
            f"| {r['run']} | {r['epochs_done']}/{r['epochs']} | {_fmt(r['effect_mae_mm'])} | {_fmt(r['rider_mae_mm'])} | "
            f"{_fmt(r['baseline_rider_mae_mm'])} | {_fmt(cs.get('code_unchanged'))} | {t1.get('objects_motion_right', '-')} | "
            f"{t1.get('riders_right', '-')} {r['table1_rider_y_mm'] or ''} | {_fmt(r['symbols_95'])} | "
            f"{' / '.join(_fmt(ro.get(n)) for n in SUMMARY_STEPS)} |")
    return "\n".join(lines)


def seed_stats(rows: list[dict], prefix: str) -> dict:
    """Mean and std over the runs named prefix_s<seed> of effect MAE, rider MAE, stability and rollout at 5."""
    sel = [r for r in rows if (m := SEEDED.fullmatch(r["run"])) and m.group(1) == prefix]

    def ms(values):
        values = [v for v in values if v is not None]
        if not values:
            return None
        return {"mean": round(statistics.fmean(values), 3),
                "std": round(statistics.stdev(values), 3) if len(values) > 1 else 0.0, "n": len(values)}

    out = {"runs": [r["run"] for r in sel]}
    for axis in "xyz":
        out[f"effect_mae_{axis}"] = ms([(r["effect_mae_mm"] or {}).get(axis) for r in sel])
        out[f"rider_mae_{axis}"] = ms([(r["rider_mae_mm"] or {}).get(axis) for r in sel])
    out["still_codes_kept"] = ms([(r["code_stability"] or {}).get("code_unchanged") for r in sel])
    out["rollout_5"] = ms([(r["rollout_scene_accuracy"] or {}).get("5") for r in sel])
    out["table1_motion_met"] = sum(bool((r["table1"] or {}).get("motion_right")) for r in sel)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", help="folder holding run folders")
    ap.add_argument("--out", required=True, help="JSON to write (a .md beside it gets the table)")
    args = ap.parse_args(argv)
    runs = sorted(p for p in Path(args.runs).iterdir() if (p / "config.json").exists())
    if not runs:
        print(f"error: no run folders (with config.json) in {args.runs}", file=sys.stderr)
        return 2
    rows = [run_summary(r) for r in runs]
    prefixes = sorted({m.group(1) for r in rows if (m := SEEDED.fullmatch(r["run"]))})
    result = {"runs": rows, "over_seeds": {p: seed_stats(rows, p) for p in prefixes}}
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(result, indent=2))
    tmp.replace(out)
    out.with_suffix(".md").write_text(markdown(rows) + "\n")
    print(markdown(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
