"""Each object's second most likely next code under m(z), distilled into rules: the exported all-outcomes form.

The rules (pddl_export.rules) say what each object's LIKELIEST next code is. m(z) gives every
next bit a probability, and the bits are independent, so an object's second likeliest next
code is its likeliest with the least certain bit flipped, (1 - q) / q times less likely (q
the chance of the flipped value). `SecondOutcome` is m(z) answering that code wherever it is
at least `min_ratio` as likely as the likeliest (and the likeliest elsewhere); enumerated on
the main rules' scenes and distilled by the same exact distillation (pddl_export.distil), it
gives rules of the same kind: under `action`, an object with `code_from` MAY take `code_to`
when the others match. Each alternative's cost is the mean over the enumerated cases of its
extra -log P, -log((1 - q) / q) >= 0, per (action, code_from, code_to).

A planner over the main rules and these (search.rules_outcomes) can then count on one object
taking its second outcome, as the learned-net `astar-outcomes` counts on m(z)'s likely
outcomes, without the network. Stored as RUN/pddl/outcomes.json beside rules.json.

    >>> import numpy as np
    >>> probs = np.array([[[0.9, 0.4]]])          # one object, bits MSB first: likeliest 10, next 11
    >>> alt, extra = second_codes(probs, min_ratio=0.05)
    >>> alt.tolist(), round(float(extra[0, 0]), 4)    # 11 is 0.4 / 0.6 as likely
    ([[3]], 0.4055)
"""
from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pddl_export.distil import distil_rules
from pddl_export.enumeration import Enumeration, SceneBlock
from pddl_export.rules import RuleSet
from pddl_export.bounded_json import read_json_file
from pddl_export.rules_io import (FREEZE_BYTES, PDDL_DIR, RULES_FILE_BYTES, _CodeStrings, paused_gc, rules_from_json,
                                  rules_to_json)
from pddl_export.symbolic import N_ACTIONS, OutcomeTransitionFn, bit_flip_costs, code_str, codes_from_bits

OUTCOMES_FILE = "outcomes.json"
MIN_OUTCOME_RATIO = 0.05  # an alternative is kept where it is at least this fraction as likely as the likeliest


def second_codes(probs: np.ndarray, min_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """(B, K, bits) bit probabilities -> each object's second likeliest next code and its extra -log P.

    Where that code is less than min_ratio as likely as the likeliest, the likeliest code is
    returned and the extra cost is inf (no alternative).
    """
    if not 0 < min_ratio <= 1:
        raise ValueError(f"min_ratio must lie in (0, 1], got {min_ratio}")
    probs = np.asarray(probs, np.float64)
    top, flip = bit_flip_costs(probs)  # (B, K, bits) extra -log P of flipping each bit
    least = np.argmin(flip, axis=-1)  # (B, K) the least certain bit
    extra = np.take_along_axis(flip, least[..., None], -1)[..., 0]
    keep = extra <= -np.log(min_ratio)
    bits = probs.shape[-1]
    alt = codes_from_bits(top) ^ np.where(keep, np.left_shift(1, bits - 1 - least), 0)
    return alt.astype(np.int64), np.where(keep, extra, np.inf)


class SecondOutcome:
    """m(z) as a transition function giving each object its second likeliest next code (second_codes)."""

    def __init__(self, transition: OutcomeTransitionFn, min_ratio: float = MIN_OUTCOME_RATIO) -> None:
        if not callable(getattr(transition, "bit_probabilities", None)):
            raise ValueError("the transition model gives no bit probabilities, so it has no second outcomes")
        self.transition, self.bits, self.min_ratio = transition, int(transition.bits), float(min_ratio)

    def outcomes(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(likeliest codes, second codes, their extra -log P) for a batch, each (B, K)."""
        probs = np.asarray(self.transition.bit_probabilities(codes, actions), np.float64)
        alt, extra = second_codes(probs, self.min_ratio)
        return codes_from_bits(probs >= 0.5), alt, extra

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        return self.outcomes(codes, actions)[1]


@dataclass(frozen=True)
class OutcomeRules:
    """Rules for each object's second likeliest next code, and each alternative's extra -log P."""

    rules: RuleSet  # an object with code_from MAY take code_to (its second outcome) where a rule fires
    costs: tuple[tuple[int, int, int, float], ...]  # (action, code_from, code_to, mean extra -log P), sorted
    min_ratio: float

    def __post_init__(self) -> None:
        if not 0 < self.min_ratio <= 1:
            raise ValueError(f"min_ratio must lie in (0, 1], got {self.min_ratio}")
        if any(not (np.isfinite(c) and c >= 0) for *_, c in self.costs):
            raise ValueError("alternative costs must be finite and >= 0")

    def alternative_costs(self) -> "AlternativeCosts":
        """The costs as a lookup the search calls with arrays of (action, code_from, code_to)."""
        return AlternativeCosts.from_costs(self.costs, self.rules.bits)


@dataclass(frozen=True, eq=False)
class AlternativeCosts:
    """Extra -log P of each (action, code_from -> code_to) alternative, inf where there is none.

    Held as sorted keys, so memory follows the number of alternatives: a dense (36, 2**bits, 2**bits)
    table would take 2.4 GB at 12 bits and 36 GB at 14 (codes with location bits).
    """

    bits: int
    keys: np.ndarray  # (N,) sorted int64: action << 2 * bits | code_from << bits | code_to
    values: np.ndarray  # (N,) float64

    @staticmethod
    def from_costs(costs: Iterable[tuple[int, int, int, float]], bits: int) -> "AlternativeCosts":
        """From (action, code_from, code_to, cost) entries; a repeated key keeps its last cost."""
        entries = {(int(a) << 2 * bits) | (int(c) << bits) | int(d): float(x) for a, c, d, x in costs}
        keys = np.array(sorted(entries), np.int64)
        return AlternativeCosts(int(bits), keys, np.array([entries[k] for k in keys.tolist()], np.float64))

    def __call__(self, actions: np.ndarray, code_from: np.ndarray, code_to: np.ndarray) -> np.ndarray:
        """Broadcast arrays of action ids and codes -> the cost of each alternative (inf: none)."""
        a, c, d = np.broadcast_arrays(*(np.asarray(x, np.int64) for x in (actions, code_from, code_to)))
        key = (a << 2 * self.bits) | (c << self.bits) | d
        if not len(self.keys):
            return np.full(key.shape, np.inf)
        at = np.minimum(np.searchsorted(self.keys, key), len(self.keys) - 1)
        return np.where(self.keys[at] == key, self.values[at], np.inf)


def _second_enumeration(second: SecondOutcome, enumeration: Enumeration
                        ) -> tuple[Enumeration, tuple[tuple[int, int, int, float], ...]]:
    """SecondOutcome's answers on the enumeration's scenes, and the mean extra -log P per (action, code_from,
    code_to) over the objects that have that alternative: both from one pass of the network."""
    sums: dict[tuple[int, int, int], list[float]] = {}
    blocks, seconds = [], 0.0
    for block in enumeration.blocks:
        states = block.states
        t0 = time.perf_counter()
        main, alt, extra = second.outcomes(states, block.actions)
        seconds += time.perf_counter() - t0
        blocks.append(SceneBlock(block.n_objects, block.scenes, block.actions, alt))
        rows, objs = np.nonzero(alt != main)
        for a, c, d, x in zip(block.actions[rows].tolist(), states[rows, objs].tolist(), alt[rows, objs].tolist(),
                              extra[rows, objs].tolist()):
            acc = sums.setdefault((a, c, d), [0.0, 0])
            acc[0] += x
            acc[1] += 1
    enum = Enumeration(enumeration.bits, enumeration.vocabulary, enumeration.max_objects, tuple(blocks),
                       n_calls=len(blocks), seconds=seconds, complete=enumeration.complete)
    return enum, tuple((a, c, d, s / n) for (a, c, d), (s, n) in sorted(sums.items()))


def distil_outcomes(transition: OutcomeTransitionFn, enumeration: Enumeration,
                    min_ratio: float = MIN_OUTCOME_RATIO) -> tuple[OutcomeRules, Enumeration]:
    """The second-outcome rules on the scenes of `enumeration` (the main rules'), and their own enumeration."""
    enum, costs = _second_enumeration(SecondOutcome(transition, min_ratio), enumeration)
    return OutcomeRules(distil_rules(enum), costs, min_ratio), enum


def outcomes_to_json(outcomes: OutcomeRules) -> dict:
    """JSON-ready form (rules as in rules.json, codes as bit strings)."""
    b = outcomes.rules.bits
    return {"min_ratio": outcomes.min_ratio, **rules_to_json(outcomes.rules),
            "costs": [{"action": a, "from": code_str(c, b), "to": code_str(d, b), "cost": round(x, 6)}
                      for a, c, d, x in outcomes.costs]}


def outcomes_from_json(d: dict) -> OutcomeRules:
    """Inverse of outcomes_to_json; one-line ValueError on a malformed file."""
    try:
        rules = rules_from_json(d)
        c = _CodeStrings(rules.bits).__getitem__  # exactly `bits` characters 0 or 1, as in rules.json
        costs = tuple((_action(r["action"]), c(r["from"]), c(r["to"]), _number(r["cost"], "cost"))
                      for r in d["costs"])
        return OutcomeRules(rules, costs, _number(d["min_ratio"], "min_ratio"))
    except KeyError as e:
        raise ValueError(f"malformed outcomes file: missing field {e}") from None
    except (TypeError, AttributeError, OverflowError) as e:
        raise ValueError(f"malformed outcomes file: {type(e).__name__}: {str(e).splitlines()[0][:200]}") from None


def _number(x, name: str) -> float:
    """A finite number of the file (not a string or boolean); ValueError naming the field otherwise."""
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not np.isfinite(x):
        raise ValueError(f"malformed outcomes file: field {name!r} must be a finite number, got {str(x)[:40]!r}")
    return float(x)


def _action(a) -> int:
    """An action id of a cost entry: an integer 0..N_ACTIONS - 1."""
    if isinstance(a, bool) or not isinstance(a, int) or not 0 <= a < N_ACTIONS:
        raise ValueError(f"cost entry action {a!r} is not an action id 0..{N_ACTIONS - 1}")
    return a


def load_outcomes(run_dir: Path) -> tuple[OutcomeRules, str]:
    """RUN/pddl/outcomes.json and the model hash recorded with it; one-line ValueError naming the file otherwise."""
    path = Path(run_dir) / PDDL_DIR / OUTCOMES_FILE
    fix = f"re-run 'symlearn export-pddl --run {run_dir} --rules'"
    if not path.exists():
        raise ValueError(f"no exported outcome rules at {path}; {fix}")
    try:
        with paused_gc(freeze=path.stat().st_size >= FREEZE_BYTES):
            d = read_json_file(path, what="outcomes file", max_bytes=RULES_FILE_BYTES)
            if not isinstance(d, dict):
                raise ValueError(f"a JSON {type(d).__name__}, expected an object")
            outcomes = outcomes_from_json(d)
        model_hash = d.get("model_hash", "")
        if not isinstance(model_hash, str):
            raise ValueError(f"model_hash must be a string, got {model_hash!r}")
    except ValueError as e:  # the bounded reader's refusals already name the file
        raise ValueError(str(e) if str(e).startswith(f"{path}: ") else f"{path}: {e}") from None
    return outcomes, model_hash
