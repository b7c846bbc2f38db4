"""Read and write distilled rules as JSON (RUN/pddl/rules.json); codes are bit strings, MSB first.

    >>> from pddl_export.rules import Rule, RuleSet
    >>> rs = RuleSet(2, (1, 2), 2, (Rule(5, 1, 2, forbids=(3,)),), 1)
    >>> rules_to_json(rs)["rules"][0]["from"], rules_from_json(rules_to_json(rs)).rules == rs.rules
    ('01', True)
"""
from __future__ import annotations

import contextlib
import gc
from pathlib import Path

from pddl_export.bounded_json import JsonFileError, MiB, read_json_file
from pddl_export.rules import COUNT_CAP, Rule, RuleSet
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


MAX_RULE_BITS = 28  # codes are packed as action << 2 * bits | from << bits | to in int64 keys; learned codes have <= 25
RULES_FILE_BYTES = 1024 * MiB  # a paper-scale rules file (327k rules) is about 80 MB
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
    """Bit string -> code, each distinct string parsed (and checked: exactly `bits` characters 0 or 1) once."""

    def __init__(self, bits: int) -> None:
        super().__init__()
        self.bits = bits

    def __missing__(self, s: str) -> int:
        if not isinstance(s, str):
            raise TypeError(f"a code must be a bit string, got {type(s).__name__}")
        if len(s) != self.bits or s.strip("01"):
            raise ValueError(f"code {s[:40]!r}{'...' if len(s) > 40 else ''} is not a string of {self.bits} bits "
                             f"(0 or 1)")
        self[s] = value = int(s, 2)
        return value


def _count(n) -> int:
    """A count bound of a rule: an integer 2..COUNT_CAP (a huge one would overflow the int16 tables)."""
    n = int(n)
    if not 0 <= n <= COUNT_CAP:
        raise ValueError(f"count bound {n if abs(n) < 10**12 else '(huge)'} is outside 0..{COUNT_CAP}")
    return n


def _ranged(d: dict, key: str, lo: int, hi: int) -> int:
    """d[key] as an integer in lo..hi; ValueError naming the field otherwise."""
    v = d[key]
    if isinstance(v, bool) or (isinstance(v, float) and not v.is_integer()):
        raise ValueError(f"field {key!r} must be an integer, got {v!r}")
    v = int(v)
    if not lo <= v <= hi:
        raise ValueError(f"field {key!r} {v if abs(v) < 10**12 else '(huge)'} is outside {lo}..{hi}")
    return v


def rules_from_json(d: dict) -> RuleSet:
    """Inverse of rules_to_json; refuses malformed files with a one-line error (bits 1..MAX_RULE_BITS, codes
    of exactly that many bit characters, counts within COUNT_CAP, max_objects within COUNT_CAP)."""
    try:
        if not isinstance(d, dict):
            raise TypeError(f"a JSON {type(d).__name__}, expected an object")
        bits = _ranged(d, "bits", 1, MAX_RULE_BITS)
        c = _CodeStrings(bits).__getitem__  # a file names a few hundred codes millions of times
        rules = tuple(Rule(int(r["action"]), c(r["from"]), c(r["to"]), tuple(map(c, r["requires"])),
                           tuple(map(c, r["forbids"])), tuple((c(x), _count(n)) for x, n in r["at_least"]),
                           tuple((c(x), _count(n)) for x, n in r["fewer_than"])) for r in d["rules"])
        return RuleSet(bits, tuple(map(c, d["vocabulary"])), _ranged(d, "max_objects", 1, COUNT_CAP), rules,
                       _ranged(d, "n_rules_before_generalization", 0, 1 << 62))
    except KeyError as e:
        raise ValueError(f"malformed rules file: missing field {e}") from None
    except (TypeError, ValueError, AttributeError, OverflowError) as e:
        raise ValueError(f"malformed rules file: {type(e).__name__}: {str(e).splitlines()[0][:200]}") from None


def _read_rules_json(path: Path, run_dir: Path) -> dict:
    """The JSON object of a rules file (read by the bounded reader); one-line ValueError naming the file if it is
    not one."""
    try:
        d = read_json_file(path, what="rules file", max_bytes=RULES_FILE_BYTES)
    except JsonFileError as e:
        raise JsonFileError(f"{e}; re-run 'symlearn export-pddl --run {run_dir} --rules'") from None
    if not isinstance(d, dict):
        raise ValueError(f"{path}: not a rules file (a JSON {type(d).__name__}, expected an object with "
                         f"'bits', 'vocabulary', 'max_objects' and 'rules')")
    return d


def load_rules(run_dir: Path) -> tuple[RuleSet, str]:
    """RUN/pddl/rules.json and the model hash recorded with it; ValueError (one line, naming the file) if unreadable."""
    path = Path(run_dir) / PDDL_DIR / RULES_FILE
    if not path.exists():
        raise ValueError(f"no exported rules at {path}; run 'symlearn export-pddl --run {run_dir} --rules' first")
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
