"""What the rules' symmetry in objects gives a search: a dead-end test and smaller state spaces.

A rule fires on an object from its own code and the counts of codes among the OTHER objects,
never from which object it is. Two consequences, both exact for any RuleSet:

- Objects holding the same code see the same counts, so every action sends them to the same
  code: once equal, always equal. A goal that asks different codes of two objects is out of
  reach from any state where they coincide (`coincident`), a sound dead-end test.
- Permuting objects commutes with every action, so states that differ only by a permutation
  of objects with the same goal (the same goal code, or both free) have the same plans.
  Sorting the codes within each such class (`canonical`) searches one state per orbit; the
  actions of a plan found there replay unchanged on the real objects (`replay`).

    >>> goal = (5, 7, 5, None, None)
    >>> split_pairs(goal).tolist()
    [[0, 1], [1, 2]]
    >>> coincident(np.array([[3, 3, 4, 1, 1], [3, 4, 3, 1, 1]]), split_pairs(goal)).tolist()
    [True, False]
    >>> canonical(np.array([[9, 1, 2, 8, 6]]), goal_classes(goal)).tolist()
    [[2, 1, 9, 6, 8]]
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np


def split_pairs(goal: Sequence[int | None]) -> np.ndarray:
    """(P, 2) object pairs i < j whose goal codes are both given and differ: they must not coincide."""
    k = len(goal)
    pairs = [(i, j) for i in range(k) for j in range(i + 1, k)
             if goal[i] is not None and goal[j] is not None and goal[i] != goal[j]]
    return np.array(pairs, np.int64).reshape(-1, 2)


def coincident(states: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(F,) True where some pair of `pairs` holds one code: no plan reaches the goal from there."""
    states = np.asarray(states)
    if not len(pairs):
        return np.zeros(len(states), bool)
    return (states[:, pairs[:, 0]] == states[:, pairs[:, 1]]).any(axis=1)


def goal_classes(goal: Sequence[int | None]) -> tuple[np.ndarray, ...]:
    """Objects grouped by goal code (free objects form one group); only groups of two or more."""
    groups: dict[int | None, list[int]] = {}
    for i, c in enumerate(goal):
        groups.setdefault(c, []).append(i)
    return tuple(np.array(g, np.int64) for g in groups.values() if len(g) > 1)


def canonical(states: np.ndarray, classes: Sequence[np.ndarray]) -> np.ndarray:
    """states (..., K) with the codes sorted within each class: one representative per orbit."""
    if not classes:
        return states
    states = np.array(states, copy=True)
    for members in classes:
        states[..., members] = np.sort(states[..., members], axis=-1)
    return states


def replay(step: Callable[[np.ndarray], np.ndarray], actions: np.ndarray, start: Sequence[int],
           plan: Sequence[int]) -> tuple[tuple[int, ...], ...]:
    """The states a plan passes through from start under step: (F, K) -> (F, A, K) over `actions`."""
    column = {int(a): i for i, a in enumerate(actions)}
    state = np.asarray(start, np.int64)
    states = [tuple(int(c) for c in state)]
    for a in plan:
        state = step(state[None])[0, column[int(a)]]
        states.append(tuple(int(c) for c in state))
    return tuple(states)
