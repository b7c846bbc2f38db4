"""How well m(z) predicts: one-step and multi-step (rollout) accuracies against the encoder's codes.

Accuracies are per bit, per object code and per whole scene, over real objects; the copy
baseline (no code changes) shows how much of that a do-nothing model already gets.
"""
from __future__ import annotations

import math

import numpy as np

from symlearn.symbolic.transition_data import TransitionData
from symlearn.symbolic.transition_model import TransitionNet, predict_bits, predict_scored

ROLLOUT_STEPS = 8  # multi-step accuracy is reported for 1..ROLLOUT_STEPS actions (the depth benchmark goes to 8)


def accuracies(pred: np.ndarray, truth: np.ndarray, mask: np.ndarray) -> dict[str, float | int]:
    """Bit, per-object code and whole-scene accuracy over real objects."""
    if mask.sum() == 0:
        return {"bit_accuracy": math.nan, "object_accuracy": math.nan, "scene_accuracy": math.nan, "n": 0}
    bit_ok = pred == truth  # (N, K, bits)
    obj_ok = bit_ok.all(-1)  # (N, K)
    scene_ok = (obj_ok | ~mask).all(-1)  # (N,)
    return {"bit_accuracy": round(float(bit_ok[mask].mean()), 5),
            "object_accuracy": round(float(obj_ok[mask].mean()), 5),
            "scene_accuracy": round(float(scene_ok.mean()), 5), "n": int(mask.shape[0])}


def rollout_chains(data: TransitionData, n: int) -> np.ndarray:
    """(M, n) sample indices of every run of n consecutive steps of one episode."""
    index = {(int(e), int(s)): i for i, (e, s) in enumerate(zip(data.episode, data.step))}
    chains = []
    for i, (e, s) in enumerate(zip(data.episode.tolist(), data.step.tolist())):
        row = [i]
        for j in range(1, n):
            nxt = index.get((e, s + j))
            if nxt is None:
                break
            row.append(nxt)
        if len(row) == n:
            chains.append(row)
    return np.asarray(chains, np.int64).reshape(-1, n)


def rollout(net: TransitionNet, data: TransitionData, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """m(z) rolled n actions along every n-step run of an episode: chains (M, n), predicted codes (M, K, bits)
    after the last action, and each rollout's -log P (M,), its steps scored on the predicted states they start from."""
    chains = rollout_chains(data, n)
    mask = data.mask[chains[:, 0]]
    state, nll = data.before[chains[:, 0]], np.zeros(len(chains))
    for j in range(n):
        state, step = predict_scored(net, state, mask, data.action[chains[:, j]])
        nll += step
    return chains, state, nll


def rollout_accuracy(net: TransitionNet, data: TransitionData, n: int) -> dict[str, float | int]:
    """Roll m(z) n actions forward from the encoder's codes at t; compare with the codes of the real state at t+n."""
    chains, state, _ = rollout(net, data, n)
    if len(chains) == 0:
        return {"object_accuracy": math.nan, "scene_accuracy": math.nan, "bit_accuracy": math.nan, "n": 0}
    return accuracies(state, data.after[chains[:, -1]], data.mask[chains[:, 0]])


def evaluate_transition(net: TransitionNet, data: TransitionData) -> dict:
    """One-step accuracies, the copy baseline (no code changes) and 1..ROLLOUT_STEPS rollout accuracies."""
    pred = predict_bits(net, data.before, data.mask, data.action)
    return {**accuracies(pred, data.after, data.mask),
            "copy_baseline": accuracies(data.before, data.after, data.mask),
            "rollout": {str(n): rollout_accuracy(net, data, n) for n in range(1, ROLLOUT_STEPS + 1)}}
