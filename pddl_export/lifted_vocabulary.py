"""The lifted domain's vocabulary: its constants and their PDDL names, the learned bits as literals, and one action
schema (`Schema`) with its text.

The constants are the six table locations (`l0` to `l5`), the layers (`h0` to `h7`, a block's top or the table;
`h1-end` to `h7-end`, a far-row stick's end), the places (PLACES: on its location, or which way and how far off)
and the objects (`o0`, ...). Every module that writes the lifted domain (pddl_export.lifted_moves, lifted_domain, lifted_problem)
or reads its plans (lifted_plans) names them through here, so that they agree.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

from pddl_export.lifted_rules import LiftedRules
from pddl_export.pddl_writer import checked_name

LEVELS = 8
SURFACES = ("table", "block-top", "stick-end")  # what the top at a location is, and what a block rests on


def surface(level: int, stands: bool) -> str:
    """The surface at a level: the table (level 0), a block standing at the location, or a far-row stick's end."""
    return SURFACES[0] if level == 0 else SURFACES[1] if stands else SURFACES[2]


def top_name(layer: str, what: str) -> str:
    """The layer constant of a top: `h3` (the table at h0, or a block standing there), `h3-end` (a stick's end);
    a parameter (`?top_l4`) stands for itself. One value per location or block, so that Fast Downward's invariant
    synthesis (one counted argument per predicate) finds `height` and `rests` as multi-valued variables."""
    if what.startswith("?"):
        return what
    return f"{layer}-end" if what == SURFACES[2] else layer


def layer_names() -> list[str]:
    """Every layer constant: the levels h0-h7 and the stick ends h1-end-h7-end."""
    return [level_name(h) for h in range(LEVELS)] + [f"{level_name(h)}-end" for h in range(1, LEVELS)]


def loc_name(loc: int) -> str:
    return f"l{int(loc)}"


def level_name(h: int) -> str:
    return f"h{int(h)}"


def model_hash_text(rules: LiftedRules) -> str:
    """The transition model's hash as the domain states it (checked_name: a piece of a PDDL name), or 'nohash'."""
    return checked_name(rules.model_hash, "the lifted rules' model_hash", "part") if rules.model_hash else "nohash"


def domain_name(rules: LiftedRules) -> str:
    """The domain's name: carries the transition model's hash, so two runs' domains are told apart."""
    return checked_name(f"symlearn-{model_hash_text(rules)}", "domain name")


@dataclass(frozen=True)
class Schema:
    """One action schema: its name, the robot action it stands for, its parts and its PDDL text."""

    name: str
    pick: int | None  # None: lifted (?from is the first parameter after the block)
    release: int | None  # None: lifted (?to follows ?from); a lifted schema refined on where it releases fixes it
    text: str
    params: tuple = ()
    pre: tuple = ()
    eff: tuple = ()
    alternative: int = 0  # which of its rule's outcomes (0: the rule's own)
    cost: int | None = None  # the cost form's action cost (its last effect increases total-cost by it)
    step: str = "move"  # "move": one robot action; "pick" / "release": its two halves (a cube's move, split)
    statics: tuple = ()  # facts every problem states for it: a pooled schema's structures (pool_schema)
    predicate: str = ""  # the static relation a pooled schema declares, with its typed parameters


def negated_bits(rules: LiftedRules) -> frozenset[int]:
    """The kept learned bits some rule's condition reads as 0 (LiftedRules.tested_kinds): only these get a negative
    form `no-bit-I`, so that no precondition is negative; every other bit is one predicate, true where the bit is 1
    (as a person would write it), which spares the translator two atoms per changed bit of every action."""
    return frozenset(bit for kind in rules.tested_kinds for bit, value in rules.layout.kind_bits(kind) if not value)


def bit_literals(rules: LiftedRules, term: str, kind: int) -> list[str]:
    """Literals fixing a piece's kept learned bits to `kind` (packed in layout.kept order): `bit-I` for a 1, and
    for a 0 `no-bit-I` where the domain has it (negated_bits)."""
    negated = negated_bits(rules)
    return [f"(bit-{bit} {term})" if value else f"(no-bit-{bit} {term})"
            for bit, value in rules.layout.kind_bits(kind) if value or bit in negated]


PLACES = ("on-spot", "minus-y-near", "minus-y-mid", "minus-y-far", "plus-y-near", "plus-y-mid", "plus-y-far", "off-x")


def place_name(p: int) -> str:
    """The place field's value as a constant: on its location, or which way (y) and how far off it (5-9, 9-15,
    over 15 cm), or off mainly in x."""
    return PLACES[int(p)]


def fluent_value(literals: Sequence[str], predicate: str, term: str) -> str | None:
    """The second argument of the first `(predicate term X)` among literals (`at`, `level`: a block's one value)."""
    head = f"({predicate} {term} "
    return next((x[len(head):-1] for x in literals if x.startswith(head)), None)


TEXT_WIDTH = 110  # literals are packed into lines of at most this many characters


def _wrapped(literals, indent: str) -> str:
    """Literals joined by spaces, a new line (at indent) before one that would pass TEXT_WIDTH."""
    lines, line = [], ""
    for lit in literals:
        if line and len(indent) + len(line) + 1 + len(lit) > TEXT_WIDTH - (20 if not lines else 0):
            lines.append(line)
            line = lit
        else:
            line = f"{line} {lit}" if line else lit
    return f"\n{indent}".join(lines + [line])


def schema_text(name: str, params, pre, eff, comment: str) -> str:
    """An action's PDDL text: its comment line, parameters, preconditions and effects (wrapped at TEXT_WIDTH)."""
    ps = " ".join(f"{p} - {t}" for p, t in params)
    pad = " " * 6
    return (f"  {comment}\n  (:action {name}\n    :parameters ({ps})\n"
            f"    :precondition (and {_wrapped(pre, pad)})\n    :effect (and {_wrapped(eff, pad)}))\n")


def object_name(i: int) -> str:
    """The PDDL name of a problem's object i (`o2`)."""
    return checked_name(f"o{int(i)}", "object name")
