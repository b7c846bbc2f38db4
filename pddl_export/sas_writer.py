"""Write learned rules for one problem as a Fast Downward SAS+ task, skipping its translator.

Fast Downward's translator spends 7-15 s on each task of the learned conditional domain
(grounding, invariant synthesis over ~1,000 conditional effects) and still cannot see that
every object holds exactly one code. Here that is known, so the task is written directly in
the SAS+ format the search component reads (file version 3; SymK, a fork of Fast Downward,
reads it too):

* One state variable per object, `o<i>`, whose values are the codes of the rule set
  (RuleSet.codes), so "one code per object" is the variable itself.
* One operator per real action with rules, `pick-P-release-R`, no precondition, unit cost;
  per object o and per rule of that action one conditional effect `o := code_to` for each
  term of the rule's context (below). FD fires every effect whose condition holds in the
  pre-state, which is apply_rules' simultaneous update.
* Context terms: a rule bounds, for some codes X_1..X_m, how many OTHER objects carry each
  X_j (lo <= count < hi). With the n objects of the problem known, the bounds become a small
  DNF over the others (context_terms): each term says, per other object z, "z has X_j" (the
  fact z = X_j), "z has none of X_j, j in T", or nothing. One conditional effect per term;
  terms may overlap, since they carry the same effect. A rule on "some other object has X"
  becomes n - 1 effects, "no other object has X" one. Sizes grow with (m + 2^m)^(n - 1)
  candidate terms per rule: small for the 1-3 objects of the paper's scenes, and a task over
  max_effects is refused.
* "z has none of X_j, j in T" needs "z != X_j", which SAS+ conditions cannot say. Each such
  X_j gets a derived variable `has-X(z)` with the one axiom `z = X_j -> has-X(z)` (layer 0),
  and the term requires its default value, has-X(z) = 0: negation by failure, exact in the
  search. Fast Downward's heuristics derive how that default value is reached themselves
  (their `axioms=approximate_negative_cycles` option computes these negated axioms exactly
  here: the axioms have no cycles).
  With `negation=Negation.EFFECTS` there are no axioms: each has-X(z) is an ordinary binary
  variable, set in the initial state from z's code and updated by every effect that changes z
  (same condition, value 1 if the new code is X_j, else 0). The states and plans are the same;
  what changes is which heuristics accept the task: Fast Downward's merge-and-shrink and
  landmark heuristics refuse axioms but take conditional effects.
* Goal: the fixed objects' codes. Metric 0 (unit costs).

The encoding is exact for any number of objects: a step of a plan is a step of the rules
(tests check plans against unified-planning's validator on the conditional PDDL domain).

    >>> from pddl_export.rules import Rule, RuleSet
    >>> rs = RuleSet(bits=2, vocabulary=(1, 2, 3), max_objects=2, n_rules_before_generalization=1,
    ...              rules=(Rule(action=5, code_from=1, code_to=2, forbids=(3,)),))
    >>> t = SASEncoder(rs).task([1, 3], [2, None])    # blocked: the other object has code 3
    >>> t.n_operators, t.n_effects, t.n_derived
    (1, 2, 2)
    >>> t.text.splitlines()[:3]
    ['begin_version', '3', 'end_version']
"""
from __future__ import annotations

import functools
import itertools
import time
from dataclasses import dataclass
from enum import Enum
from typing import Sequence

from pddl_export.pddl_writer import action_name, checked_task, code_predicate, object_name, task_codes
from pddl_export.rules import RuleSet
from pddl_export.symbolic import SymbolicGoal

SAS_FILE_VERSION = 3
MAX_EFFECTS = 2_000_000  # refuse tasks whose conditional effects would exceed this
MAX_SUBSET_CODES = 4  # context_terms minimizes over rules with at most this many condition codes


class TaskTooLargeError(RuntimeError):
    """The SAS+ encoding of a problem would have more than max_effects conditional effects."""


class TaskTimeoutError(TaskTooLargeError):
    """Writing the task passed its deadline (the operators of a new object count are built once, then cached)."""


@dataclass(frozen=True)
class SASTask:
    """One problem as SAS+ text, with the sizes that explain its parse time."""

    text: str
    n_objects: int
    n_variables: int  # objects + derived has-X(z) facts
    n_derived: int
    n_operators: int
    n_effects: int
    n_axioms: int

    def __post_init__(self) -> None:
        if self.n_objects < 1 or self.n_variables < self.n_objects:
            raise ValueError("an SAS+ task needs at least one object variable")


@dataclass(frozen=True)
class _Body:
    """What does not depend on init and goal: variables, operators and axioms for n objects."""

    variables: str
    operators: str
    axioms: str
    n_variables: int
    n_derived: int
    n_operators: int
    n_effects: int
    n_axioms: int
    tracked: tuple[tuple[int, int], ...] = ()  # (object, code) of each has-X(z) variable, in variable order


class Negation(str, Enum):
    """How "object z does not hold code X" is encoded (str-valued: compares equal to its name)."""

    AXIOMS = "axioms"  # a derived variable with one axiom, read at its default value (the smallest task)
    EFFECTS = "effects"  # a state variable kept up to date by the effects that change z (no axioms)


class TermKind(str, Enum):
    """What one term of a context DNF says about one other object z (str-valued: compares equal to its name)."""

    EQ = "eq"  # (EQ, (j,)): z has X_j
    NOT = "not"  # (NOT, T): z has none of X_j, j in T (T empty: z is free)


Option = tuple[TermKind, tuple[int, ...]]


def satisfying_cells(intervals: tuple[tuple[int, int], ...], k: int) -> list[tuple[int, ...]]:
    """Every assignment of k others to categories 0..m (m: none of X_1..X_m) with lo_j <= #j < hi_j, sorted.

    Built object by object, never taking a category that is at its upper bound nor leaving fewer objects than
    the lower bounds still need: a rule that forbids most of its m codes leaves few choices per object, where
    trying all (m + 1)^k assignments took minutes for 4-object tasks of 17-bit codes (docs/BENCHMARKS.md).
    """
    m = len(intervals)
    lo = [a for a, _ in intervals]
    hi = [b for _, b in intervals]
    counts = [0] * m
    out: list[tuple[int, ...]] = []
    cell: list[int] = []

    def extend(left: int, need: int) -> None:
        if need > left:
            return
        if left == 0:
            if all(c < h for c, h in zip(counts, hi)):  # a bound of hi <= 0 no assignment meets
                out.append(tuple(cell))
            return
        for j in range(m + 1):
            if j < m and counts[j] + 1 >= hi[j]:
                continue
            gained = 1 if j < m and counts[j] < lo[j] else 0
            if j < m:
                counts[j] += 1
            cell.append(j)
            extend(left - 1, need - gained)
            cell.pop()
            if j < m:
                counts[j] -= 1

    extend(k, sum(lo))
    return out


@functools.lru_cache(maxsize=4096)
def context_terms(intervals: tuple[tuple[int, int], ...], k: int) -> tuple[tuple[Option, ...], ...]:
    """A small DNF, over k other objects, of "lo_j <= #others with X_j < hi_j for every j".

    Each term gives every other object one option: "eq j" (its code is X_j) or "not T" (its
    code is none of X_j, j in T; T empty = free). Cells are the exact assignments of the
    others to categories X_1..X_m or "none"; terms are the prime implicants (all their cells
    satisfy the bounds, and no larger term's do) picked greedily to cover every satisfying
    cell, fewest conditions first. Terms may overlap: they carry the same effect. Above
    MAX_SUBSET_CODES codes, each satisfying cell is its own term (options eq j / not all).
    """
    m = len(intervals)
    cats = range(m + 1)  # m = "none of them"
    cells = set(satisfying_cells(intervals, k))
    everything: tuple[int, ...] = tuple(range(m))
    if m > MAX_SUBSET_CODES:
        return tuple(tuple((TermKind.EQ, (j,)) if j < m else (TermKind.NOT, everything) for j in cell)
                     for cell in sorted(cells))
    options: list[tuple[Option, frozenset[int], int]] = [((TermKind.EQ, (j,)), frozenset([j]), 1)
                                                          for j in range(m)]
    for size in range(m + 1):
        for t in itertools.combinations(range(m), size):
            options.append(((TermKind.NOT, t), frozenset(cats) - frozenset(t), size))
    implicants = []
    for combo in itertools.product(options, repeat=k):
        covered = frozenset(itertools.product(*(c for _, c, _ in combo)))
        if covered <= cells:
            implicants.append((tuple(o for o, _, _ in combo), covered, sum(n for _, _, n in combo)))
    primes = [t for t in implicants if not any(t[1] < u[1] for u in implicants)]
    left, terms = set(cells), []
    while left:
        best = max(primes, key=lambda t: (len(t[1] & left), -t[2], t[0]))
        terms.append(best[0])
        left -= best[1]
    return tuple(sorted(terms))


class SASEncoder:
    """SAS+ tasks over one rule set; the operators for n objects are built once and reused."""

    def __init__(self, rules: RuleSet, max_effects: int = MAX_EFFECTS, negation: Negation | str = Negation.AXIOMS) -> None:
        self.rules = rules
        self.max_effects = int(max_effects)
        self.negation = Negation(negation)
        self.codes = rules.codes
        self.value = {c: i for i, c in enumerate(self.codes)}  # code -> value index of an object variable
        self._bodies: dict[int, _Body] = {}

    def with_negation(self, negation: Negation | str) -> "SASEncoder":
        """This encoder if it writes `negation` already, else a sibling over the same rules that does (cached)."""
        negation = Negation(negation)
        if negation is self.negation:
            return self
        if not hasattr(self, "_siblings"):
            self._siblings: dict[Negation, SASEncoder] = {}
        if negation not in self._siblings:
            self._siblings[negation] = SASEncoder(self.rules, self.max_effects, negation)
        return self._siblings[negation]

    def task(self, init: Sequence[int], goal: SymbolicGoal | Sequence[int | None],
             deadline: float | None = None) -> SASTask:
        """The SAS+ task from init codes to goal codes (ValueError on bad shapes).

        Codes outside the rules' vocabulary (RuleSet.with_codes: inert, kept by their objects) become
        extra values of the object variables, through a sibling encoder cached per set of new codes.
        """
        new = task_codes(init, goal) - set(self.codes)
        if new:
            if not hasattr(self, "_extended"):
                self._extended: dict[frozenset, SASEncoder] = {}
            if new not in self._extended:
                self._extended[new] = SASEncoder(self.rules.with_codes(new), self.max_effects, self.negation)
            return self._extended[new].task(init, goal, deadline)
        init_t, goal_g = checked_task(self.rules, init, goal)
        n = len(init_t)
        body = self._bodies.get(n)
        if body is None:
            body = self._bodies[n] = self._body(n, deadline)
        state = [str(self.value[c]) for c in init_t] + [str(int(init_t[z] == x)) if self.negation is Negation.EFFECTS
                                                         else "0" for z, x in body.tracked]
        goals = [(i, self.value[c]) for i, c in enumerate(goal_g.codes) if c is not None]
        text = "\n".join([
            "begin_version", str(SAS_FILE_VERSION), "end_version", "begin_metric", "0", "end_metric",
            body.variables, "0",  # no mutex groups: the object variables already are them
            "begin_state", *state, "end_state",
            "begin_goal", str(len(goals)), *(f"{v} {x}" for v, x in goals), "end_goal",
            body.operators, body.axioms, ""])
        return SASTask(text=text, n_objects=n, n_variables=body.n_variables, n_derived=body.n_derived,
                       n_operators=body.n_operators, n_effects=body.n_effects, n_axioms=body.n_axioms)

    def _body(self, n: int, deadline: float | None = None) -> _Body:
        """The variables, operators and axioms for n objects; TaskTimeoutError past `deadline` (perf_counter)."""
        bits = self.rules.bits
        has: dict[tuple[int, int], int] = {}  # (object, code) -> derived variable index, after the objects

        def has_var(z: int, x: int) -> int:
            return has.setdefault((z, x), n + len(has))

        per_action, n_effects = [], 0
        for a in self.rules.actions:
            effects: set[tuple[tuple[tuple[int, int], ...], int, int]] = set()
            for rule in (r for r in self.rules.rules if r.action == a):
                if deadline is not None and time.perf_counter() > deadline:
                    raise TaskTimeoutError(f"writing the SAS+ task for {n} objects ({len(self.rules.rules)} rules) "
                                           f"passed the time limit")
                bounds = rule.bounds()
                if any(lo > n - 1 for lo, _ in bounds.values()):
                    continue  # needs more other objects than the problem has
                xs = [x for x, (lo, hi) in bounds.items() if lo > 0 or hi <= n - 1]  # drop vacuous bounds
                terms = context_terms(tuple(bounds[x] for x in xs), n - 1)
                for o in range(n):
                    others = [z for z in range(n) if z != o]
                    own = ((o, self.value[rule.code_from]),)
                    for term in terms:
                        cond = list(own)
                        for z, (kind, js) in zip(others, term):
                            if kind is TermKind.EQ:
                                cond.append((z, self.value[xs[js[0]]]))
                            else:
                                cond += [(has_var(z, xs[j]), 0) for j in js]
                        effects.add((tuple(sorted(cond)), o, self.value[rule.code_to]))
                        self._check_size(n, n_effects + len(effects))
            if effects:
                n_effects += len(effects)
                per_action.append((a, effects))
        ops = []
        for a, effects in per_action:  # has-X(z) variables are all known only now
            if self.negation is Negation.EFFECTS:
                tracking = self._tracking_effects(effects, has)
                n_effects += len(tracking)
                self._check_size(n, n_effects)
                effects = effects | tracking
            lines = ["begin_operator", action_name(a), "0", str(len(effects))]
            for cond, var, post in sorted(effects):
                lines.append(f"{len(cond)} {' '.join(f'{v} {x}' for v, x in cond)} {var} -1 {post}")
            ops.append("\n".join(lines + ["1", "end_operator"]))

        variables = [str(n + len(has))]
        for o in range(n):
            names = [f"Atom {code_predicate(c, bits)}({object_name(o)})" for c in self.codes]
            variables += ["begin_variable", object_name(o), "-1", str(len(self.codes)), *names, "end_variable"]
        axioms = []
        derived = self.negation is Negation.AXIOMS
        for (z, x), var in sorted(has.items(), key=lambda kv: kv[1]):
            fact = f"has-{code_predicate(x, bits)}({object_name(z)})"
            variables += ["begin_variable", f"has-{code_predicate(x, bits)}-{object_name(z)}", "0" if derived else "-1",
                          "2", f"NegatedAtom {fact}", f"Atom {fact}", "end_variable"]
            if derived:
                axioms.append(f"begin_rule\n1\n{z} {self.value[x]}\n{var} 0 1\nend_rule")
        return _Body(variables="\n".join(variables), operators="\n".join([str(len(ops)), *ops]),
                     axioms="\n".join([str(len(axioms)), *axioms]), n_variables=n + len(has),
                     n_derived=len(has) if derived else 0, n_operators=len(ops), n_effects=n_effects,
                     n_axioms=len(axioms), tracked=tuple(sorted(has, key=has.__getitem__)))

    def _check_size(self, n: int, n_effects: int) -> None:
        if n_effects > self.max_effects:
            raise TaskTooLargeError(f"the SAS+ task for {n} objects needs more than {self.max_effects} conditional "
                                    "effects; plan with fewer objects or use the PDDL planners")

    def _tracking_effects(self, effects: set, has: dict[tuple[int, int], int]) -> set:
        """For Negation.EFFECTS: with each effect o := Y, set every tracked has-X(o) to [Y == X] (same condition)."""
        code_of = {v: c for c, v in self.value.items()}
        out = set()
        for cond, o, post in effects:
            for (z, x), var in has.items():
                if z == o:
                    out.add((cond, var, int(code_of[post] == x)))
        return out
