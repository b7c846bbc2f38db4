"""Write learned rules as PDDL text: a lifted conditional-effects domain or a grounded STRIPS task.

Two encodings of the same rules (docs/DESIGN.md, "Encoding learned rules for the planners",
says which planner takes which):

* Conditional form (`conditional_domain` + `problem_pddl`): one parameterless action
  `pick-P-release-R` per real action that changes something, whose effect is
  `(forall (?o - obj) (and (when <rule condition> <rule effect>) ...))`, one `when` per rule.
  PDDL evaluates every `when` in the pre-state and applies all of them at once, which is
  exactly apply_rules' simultaneous update; the rules of one (action, own code) are mutually
  exclusive (RuleSet checks it), so one step of the plan is one step of the network. Plans
  read as the robot's own actions. The context on other objects is written with `exists`:
  "some other object has X" is `(exists (?z - obj) (code-X ?z))`; the `(not (= ?z ?o))`
  guard is added only when X is ?o's own code, since each object holds exactly one code
  (true in the initial state and kept by every effect), so another code can only be on
  another object. "At least n" uses n pairwise-distinct variables; "none" and "fewer than
  n" are the negations. Fast Downward and SymK take it as written.

  Conditions as one derived atom: a rule condition with a context is written
  `(forall (?s - scene) (and (= ?s the-scene) (code-C ?o) <context>))` over the type
  `scene`, whose only object is the domain constant `the-scene`; a universal over one
  object is the formula itself (the equality keeps unified-planning from dropping the
  unused quantifier when it rewrites the domain). It is there for Fast Downward's
  translator, which compiles a universal condition into one derived atom. Written plainly,
  the translator negates the disjunction of all add conditions of each code atom, a
  product over their literals: on a 1,000-rule domain it did not finish in 120 s; with the
  wrapper it translates a 3-object task in about 10 s.
* STRIPS form (`strips_pddl`): for ONE problem, the joint states reachable from its initial
  state under the rules are enumerated (breadth first, bounded by max_states); each
  (state, real action) that changes something becomes the ground action
  `pick-P-release-R-sN` (N = the state's index) whose precondition is the full joint
  assignment and whose effect changes exactly the objects that change. Objects are domain
  constants; only :strips and :typing are needed, so every planner (pyperplan,
  Fast Downward) takes it. Its size grows with the reachable state space. The task also
  carries its states and edges, from which search.up_problem.strips_problem builds the same
  problem for unified-planning without its PDDL reader.

Names: codes are predicates `code-<bits, MSB first>` (`code-00011011`), objects `o0, o1, ...`.
Every function returns a string; `pddl_export.files.atomic_write_text` puts one on disk.

    >>> from pddl_export.rules import Rule, RuleSet
    >>> rs = RuleSet(bits=2, vocabulary=(1, 2), max_objects=2, n_rules_before_generalization=1,
    ...              rules=(Rule(action=5, code_from=1, code_to=2),))
    >>> for line in conditional_domain(rs, model_hash="abc").splitlines()[:3]:
    ...     print(line)
    ;; symlearn learned domain (conditional form)
    ;; model-hash: abc
    ;; vocabulary-size: 2
    >>> "(:goal (and (code-10 o0)))" in problem_pddl(rs, [1, 2], [2, None], model_hash="abc")
    True
    >>> t = strips_pddl(rs, [1, 1], [2, 2], model_hash="abc")   # both objects change at once
    >>> t.n_states, t.n_actions
    (2, 1)
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from enum import Enum
from typing import Sequence

import numpy as np

from pddl_export.rules import INF, Rule, RuleSet, apply_rules_batch
from pddl_export.symbolic import N_ACTIONS, N_LOCATIONS, SymbolicGoal, code_str

class PddlForm(str, Enum):
    """The two PDDL encodings of the rules; the values are the names used on the command line and in JSON."""

    CONDITIONAL = "conditional"  # conditional_domain + problem_pddl: lifted, one action per real action
    STRIPS = "strips"  # strips_pddl: grounded over the states reachable from one initial state


OBJECT_TYPE = "obj"
SCENE_TYPE, SCENE_CONSTANT, SCENE_VAR = "scene", "the-scene", "?s"  # the one-object wrapper type
_ACTION_RE = re.compile(r"^pick-([0-5])-release-([0-5])(?:-s[0-9]+)?$", re.IGNORECASE)
_CODE_RE = re.compile(r"^code-([01]+)$", re.IGNORECASE)
_OBJECT_RE = re.compile(r"^o([0-9]+)$", re.IGNORECASE)


# ----------------------------------------------------------------------------- names


PDDL_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")  # PDDL's name grammar: a letter, then letters, digits, - and _
PDDL_NAME_PART = re.compile(r"[A-Za-z0-9_-]+")  # a piece of a name, such as a hash (it may start with a digit)
MAX_NAME_CHARS = 100
MAX_COMMENT_CHARS = 200
NAME_FORMS = ("name", "part", "comment")


def checked_name(text: object, what: str, form: str = "name") -> str:
    """The one check of every string a writer puts into a PDDL (or SAS+) file, whatever file it came from.

    form "name" (domain, problem and object names): `text` itself where it is a PDDL name (PDDL_NAME, at most
    MAX_NAME_CHARS characters), else a one-line ValueError naming `what`; "part": the same for a piece of a name
    that may start with a digit (a hash); "comment": any text for a `;` comment, escaped onto one line (every run of
    whitespace, newlines included, one space; an unprintable character as its escape), at most MAX_COMMENT_CHARS.
    So no string can end its name or comment and start PDDL text of its own."""
    if form == "comment":
        flat = "".join(c if c.isprintable() else ascii(c)[1:-1] for c in " ".join(str(text).split()))
        return flat if len(flat) <= MAX_COMMENT_CHARS else flat[:MAX_COMMENT_CHARS - 3] + "..."
    pattern = {"name": PDDL_NAME, "part": PDDL_NAME_PART}[form]
    if not (isinstance(text, str) and len(text) <= MAX_NAME_CHARS and pattern.fullmatch(text)):
        first = "letters" if form == "part" else "a letter, then letters"
        raise ValueError(f"{what} {str(text)[:60]!r} is not a PDDL name ({first}, digits, '-' and '_'; at most "
                         f"{MAX_NAME_CHARS} characters)")
    return text


def pddl_name(text: str) -> str:
    """A valid PDDL name from any text: lowercase letters, digits, '-' and '_', starting with a letter (checked_name
    refuses one longer than MAX_NAME_CHARS)."""
    name = re.sub(r"[^a-z0-9_-]+", "-", str(text).strip().lower()).strip("-_")
    if not name:
        raise ValueError(f"cannot make a PDDL name from {str(text)[:60]!r}")
    return checked_name(name if name[0].isalpha() else f"x-{name}", "PDDL name")


def code_predicate(code: int, bits: int) -> str:
    """'code-00011011' for code 27 with 8 bits."""
    return f"code-{code_str(code, bits)}"


def code_from_predicate(name: str) -> int:
    """Inverse of code_predicate."""
    m = _CODE_RE.match(name)
    if not m:
        raise ValueError(f"{name!r} is not a code predicate")
    return int(m.group(1), 2)


def object_name(index: int) -> str:
    """'o3' for object 3: the PDDL name of the object at that index of the scene."""
    return checked_name(f"o{int(index)}", "object name")


def object_index(name: str) -> int:
    """Inverse of object_name."""
    m = _OBJECT_RE.match(name)
    if not m:
        raise ValueError(f"{name!r} is not an object name")
    return int(m.group(1))


def action_name(action: int) -> str:
    """'pick-P-release-R' for action id P * 6 + R."""
    if not 0 <= int(action) < N_ACTIONS:
        raise ValueError(f"action must lie in 0..{N_ACTIONS - 1}, got {action}")
    return f"pick-{int(action) // N_LOCATIONS}-release-{int(action) % N_LOCATIONS}"


def names_action_id(name: str) -> bool:
    """Whether an action name is 'pick-P-release-R[-sN]' (the rules' domains), which action_id_from_name reads."""
    return bool(_ACTION_RE.match(name))


def action_id_from_name(name: str) -> int:
    """Action id of 'pick-P-release-R' or of a grounded 'pick-P-release-R-sN'."""
    m = _ACTION_RE.match(name)
    if not m:
        raise ValueError(f"{name!r} does not name a real action (pick-P-release-R[-sN])")
    return int(m.group(1)) * N_LOCATIONS + int(m.group(2))


# ----------------------------------------------------------------------------- text pieces


def _header(kind: str, model_hash: str, rules: RuleSet, extra: Sequence[str] = ()) -> list[str]:
    one_line = checked_name(model_hash, "model hash", "comment")
    lines = [
        f";; symlearn learned {kind}",
        f";; model-hash: {one_line}",
        f";; vocabulary-size: {len(rules.vocabulary)}",
        f";; rules: {rules.n_rules} (before generalization: {rules.n_rules_before_generalization})",
        f";; exact for scenes of up to {rules.max_objects} objects",
    ]
    return lines + [f";; {x}" for x in extra]


def _count_formula(code: int, n: int, own_code: int, bits: int) -> tuple[str, bool]:
    """'at least n OTHER objects have `code`' and whether it uses equality."""
    vs = ["?z"] if n == 1 else [f"?z{i}" for i in range(1, n + 1)]
    parts = [f"(not (= {a} {b}))" for i, a in enumerate(vs) for b in vs[i + 1:]]
    if code == own_code:
        parts += [f"(not (= {v} ?o))" for v in vs]
    parts += [f"({code_predicate(code, bits)} {v})" for v in vs]
    body = parts[0] if len(parts) == 1 else f"(and {' '.join(parts)})"
    return f"(exists ({' '.join(vs)} - {OBJECT_TYPE}) {body})", len(parts) > n


@dataclass(frozen=True)
class _Condition:
    text: str
    uses_exists: bool
    uses_negation: bool
    uses_equality: bool


def _rule_condition(rule: Rule, bits: int) -> _Condition:
    conds = [f"({code_predicate(rule.code_from, bits)} ?o)"]
    eq = neg = False
    for x, (lo, hi) in rule.bounds().items():
        if lo >= 1:
            text, e = _count_formula(x, lo, rule.code_from, bits)
            conds.append(text)
            eq |= e
        if hi < INF:
            text, e = _count_formula(x, hi, rule.code_from, bits)
            conds.append(f"(not {text})")
            eq, neg = eq | e, True
    neg |= eq  # (not (= ..)) is a negative literal too
    if len(conds) == 1:
        return _Condition(conds[0], False, neg, eq)
    # One-object universal wrapper: see "Conditions as one derived atom" in the module docstring.
    text = f"(forall ({SCENE_VAR} - {SCENE_TYPE}) (and (= {SCENE_VAR} {SCENE_CONSTANT}) {' '.join(conds)}))"
    return _Condition(text, True, neg, True)


def _requirements(*flags: str) -> str:
    return f"(:requirements {' '.join(flags)})"


def conditional_domain(rules: RuleSet, model_hash: str, name: str = "symlearn") -> str:
    """Domain text: one parameterless conditional-effects action per real action with rules."""
    bits = rules.bits
    by_action: dict[int, list[Rule]] = {}
    for r in rules.rules:
        by_action.setdefault(r.action, []).append(r)
    actions, uses = [], {"exists": False, "neg": False, "eq": False}
    for a in sorted(by_action):
        whens = []
        for r in by_action[a]:
            c = _rule_condition(r, bits)
            uses["exists"] |= c.uses_exists
            uses["neg"] |= c.uses_negation
            uses["eq"] |= c.uses_equality
            frm, to = code_predicate(r.code_from, bits), code_predicate(r.code_to, bits)
            whens.append(f"      (when {c.text}\n        (and (not ({frm} ?o)) ({to} ?o)))")
        actions.append(
            f"  (:action {action_name(a)}\n"
            f"    :parameters ()\n"
            f"    :precondition (and)\n"
            f"    :effect (forall (?o - {OBJECT_TYPE}) (and\n" + "\n".join(whens) + ")))")
    flags = [":strips", ":typing"] + ([":conditional-effects"] if actions else [])
    flags += [":existential-preconditions", ":universal-preconditions"] if uses["exists"] else []
    flags += [":negative-preconditions"] if uses["neg"] else []
    flags += [":equality"] if uses["eq"] else []
    preds = " ".join(f"({code_predicate(c, bits)} ?o - {OBJECT_TYPE})" for c in rules.codes)
    lines = _header(f"domain ({PddlForm.CONDITIONAL.value} form)", model_hash, rules, [f"actions: {len(actions)}"])
    types = f"{OBJECT_TYPE} {SCENE_TYPE}" if uses["exists"] else OBJECT_TYPE
    lines += [f"(define (domain {pddl_name(name)})", f"  {_requirements(*flags)}", f"  (:types {types})"]
    lines += [f"  (:constants {SCENE_CONSTANT} - {SCENE_TYPE})"] if uses["exists"] else []
    lines += [f"  (:predicates {preds})"]
    lines += actions + [")", ""]
    return "\n".join(lines)


def checked_task(rules: RuleSet, init: Sequence[int], goal: SymbolicGoal | Sequence[int | None]) -> tuple[tuple[int, ...], SymbolicGoal]:
    """(init codes, goal) checked against the rules' vocabulary; ValueError names the problem."""
    init_t = tuple(int(c) for c in init)
    goal_g = goal if isinstance(goal, SymbolicGoal) else SymbolicGoal(tuple(goal))
    if not init_t:
        raise ValueError("a problem needs at least one object")
    if len(goal_g.codes) != len(init_t):
        raise ValueError(f"goal has {len(goal_g.codes)} objects, init has {len(init_t)}")
    known = set(rules.codes)
    unknown = sorted({c for c in init_t + goal_g.codes if c is not None} - known)
    if unknown:
        raise ValueError(f"codes {unknown} are not in the learned vocabulary (no PDDL predicate); "
                         "add them to the vocabulary before distilling")
    return init_t, goal_g


def task_codes(init: Sequence[int], goal: SymbolicGoal | Sequence[int | None]) -> frozenset[int]:
    """Every code a task names: the initial codes and the goal's fixed ones."""
    fixed = goal.codes if isinstance(goal, SymbolicGoal) else goal
    return frozenset(int(c) for c in (*init, *fixed) if c is not None)


def _goal_text(goal: SymbolicGoal, bits: int) -> str:
    atoms = [f"({code_predicate(c, bits)} {object_name(i)})" for i, c in enumerate(goal.codes) if c is not None]
    return f"(:goal (and {' '.join(atoms)}))"


def problem_pddl(
    rules: RuleSet,
    init: Sequence[int],
    goal: SymbolicGoal | Sequence[int | None],
    model_hash: str,
    name: str = "task",
    domain_name: str = "symlearn",
) -> str:
    """Problem text for the conditional form: objects o0.., their codes, the fixed goal codes."""
    init_t, goal_g = checked_task(rules, init, goal)
    bits = rules.bits
    objs = " ".join(object_name(i) for i in range(len(init_t)))
    facts = " ".join(f"({code_predicate(c, bits)} {object_name(i)})" for i, c in enumerate(init_t))
    lines = _header("problem", model_hash, rules, [f"objects: {len(init_t)}"])
    lines += [f"(define (problem {pddl_name(name)})", f"  (:domain {pddl_name(domain_name)})",
              f"  (:objects {objs} - {OBJECT_TYPE})", f"  (:init {facts})",
              f"  {_goal_text(goal_g, bits)})", ""]
    return "\n".join(lines)


# ----------------------------------------------------------------------------- STRIPS form


class StateLimitError(RuntimeError):
    """The reachable joint state space is larger than max_states."""


@dataclass(frozen=True)
class StripsTask:
    """A grounded STRIPS domain and problem for one initial state, as text and as the data behind it."""

    domain: str
    problem: str
    n_states: int  # reachable joint states
    n_actions: int  # ground actions (state, real action) that change something
    states: tuple[tuple[int, ...], ...] = ()  # the reachable joint states, states[0] the initial one
    edges: tuple[tuple[int, int, int], ...] = ()  # ground actions: (state index, action id, next state index)
    goal: tuple[int | None, ...] = ()
    bits: int = 0
    codes: tuple[int, ...] = ()  # the code predicates the domain declares
    name: str = "task"  # the problem's PDDL name

    def __post_init__(self) -> None:
        if self.n_states < 1 or self.n_actions < 0:
            raise ValueError("need n_states >= 1 and n_actions >= 0")


def reachable_transitions(rules: RuleSet, init: Sequence[int], max_states: int = 100_000) -> tuple[list[tuple[int, ...]], list[tuple[int, int, int]]]:
    """Breadth-first reachable joint states and their changing edges (state index, action, next index).

    States are numbered in breadth-first order; each layer is expanded with one batched
    apply_rules_batch call over (frontier states x actions with rules).
    """
    start = tuple(int(c) for c in init)
    index, states = {start: 0}, [start]
    edges: list[tuple[int, int, int]] = []
    actions = np.array(rules.actions, np.int64)
    frontier = [0]
    while frontier and len(actions):
        pre = np.array([states[i] for i in frontier], np.int64)  # (F, K)
        nxt = apply_rules_batch(rules, np.repeat(pre, len(actions), axis=0), np.tile(actions, len(pre)))
        new_frontier = []
        for r, row in enumerate(nxt.tolist()):
            i, a, succ = frontier[r // len(actions)], int(actions[r % len(actions)]), tuple(row)
            if succ == states[i]:
                continue
            if succ not in index:
                if len(states) >= max_states:
                    raise StateLimitError(
                        f"more than {max_states} joint states reachable from {list(start)}; "
                        "use the conditional form or raise max_states")
                index[succ] = len(states)
                states.append(succ)
                new_frontier.append(index[succ])
            edges.append((i, a, index[succ]))
        frontier = new_frontier
    return states, edges


def strips_pddl(
    rules: RuleSet,
    init: Sequence[int],
    goal: SymbolicGoal | Sequence[int | None],
    model_hash: str,
    name: str = "task",
    domain_name: str = "symlearn-strips",
    max_states: int = 100_000,
) -> StripsTask:
    """Grounded STRIPS domain + problem over the states reachable from `init` (see module doc).

    Codes outside the vocabulary are inert (RuleSet.with_codes) and get predicates of their own."""
    rules = rules.with_codes(task_codes(init, goal))
    init_t, goal_g = checked_task(rules, init, goal)
    bits = rules.bits
    states, edges = reachable_transitions(rules, init_t, max_states)
    objs = [object_name(i) for i in range(len(init_t))]

    def atom(code: int, i: int) -> str:
        return f"({code_predicate(code, bits)} {objs[i]})"

    actions = []
    for i, a, j in edges:
        pre, post = states[i], states[j]
        eff = [x for k, (c, d) in enumerate(zip(pre, post)) if c != d for x in (f"(not {atom(c, k)})", atom(d, k))]
        actions.append(
            f"  (:action {action_name(a)}-s{i}\n    :parameters ()\n"
            f"    :precondition (and {' '.join(atom(c, k) for k, c in enumerate(pre))})\n"
            f"    :effect (and {' '.join(eff)}))")
    codes = sorted(set(rules.codes) | {c for s in states for c in s})
    preds = " ".join(f"({code_predicate(c, bits)} ?o - {OBJECT_TYPE})" for c in codes)
    extra = [f"objects: {len(objs)}", f"reachable states: {len(states)}", f"ground actions: {len(actions)}"]
    dom = _header("domain (grounded STRIPS form)", model_hash, rules, extra)
    dom += [f"(define (domain {pddl_name(domain_name)})", f"  {_requirements(':strips', ':typing')}",
            f"  (:types {OBJECT_TYPE})", f"  (:constants {' '.join(objs)} - {OBJECT_TYPE})",
            f"  (:predicates {preds})"]
    dom += actions + [")", ""]
    prob = _header("problem (grounded STRIPS form)", model_hash, rules, extra[:1])
    prob += [f"(define (problem {pddl_name(name)})", f"  (:domain {pddl_name(domain_name)})",
             f"  (:init {' '.join(atom(c, k) for k, c in enumerate(init_t))})",
             f"  {_goal_text(goal_g, bits)})", ""]
    return StripsTask("\n".join(dom), "\n".join(prob), len(states), len(actions), states=tuple(states),
                      edges=tuple(edges), goal=goal_g.codes, bits=bits, codes=tuple(codes), name=pddl_name(name))
