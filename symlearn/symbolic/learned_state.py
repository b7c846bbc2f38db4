"""The symbolic state a planner reads on the learned route: what the relational model computes from the crops.

Objects are named o1..ok in the order the scene lists them, locations l0..l5. A state holds
`(at o l)` from relation head 0, `(rK a b)` from object-object head K (`(on a b)` for a rests-on head) and
`(uB o)` for each set bit B of o's unary code, with the closed world's negations a STRIPS operator needs:
`(nothing-rK b)` (`(clear b)`) when no object relates to b by head K, `(on-table a)` when a rests on no object,
and `(empty l)` when no object is at l. Nothing here reads a pose, a location field or
a simulator label.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np
import torch

from pddl_export.learned_domain import Atom, Transition
from symlearn.data.dataset import load_split
from symlearn.learning.entities import entity_inputs, location_crops


def head_names(n_heads: int, support: bool) -> list[str]:
    """The predicate of each object-object head 1..n_heads-1: `on` for a rests-on head (model.support), else rK."""
    return ["at"] + [("on" if support and h == 1 else f"r{h}") for h in range(1, n_heads)]


def atoms_of(codes: np.ndarray, rel: np.ndarray, n_objects: int, support: bool = False) -> frozenset[Atom]:
    """One scene's atoms from its object codes (K, bits) and relations (R, E, E), E = K + 6; with `support`,
    head 1 is rests-on, written `(on a b)`, `(clear b)` when nothing rests on b and `(on-table a)` when a rests on
    no object."""
    k = codes.shape[0]
    names = head_names(rel.shape[0], support)
    out: set[Atom] = set()
    for i in range(n_objects):
        o = f"o{i + 1}"
        out.update((f"u{b}", o) for b in np.flatnonzero(codes[i] > 0.5))
        out.update(("at", o, f"l{j}") for j in np.flatnonzero(rel[0, i, k:] > 0.5))
        for h in range(1, rel.shape[0]):
            out.update((names[h], o, f"o{j + 1}") for j in np.flatnonzero(rel[h, i, :n_objects] > 0.5))
    # the closed world's negations of the relations, as atoms a STRIPS operator can test and change
    objects = [f"o{i + 1}" for i in range(n_objects)]
    for h in range(1, rel.shape[0]):
        negation = "clear" if names[h] == "on" else f"nothing-{names[h]}"
        out.update((negation, o) for o in objects if not any((names[h], a, o) in out for a in objects))
        if names[h] == "on":
            out.update(("on-table", o) for o in objects if not any(("on", o, b) in out for b in objects))
    for j in range(rel.shape[-1] - k):
        if not any(("at", o, f"l{j}") in out for o in objects):
            out.add(("empty", f"l{j}"))
    return frozenset(out)


@torch.no_grad()
def scene_symbols(model, windows: np.ndarray, depth: np.ndarray, origin: np.ndarray, n_objects: np.ndarray,
                  batch_size: int = 256) -> tuple[np.ndarray, np.ndarray]:
    """(N, K, 64, 64) crops, (N, K, 2) origins, (N,) counts -> codes (N, K, bits) and relations (N, R, E, E)."""
    loc = location_crops(depth, origin, n_objects, windows)
    codes, rels = [], []
    k = depth.shape[1]
    for a in range(0, len(depth), batch_size):
        sl = slice(a, a + batch_size)
        obj, loc_in = entity_inputs(depth[sl], origin[sl], loc[sl], windows)
        mask = torch.from_numpy(np.arange(k)[None] < n_objects[sl, None])
        c, _, r, _, _ = model.symbols(obj, mask, loc_in)
        codes.append(c.numpy())
        rels.append(r.numpy())
    return np.concatenate(codes), np.concatenate(rels)


def data_transitions(model, blob: dict, roots: Sequence[Path], split: str) -> list[Transition]:
    """Every sample of a split of the data sets as a Transition between learned symbolic states."""
    windows = blob["windows"].numpy()
    support = model.cfg.support
    out = []
    for root in roots:
        d = load_split(Path(root), split)
        pre = scene_symbols(model, windows, d.pre_depth, d.pre_origin, d.n_objects)
        post = scene_symbols(model, windows, d.post_depth, d.post_origin, d.n_objects)
        for i in range(len(d)):
            n, a = int(d.n_objects[i]), int(d.action[i])
            out.append(Transition(atoms_of(pre[0][i], pre[1][i], n, support),
                                  atoms_of(post[0][i], post[1][i], n, support), f"l{a // 6}", f"l{a % 6}"))
    return out
