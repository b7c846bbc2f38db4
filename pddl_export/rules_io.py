"""Read and write distilled rules as JSON (RUN/pddl/rules.json); codes are bit strings, MSB first.

    >>> from pddl_export.rules import Rule, RuleSet
    >>> rs = RuleSet(2, (1, 2), 2, (Rule(5, 1, 2, forbids=(3,)),), 1)
    >>> rules_to_json(rs)["rules"][0]["from"], rules_from_json(rules_to_json(rs)).rules == rs.rules
    ('01', True)
"""
from __future__ import annotations

import contextlib
import gc
import json
from pathlib import Path

from pddl_export.rules import Rule, RuleSet
from pddl_export.symbolic import code_str

PDDL_DIR = "pddl"  # RUN/pddl holds domain.pddl, rules.json and report.json
RULES_FILE = "rules.json"


def rules_to_json(rules: RuleSet) -> dict:
    """The rules as a JSON-ready dict (codes as bit strings, actions also as pick/release)."""
    b = rules.bits
    return {"bits": b, "vocabulary": [code_str(c, b) for c in rules.vocabulary], "max_objects": rules.max_objects,
            "n_rules_before_generalization": rules.n_rules_before_generalization,
            "rules": [{"action": r.action, "pick": r.action // 6, "release": r.action % 6,
                       "from": code_str(r.code_from, b), "to": code_str(r.code_to, b),
                       "requires": [code_str(c, b) for c in r.requires], "forbids": [code_str(c, b) for c in r.forbids],
                       "at_least": [[code_str(c, b), n] for c, n in r.at_least],
                       "fewer_than": [[code_str(c, b), n] for c, n in r.fewer_than]} for r in rules.rules]}


FREEZE_BYTES = 20_000_000  # a rules file this big is loaded to stay: its objects leave the collector's sight


@contextlib.contextmanager
def paused_gc(freeze: bool = False):
    """No cyclic garbage collection inside the block: loading builds millions of acyclic objects, and the
    collector's passes over them took a third of the time (6.9 against 4.4 s for 327k rules).

    With `freeze`, one collection runs first (so that no garbage is kept), and when the block ends well every
    object then tracked, what it built and what lived before, goes to the permanent generation (gc.freeze):
    otherwise the collector's later passes over ten million objects land inside a planner's first call (1.2 s
    instead of 0.2 s for 1-5-object rules). Acyclic objects are still freed when their last reference goes.
    """
    was = gc.isenabled()
    if freeze:
        gc.collect()
    gc.disable()
    try:
        yield
        if freeze:
            gc.freeze()
    finally:
        if was:
            gc.enable()


class _CodeStrings(dict):
    """Bit string -> code, each distinct string parsed once."""

    def __missing__(self, s: str) -> int:
        self[s] = value = int(s, 2)
        return value


def rules_from_json(d: dict) -> RuleSet:
    """Inverse of rules_to_json; refuses malformed files with a one-line error."""
    try:
        c = _CodeStrings().__getitem__  # a file names a few hundred codes millions of times
        rules = tuple(Rule(int(r["action"]), c(r["from"]), c(r["to"]), tuple(map(c, r["requires"])),
                           tuple(map(c, r["forbids"])), tuple((c(x), int(n)) for x, n in r["at_least"]),
                           tuple((c(x), int(n)) for x, n in r["fewer_than"])) for r in d["rules"])
        return RuleSet(int(d["bits"]), tuple(map(c, d["vocabulary"])), int(d["max_objects"]), rules,
                       int(d["n_rules_before_generalization"]))
    except KeyError as e:
        raise ValueError(f"malformed rules file: missing field {e}") from None
    except (TypeError, ValueError, AttributeError) as e:
        raise ValueError(f"malformed rules file: {type(e).__name__}: {e}") from None


def _read_rules_json(path: Path, run_dir: Path) -> dict:
    """The JSON object of a rules file; one-line ValueError naming the file if it is not one."""
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not valid JSON (line {e.lineno}, column {e.colno}: {e.msg}); "
                         f"re-run 'symlearn export-pddl --run {run_dir}'") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: cannot be read: {type(e).__name__}: {e}") from None
    if not isinstance(d, dict):
        raise ValueError(f"{path}: not a rules file (a JSON {type(d).__name__}, expected an object with "
                         f"'bits', 'vocabulary', 'max_objects' and 'rules')")
    return d


def load_rules(run_dir: Path) -> tuple[RuleSet, str]:
    """RUN/pddl/rules.json and the model hash recorded with it; ValueError (one line, naming the file) if unreadable."""
    path = Path(run_dir) / PDDL_DIR / RULES_FILE
    if not path.exists():
        raise ValueError(f"no exported rules at {path}; run 'symlearn export-pddl --run {run_dir}' first")
    with paused_gc(freeze=path.stat().st_size >= FREEZE_BYTES):
        d = _read_rules_json(path, run_dir)
        try:
            rules = rules_from_json(d)
        except ValueError as e:
            raise ValueError(f"{path}: {e}") from None
    model_hash = d.get("model_hash", "")
    if not isinstance(model_hash, str):
        raise ValueError(f"{path}: malformed rules file: model_hash must be a string, got {model_hash!r}")
    return rules, model_hash
