"""m(z) for planners: LearnedTransition implements pddl_export.symbolic.TransitionFn on integer codes.

    >>> m = LearnedTransition.from_run(Path("runs/paper"))                                          # doctest: +SKIP
    >>> m(np.array([[3, 17]]), np.array([action_id(3, 4)]))   # (B, K) codes, (B,) actions      # doctest: +SKIP
    array([[ 3, 19]])

A* (search.learned_astar) and the PDDL export call it; `scored` adds how likely each prediction is
(the outcome planners, `astar-outcomes`, charge it), and `bit_probabilities` gives every bit's
probability, from which `astar-outcomes` draws the other likely outcomes of an action; a mixture m(z)
(`modes` > 1) gives them whole through `mode_outcomes`.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pddl_export.symbolic import bits_from_codes, codes_from_bits
from symlearn.learning.checkpoint import effect_model_sha256, load_effect_model
from symlearn.learning.models import AttentiveDeepSym
from symlearn.sim.camera import CameraConfig
from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE, TransitionError, load_transition
from symlearn.symbolic.transition_data import SymbolReader
from symlearn.symbolic.transition_model import TransitionNet, predict_modes, predict_probabilities, predict_scored
from symlearn.world import N_ACTIONS


class LearnedTransition:
    """m(z) as a pddl_export.symbolic.TransitionFn: integer codes in, thresholded integer codes out."""

    def __init__(self, net: TransitionNet, batch_size: int = 4096, location_camera: CameraConfig | None = None) -> None:
        self.net = net.eval()
        self.bits = int(net.cfg.bits)
        self.modes = int(net.cfg.modes)
        self.batch_size = batch_size
        if (location_camera is None) != (net.cfg.location_bits == 0):
            raise TransitionError(f"a transition with {net.cfg.location_bits} location bits needs "
                                  f"{'a' if net.cfg.location_bits else 'no'} camera to read them")
        self.location_camera = location_camera  # the camera location bits are read through, None without them

    def reader(self, model: AttentiveDeepSym) -> SymbolReader:
        """What turns crops into this model's codes: the effect model's encoder, plus location bits if it has them."""
        if int(model.cfg.bits) + self.net.cfg.location_bits != self.bits:
            raise TransitionError(f"an effect model of {model.cfg.bits}-bit codes cannot give this transition's "
                                  f"{self.bits}-bit codes")
        return SymbolReader(model, self.location_camera, self.net.cfg.location_bits)

    @classmethod
    def from_run(cls, run_dir: Path, check_encoder: bool = True) -> "LearnedTransition":
        """Load RUN/transition.pt; refuses one trained on another effect model than RUN/best.pt."""
        run_dir = Path(run_dir)
        net, meta = load_transition(run_dir / TRANSITION_FILE)
        if check_encoder:
            best = run_dir / "best.pt"
            if best.exists() and meta.get("effect_model_sha256") != effect_model_sha256(run_dir):
                raise TransitionError(f"{run_dir / TRANSITION_FILE} was trained on another effect model than "
                                      f"{best}; re-run 'symlearn train-transition'")
        cam = meta.get("location_camera")
        try:
            camera = None if cam is None else CameraConfig.from_json(cam)
        except (TypeError, AttributeError) as e:
            raise TransitionError(f"{run_dir / TRANSITION_FILE} records an unreadable location camera ({e})") from None
        return cls(net, location_camera=camera)

    def __call__(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """(B, K) int codes and (B,) action ids -> (B, K) int64 next codes."""
        return self.scored(codes, actions)[0]

    def scored(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """As __call__, plus each row's -log P(predicted next codes) under the network, (B,) float64."""
        codes, actions = self._checked(codes, actions)
        if codes.size == 0:
            return codes.astype(np.int64), np.zeros(codes.shape[0])
        bits = bits_from_codes(codes, self.bits)  # (B, K, bits)
        mask = np.ones(codes.shape, bool)
        nxt, nll = predict_scored(self.net, bits, mask, actions.astype(np.int64), self.batch_size)
        return codes_from_bits(nxt), nll

    def bit_probabilities(self, codes: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """(B, K) int codes and (B,) action ids -> (B, K, bits) float64 P(each next bit is 1), MSB first."""
        codes, actions = self._checked(codes, actions)
        if codes.size == 0:
            return np.zeros((*codes.shape, self.bits))
        return predict_probabilities(self.net, bits_from_codes(codes, self.bits), np.ones(codes.shape, bool),
                                     actions.astype(np.int64), self.batch_size)

    def mode_outcomes(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B, K) codes, (B,) actions -> each mode's likeliest next state (B, M, K) int64 and its -log P (B, M)."""
        codes, actions = self._checked(codes, actions)
        if codes.size == 0:
            n, k = codes.shape
            return np.zeros((n, self.modes, k), np.int64), np.zeros((n, self.modes))
        states, nll = predict_modes(self.net, bits_from_codes(codes, self.bits), np.ones(codes.shape, bool),
                                    actions.astype(np.int64), self.batch_size)
        return codes_from_bits(states), nll

    def _checked(self, codes: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Refuse codes and actions of the wrong shape, dtype or range."""
        codes = np.asarray(codes)
        actions = np.asarray(actions)
        if codes.ndim != 2 or actions.shape != codes.shape[:1]:
            raise ValueError(f"codes must be (B, K) and actions (B,); got {codes.shape} and {actions.shape}")
        if not (np.issubdtype(codes.dtype, np.integer) and np.issubdtype(actions.dtype, np.integer)):
            raise ValueError(f"codes and actions must be integers, got {codes.dtype} and {actions.dtype}")
        if codes.size and (codes.min() < 0 or codes.max() >= 1 << self.bits):
            raise ValueError(f"codes must lie in 0..{(1 << self.bits) - 1}")
        if actions.size and (actions.min() < 0 or actions.max() >= N_ACTIONS):
            raise ValueError(f"action ids must lie in 0..{N_ACTIONS - 1}")
        return codes, actions


def planning_models(run_dir: Path) -> tuple[SymbolReader, LearnedTransition]:
    """RUN's m(z) and what reads crops into its codes: the effect model's encoder, plus m(z)'s location bits if any.

    RUN/best.pt is loaded (and so checked) first: a damaged best.pt is named as such, not reported as a
    transition.pt trained on another effect model (whose check compares best.pt's hash).
    """
    model, _ = load_effect_model(Path(run_dir))
    transition = LearnedTransition.from_run(Path(run_dir))
    return transition.reader(model), transition
