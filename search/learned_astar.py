"""A* over symbolic states, with a (learned) TransitionFn as the successor model.

    result = plan_symbolic(transition, np.array([3, 0, 12]), SymbolicGoal((3, None, 7)),
                           uniform_cost=True)
    if result.found:
        print(result.plan, result.predicted_states[-1])  # action ids, predicted final codes

States are tuples of per-object integer codes; every action costs 1, and actions that leave
the state unchanged (self-loops) are skipped.

Batching: each expansion evaluates all 36 actions in one call,
`transition(np.repeat(state[None], 36, 0), np.arange(36))`. For the learned model the forward
pass (attention over K objects) dominates the cost of an expansion, and 36 rows cost about as
much as one, so one call per expansion is ~36x cheaper than one call per action.

Heuristic: the number of goal-fixed objects whose code differs from the goal. It is NOT
admissible in general: one action can change several objects at once (pushing a stick moves
the cube riding on it), so h can exceed the remaining plan length and A* may return a longer
plan than needed. A* stays complete with it (finite state space, re-opening on cheaper paths).
Pass uniform_cost=True (h = 0, breadth-first order) for plans of optimal length.

Most likely plans: with risk_weight w > 0 an action costs 1 + w * (-log P(its predicted next
state)), read from a ScoredTransitionFn's `scored`. Among plans of similar length A* then
prefers those whose every prediction the model is sure of, the plans most likely to unfold in
the world as predicted (m(z)'s confidence is calibrated on held-out steps: docs/RESULTS.md).
The mismatch heuristic is then counted in cost units, times the median cost of the start's actions,
so that the search stays as greedy as with unit costs. The result's extra["log_p"] is the plan's
summed log-probability.

All outcomes: with max_outcomes n > 1 (and w > 0), an action leads not only to the network's most
likely next state but to each of its n most likely outcomes that is at least min_outcome_ratio times
as likely, each costing 1 + w * (-log P(that outcome)): the all-outcomes determinization of
FF-Replan (Yoon, Fern and Givan, ICAPS 2007), read from an OutcomeTransitionFn's bit probabilities.
A goal that the network's most likely predictions never reach, but a likely enough other outcome
does, then gets a plan; execution checks each step and replans when the world picks another outcome.
The bits are independent given the input, so the n most likely outcomes are the likeliest state with
subsets of its n - 1 least certain bits flipped (exact: any other flip is less likely than each of these).
A mixture m(z) (a transition with `modes` > 1 and `mode_outcomes`) names its outcomes itself: each
mode's likeliest state, however many bits apart, scored under the whole mixture.
"""
from __future__ import annotations

import time

import numpy as np

from search.astar import astar, outcome_result
from search.result import PlanResult
from pddl_export.symbolic import (N_ACTIONS, OutcomeTransitionFn, ScoredTransitionFn, SymbolicGoal, TransitionFn,
                                  bit_flip_costs, codes_from_bits)

State = tuple[int, ...]
MAX_OUTCOMES = 9  # likely_outcomes enumerates 2**(max_outcomes - 1) flip subsets per action


def _check_codes(codes: np.ndarray, shape: tuple[int, ...], bits: int, what: str) -> None:
    """Refuse arrays of the wrong shape, non-integer dtype, or codes outside 0..2**bits - 1."""
    if codes.shape != shape:
        raise ValueError(f"{what} has shape {codes.shape}, expected {shape}")
    if not np.issubdtype(codes.dtype, np.integer):
        raise ValueError(f"{what} must hold integer codes, got dtype {codes.dtype}")
    if codes.size and (codes.min() < 0 or codes.max() >= 1 << bits):
        raise ValueError(f"{what} holds codes outside 0..{(1 << bits) - 1} ({bits} bits)")


def symbolic_successors(transition: TransitionFn, state: State) -> list[tuple[int, State]]:
    """(action, next_state) for each action that changes state; one batched call of 36 rows."""
    return [(a, nxt) for a, nxt, _ in scored_successors(transition, state, scored=False)]


def scored_successors(transition: TransitionFn | ScoredTransitionFn, state: State,
                      scored: bool = True) -> list[tuple[int, State, float]]:
    """(action, next_state, -log P(next_state)) for each action that changes state (0.0 when not scored)."""
    batch = np.repeat(np.asarray(state, np.int64)[None], N_ACTIONS, 0)  # (36, K)
    actions = np.arange(N_ACTIONS, dtype=np.int64)
    if scored:
        nxt, nll = transition.scored(batch, actions)
        nxt, nll = np.asarray(nxt), np.asarray(nll, np.float64)
        if nll.shape != (N_ACTIONS,) or not np.all(np.isfinite(nll)) or nll.min() < 0:
            raise ValueError(f"transition scores must be (36,) finite and >= 0, got {nll.shape}")
    else:
        nxt, nll = np.asarray(transition(batch, actions)), np.zeros(N_ACTIONS)
    _check_codes(nxt, (N_ACTIONS, len(state)), int(transition.bits), "transition output")
    moved = np.flatnonzero(np.any(nxt != batch, axis=1))  # self-loops dropped
    rows = nxt.tolist()
    return [(int(a), tuple(rows[a]), float(nll[a])) for a in moved]


def likely_outcomes(probs: np.ndarray, max_outcomes: int, min_ratio: float) -> list[list[tuple[State, float]]]:
    """Per row of (A, K, bits) bit probabilities: its most likely next states with their -log P, likeliest first.

    At most max_outcomes per row, each at least min_ratio times as likely as the row's likeliest state
    (which always comes first). Bits are independent, so flipping bit b multiplies P by q_b / (1 - q_b),
    q_b the probability of the value it does not take in the likeliest state.
    """
    probs = np.asarray(probs, np.float64)
    n_rows, k, bits = probs.shape
    top, flip_bits = bit_flip_costs(probs)
    base = -np.log(np.where(top, probs, 1.0 - probs)).sum((1, 2))  # (A,) -log P(likeliest state)
    flip = flip_bits.reshape(n_rows, k * bits)  # extra -log P of one flip, >= 0, inf where certain
    n_cand = min(max_outcomes - 1, k * bits)
    cand = np.argsort(flip, axis=1, kind="stable")[:, :n_cand]  # (A, n_cand) the least certain bits
    subsets = ((np.arange(1 << n_cand)[:, None] >> np.arange(n_cand)) & 1).astype(bool)  # (S, n_cand), [0] = none
    extra = np.where(subsets[None], np.take_along_axis(flip, cand, 1)[:, None, :], 0.0).sum(-1)  # (A, S)
    # each subset's flips as one XOR mask per object: candidates are distinct bits, so summing them is XOR
    value = np.left_shift(1, bits - 1 - cand % bits)[..., None] * (cand[..., None] // bits == np.arange(k))  # (A, n_cand, K)
    states = codes_from_bits(top)[:, None, :] ^ (subsets[None, :, :, None] * value[:, None]).sum(2)  # (A, S, K)
    order = np.argsort(extra, axis=1, kind="stable")[:, :max_outcomes]  # (A, <= max_outcomes), likeliest first
    nll = base[:, None] + np.take_along_axis(extra, order, 1)
    keep = np.take_along_axis(extra, order, 1) <= -np.log(min_ratio)
    picked = np.take_along_axis(states, order[..., None], 1).tolist()
    return [[(tuple(picked[r][j]), float(nll[r, j])) for j in range(order.shape[1]) if keep[r, j]]
            for r in range(n_rows)]


def outcome_successors(transition: OutcomeTransitionFn, state: State, max_outcomes: int,
                       min_ratio: float) -> list[tuple[int, State, float]]:
    """(action, next_state, -log P) for each likely outcome of each action that changes state; one batched call."""
    if int(getattr(transition, "modes", 1)) > 1 and callable(getattr(transition, "mode_outcomes", None)):
        return mode_successors(transition, state, max_outcomes, min_ratio)
    batch = np.repeat(np.asarray(state, np.int64)[None], N_ACTIONS, 0)  # (36, K)
    bits = int(transition.bits)
    probs = np.asarray(transition.bit_probabilities(batch, np.arange(N_ACTIONS, dtype=np.int64)), np.float64)
    if probs.shape != (N_ACTIONS, len(state), bits) or not np.all((probs >= 0) & (probs <= 1)):
        raise ValueError(f"bit probabilities must be (36, {len(state)}, {bits}) in [0, 1], got shape {probs.shape}")
    return [(a, nxt, nll) for a, row in enumerate(likely_outcomes(probs, max_outcomes, min_ratio))
            for nxt, nll in row if nxt != state]


def mode_successors(transition, state: State, max_outcomes: int, min_ratio: float) -> list[tuple[int, State, float]]:
    """As outcome_successors, from a mixture's modes: per action its distinct mode states, likeliest first,
    at most max_outcomes, each at least min_ratio times as likely as the likeliest."""
    batch = np.repeat(np.asarray(state, np.int64)[None], N_ACTIONS, 0)
    states, nll = transition.mode_outcomes(batch, np.arange(N_ACTIONS, dtype=np.int64))
    states, nll = np.asarray(states, np.int64), np.asarray(nll, np.float64)
    if states.ndim != 3 or states.shape[::2] != (N_ACTIONS, len(state)) or nll.shape != states.shape[:2]:
        raise ValueError(f"mode outcomes must be (36, M, {len(state)}) states and (36, M) -log P, "
                         f"got {states.shape} and {nll.shape}")
    _check_codes(states.reshape(-1, len(state)), (states.shape[0] * states.shape[1], len(state)),
                 int(transition.bits), "mode outcome")
    order, limit, out = np.argsort(nll, axis=1, kind="stable"), -np.log(min_ratio), []
    for a in range(N_ACTIONS):
        kept: set[State] = set()
        for j in order[a]:
            if len(kept) == max_outcomes or nll[a, j] - nll[a, order[a, 0]] > limit:
                break
            nxt = tuple(states[a, j].tolist())
            if nxt not in kept:
                kept.add(nxt)
                if nxt != state:
                    out.append((a, nxt, float(nll[a, j])))
    return out


def _check_request(transition: TransitionFn, start_arr: np.ndarray, goal: SymbolicGoal, risk_weight: float,
                   max_outcomes: int, min_outcome_ratio: float) -> None:
    """Refuse a start or goal that does not fit the transition's codes, and costs or outcomes it cannot give."""
    bits = int(transition.bits)
    if start_arr.ndim != 1:
        raise ValueError(f"start_codes must have shape (K,), got {start_arr.shape}")
    k = start_arr.shape[0]
    if len(goal.codes) != k:
        raise ValueError(f"goal has {len(goal.codes)} objects, start_codes has {k}")
    _check_codes(start_arr, (k,), bits, "start_codes")
    if any(c is not None and not 0 <= c < 1 << bits for c in goal.codes):
        raise ValueError(f"goal {goal.codes} holds codes outside 0..{(1 << bits) - 1}")
    if not (np.isfinite(risk_weight) and risk_weight >= 0):
        raise ValueError(f"risk_weight must be a finite number >= 0, got {risk_weight}")
    scored = risk_weight > 0
    if scored and not callable(getattr(transition, "scored", None)):
        raise ValueError(f"risk_weight {risk_weight} needs a transition that scores its predictions "
                         f"(a `scored` method); {type(transition).__name__} has none")
    if not (isinstance(max_outcomes, (int, np.integer)) and 1 <= max_outcomes <= MAX_OUTCOMES):
        raise ValueError(f"max_outcomes must be an integer in 1..{MAX_OUTCOMES}, got {max_outcomes!r}")
    if not 0 < min_outcome_ratio <= 1:
        raise ValueError(f"min_outcome_ratio must lie in (0, 1], got {min_outcome_ratio}")
    if max_outcomes > 1 and not scored:
        raise ValueError("max_outcomes > 1 needs risk_weight > 0: unlikely outcomes must cost their improbability")
    if max_outcomes > 1 and not callable(getattr(transition, "bit_probabilities", None)):
        raise ValueError(f"max_outcomes {max_outcomes} needs a transition with bit probabilities "
                         f"(a `bit_probabilities` method); {type(transition).__name__} has none")


def plan_symbolic(
    transition: TransitionFn,
    start_codes: np.ndarray,
    goal: SymbolicGoal,
    *,
    max_expansions: int = 20000,
    timeout_s: float = 30.0,
    uniform_cost: bool = False,
    risk_weight: float = 0.0,
    max_outcomes: int = 1,
    min_outcome_ratio: float = 0.05,
    planner_name: str = "astar",
) -> PlanResult:
    """Plan from start_codes (K,) to a (partial) goal; one batched transition call per expansion.

    risk_weight > 0 charges each action w * (-log P) on top of its unit cost; max_outcomes > 1 also
    branches on each action's other likely outcomes (module docstring).
    """
    t0 = time.perf_counter()
    start_arr = np.asarray(start_codes)
    _check_request(transition, start_arr, goal, risk_weight, max_outcomes, min_outcome_ratio)
    scored = risk_weight > 0
    fixed = [(i, c) for i, c in enumerate(goal.codes) if c is not None]
    step_nll: dict[tuple[State, int, State], float] = {}

    def expand(state: State) -> list[tuple[int, State, float]]:
        if max_outcomes > 1:
            return outcome_successors(transition, state, max_outcomes, min_outcome_ratio)  # type: ignore[arg-type]
        return scored_successors(transition, state, scored)

    def is_goal(state: State) -> bool:
        return all(state[i] == c for i, c in fixed)

    start = tuple(start_arr.tolist())
    first = expand(start) if scored and not is_goal(start) else []
    # With risk, an action costs more than 1, so h is put in cost units (the median cost of the start's
    # actions); else A* would fall back towards breadth-first order and run out of time on bigger scenes.
    likeliest: dict[int, float] = {}  # action -> -log P of its likeliest outcome (the only one unless max_outcomes > 1)
    for a, _, nll in first:
        likeliest[a] = min(nll, likeliest.get(a, np.inf))
    scale = float(np.median([1.0 + risk_weight * nll for nll in likeliest.values()])) if first else 1.0

    def heuristic(state: State) -> float:
        return scale * sum(state[i] != c for i, c in fixed)

    def successors(state: State) -> list[tuple[int, State, float]]:
        out = []
        for a, nxt, nll in (first if state == start and first else expand(state)):
            if scored:  # kept for the plan's log_p; unit-cost search needs none of it
                step_nll[state, a, nxt] = nll
            out.append((a, nxt, 1.0 + risk_weight * nll))
        return out

    out = astar(start, is_goal, successors, heuristic,
                max_expansions=max_expansions, timeout_s=timeout_s, uniform_cost=uniform_cost)
    extra: dict = {"uniform_cost": uniform_cost, "risk_weight": risk_weight}
    if max_outcomes > 1:
        extra.update(max_outcomes=max_outcomes, min_outcome_ratio=min_outcome_ratio)
    if scored:
        extra["heuristic_scale"] = round(scale, 6)
    if scored and out.states:
        extra["log_p"] = round(-sum(step_nll[s, a, n] for s, a, n in zip(out.states, out.actions, out.states[1:])), 6)
    return outcome_result(out, planner_name, t0, timeout_s, f"max_expansions={max_expansions}",
                          f"the {out.expansions} reachable states", extra)
