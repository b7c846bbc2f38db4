"""The terms that shape the relational model's symbols (symlearn.learning.relational) from what the robot saw.

Effect prediction alone trains the model; these terms tie its relations to the robot's own experience, never to a
pose or a label: where the suction tool held an object (`grasp_loss`, or `cover_loss` for a cover model), what rode
along with it and what stayed where it was picked (`ride_loss`, `support_loss`), where it was let go
(`post_support_loss`), at most one object on each (`support_exclusion`), and object-object relations kept off where
they do not help (`relation_density`). symlearn.learning.relational_training weighs them (RelationalTrainConfig).
"""
from __future__ import annotations

import torch
import torch.nn.functional as F

from symlearn.world import N_LOCATIONS


def grasp_loss(logits: torch.Tensor, held: torch.Tensor, actions: torch.Tensor, k: int) -> torch.Tensor:
    """Cross-entropy of at(o, .) for the object the robot grasped, against the action's pick location.

    The robot knows what it did: when its suction tool held an object, that object stood at the pick location.
    This is the one signal that ties the learned at(o, l) to a place; every other object's at(o, l) comes from
    the same pair network, never from a label."""
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if not len(rows):
        return logits.new_zeros(())
    at_logits = logits[rows, 0, held[rows], k:]  # (n, L)
    return F.cross_entropy(at_logits, actions[rows] // N_LOCATIONS)


def cover_loss(logits: torch.Tensor, held: torch.Tensor, where: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Binary cross-entropy of a cover model's at(o, l) (model.cover) from what the robot's tool met at `where`
    ((B,) location indices: the pick location, or the release location on the scene after the action):
    - the object the suction tool held covers that location (it was lifted there, or let go there);
    - where a pick lifted nothing, no object covers the location (an empty cell; on the scene after, too).
    Nothing is said of an object under the held one, nor of cells no pick tried: the pair network carries what it
    learned to them. The robot's own experience, no pose: this is what "a pick at l lifts o" means.

    Tried on dev and left out: also clearing the grasped cell of every object not under the held one (by the
    model's own rests-on reading) took rel_dev from 0.875 to 0.50 (stacks' lower objects lost their location), and
    adding what it stands on as covering the cell, to 0.725."""
    k = mask.shape[1]
    at_logits = logits[:, 0, :k, k:]  # (B, K, L)
    rows = torch.arange(len(held), device=held.device)
    at_where = at_logits[rows, :, where]  # (B, K): at(o, where) of every object
    grasped = held >= 0
    pos = torch.zeros_like(mask)
    pos[rows[grasped], held[grasped]] = True
    neg = mask & ~grasped[:, None]
    labelled = pos | neg
    if not labelled.any():
        return logits.new_zeros(())
    return F.binary_cross_entropy_with_logits(at_where[labelled], pos[labelled].to(logits.dtype))


def ride_loss(logits: torch.Tensor, held: torch.Tensor, rider: torch.Tensor, mask: torch.Tensor,
              at: torch.Tensor | None = None, actions: torch.Tensor | None = None) -> torch.Tensor:
    """Binary cross-entropy that makes r1(a, b) say "a rests on b", from what the robot saw its grasp do.

    - r1(a, held): whether object a rode along with the held object (an effect the robot saw; a stack beside
      the stick that did not move is a negative example);
    - r1(held, b) = 1 for every object b that stayed at the pick location, as the model's own at(o, l) places
      them (`at`, (B, K+L, K+L) relation 0, detached; `actions` give the pick location): a pick lifts the top
      object, so whatever stays where it was picked lay under it.
    """
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if not len(rows):
        return logits.new_zeros(())
    k = mask.shape[1]
    h = held[rows]
    row_logits = logits[rows, 1, :k, h]  # (n, K): r1(a, held) for every a of the scene
    others = mask[rows] & (torch.arange(k, device=mask.device)[None] != h[:, None])
    loss = F.binary_cross_entropy_with_logits(row_logits[others], rider[rows][others].to(logits.dtype))
    if at is None or actions is None:
        return loss
    pick = actions[rows] // N_LOCATIONS
    at_pick = at[rows, :k, k:][torch.arange(len(rows)), :, pick] > 0.5  # (n, K): placed at the pick location
    under = others & at_pick & ~rider[rows]
    if under.any():
        col_logits = logits[rows, 1, h, :k]  # (n, K): r1(held, b)
        loss = loss + F.binary_cross_entropy_with_logits(col_logits[under], torch.ones_like(col_logits[under]))
    return loss


def log_prob_of(logp: torch.Tensor, members: torch.Tensor) -> torch.Tensor:
    """log P(the choice is one of `members`) from log-probabilities over the last axis and a same-shape bool mask."""
    return torch.logsumexp(logp.masked_fill(~members, -1e4), -1)


def support_loss(logits: torch.Tensor, held: torch.Tensor, rider: torch.Tensor, mask: torch.Tensor,
                 at: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
    """Cross-entropy of the rests-on head (relation 1 of a model.support model) from what the robot saw its grasp do.

    Head 1 picks, for each object a, one support: another object b (logits[.., 1, a, b]) or the table (the
    diagonal). In a scene where the suction tool held object h (picked at location p):
    - h rests on one of the objects that stayed at p (the model's own at, detached), or on the table if none did:
      a pick lifts the top object, so what stays where it was picked lay under it;
    - an object that rode along rests on h or on another rider;
    - an object that did not ride rests on neither h nor a rider.
    Each is a set-valued target (the log of the probability summed over the set), so a three-object stack does
    not have to say which of the two below it h touches; the network learns that from two-object stacks."""
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if not len(rows):
        return logits.new_zeros(())
    k = mask.shape[1]
    n = len(rows)
    ar = torch.arange(n, device=mask.device)
    h, m, rid = held[rows], mask[rows], rider[rows]
    logp = torch.log_softmax(logits[rows, 1, :k, :k], -1)  # (n, K, K); the diagonal is "on the table"
    eye = torch.eye(k, dtype=torch.bool, device=mask.device)[None]
    is_h = F.one_hot(h, k).bool()
    pick = actions[rows] // N_LOCATIONS
    stayed = m & ~is_h & ~rid & (at[rows, :k, k:][ar, :, pick] > 0.5)  # (n, K)
    target_h = torch.where(stayed.any(1, keepdim=True), stayed, is_h)  # h's candidates (or itself: the table)
    loss_h = -log_prob_of(logp[ar, h], target_h)
    carried = is_h | rid  # (n, K): h and its riders
    loss = loss_h.mean()
    sets = carried[:, None, :] & ~eye  # (n, K, K): for object a, the carried objects other than itself
    lse = log_prob_of(logp, sets)  # (n, K): log P(a rests on a carried object)
    riders = rid & m
    if riders.any():
        loss = loss - lse[riders].mean()
    still = m & ~carried
    if still.any():
        loss = loss - torch.log1p(-lse[still].exp().clamp(max=1 - 1e-6)).mean()
    return loss


def post_support_loss(pre_logits: torch.Tensor, post_logits: torch.Tensor, held: torch.Tensor, rider: torch.Tensor,
                      mask: torch.Tensor, post_at: torch.Tensor, actions: torch.Tensor) -> torch.Tensor:
    """The rests-on head read on the scene after the action (model.support), from what the robot did:
    - where it released the held object h (location r), h now rests on one of the objects at r that it did not
      carry there (the model's own at on the scene after, detached), or on the table if there is none;
    - every other object rests on what it rested on before (a pick-and-place moves only h and its riders, which
      keep their supports): the cross-entropy of its support after against its support before, both ways.
    Scenes where nothing was held (a pick at an empty location) change nothing: every object keeps its support."""
    k = mask.shape[1]
    eye = torch.eye(k, dtype=torch.bool, device=mask.device)[None]
    pre = torch.log_softmax(pre_logits[:, 1, :k, :k], -1)
    post = torch.log_softmax(post_logits[:, 1, :k, :k], -1)
    is_h = F.one_hot(held.clamp_min(0), k).bool() & (held >= 0)[:, None]
    keep = mask & ~is_h  # (B, K)
    loss = pre.new_zeros(())
    if keep.any():  # symmetric cross-entropy of the two supports (each side detached in turn)
        ce = -(pre.exp().detach() * post).sum(-1) - (post.exp().detach() * pre).sum(-1)
        loss = loss + ce[keep].mean() / 2
    rows = torch.nonzero(held >= 0).squeeze(-1)
    if len(rows):
        ar = torch.arange(len(rows), device=mask.device)
        h = held[rows]
        release = actions[rows] % N_LOCATIONS
        carried = is_h[rows] | rider[rows]
        below = mask[rows] & ~carried & (post_at[rows, :k, k:][ar, :, release] > 0.5)
        target = torch.where(below.any(1, keepdim=True), below, is_h[rows])
        loss = loss - log_prob_of(post[rows][ar, h], target).mean()
    return loss


def support_exclusion(logits: torch.Tensor, mask: torch.Tensor, spared: torch.Tensor | None = None) -> torch.Tensor:
    """Mean squared excess over one of the objects resting on each object (rests-on probabilities summed per
    support): in a three-object stack the top rests on the middle one, not also on the bottom one, which the
    grasp alone cannot tell (both stayed where the top was picked). A stick with a cube on each end is the
    exception: `spared` (B, K) bool marks supports the robot saw carry two or more riders, left out of the
    penalty (without it the penalty pays for them; they are rare in the paper's data)."""
    k = mask.shape[1]
    eye = torch.eye(k, dtype=torch.bool, device=mask.device)[None]
    p = torch.softmax(logits[:, 1, :k, :k], -1).masked_fill(eye, 0.0) * mask[:, :, None]
    excess = F.relu(p.sum(1) - 1.0) * mask
    if spared is not None:
        excess = excess * ~spared
    return (excess ** 2).sum() / mask.sum().clamp_min(1)


def relation_density(logits: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
    """Mean probability of the object-object relations (heads 1.. of (B, R, E, E) logits) over the real pairs: a
    penalty that keeps a relation off where it does not help predict effects."""
    k = mask.shape[1]
    pairs = (mask[:, :, None] & mask[:, None, :] & ~torch.eye(k, dtype=torch.bool, device=mask.device)[None])
    p = torch.sigmoid(logits[:, 1:, :k, :k]) * pairs[:, None]
    return p.sum() / (pairs.sum() * (logits.shape[1] - 1)).clamp_min(1)
