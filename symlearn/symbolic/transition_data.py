"""The transition model's data: every sample's objects encoded by the trained effect model, before and after.

The training pairs of m(z) are the effect model's own codes of the before- and after-crops of
every data sample (encoder in eval mode: deterministic threshold). The same encoder turns a
live simulator observation into codes for planning. A SymbolReader with a camera appends each
object's location bits (symlearn.symbolic.locations) to its code, in training and planning alike.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import torch

from pddl_export.location_codec import LOCATION_BITS
from pddl_export.symbolic import codes_from_bits
from symlearn.data.dataset import InteractionData
from symlearn.data.model_input import model_inputs
from symlearn.learning.models import AttentiveDeepSym
from symlearn.sim.camera import CameraConfig, crop_centres_xy, crop_tops_z
from symlearn.symbolic.locations import HEIGHTED_BITS, location_bits


@dataclass(frozen=True)
class TransitionData:
    """Encoded samples of one split: codes before and after each action, as 0/1 bit arrays."""

    before: np.ndarray  # (N, K, bits) float32 0/1, padded slots zero
    action: np.ndarray  # (N,) int64 action ids
    after: np.ndarray  # (N, K, bits) float32 0/1
    mask: np.ndarray  # (N, K) bool, real objects
    episode: np.ndarray  # (N,) int32 episode ids (unique within the split)
    step: np.ndarray  # (N,) int step index within the episode

    def __post_init__(self) -> None:
        n = self.action.shape[0]
        for f in dataclasses.fields(self):
            if getattr(self, f.name).shape[0] != n:
                raise ValueError(f"{f.name} has {getattr(self, f.name).shape[0]} rows, expected {n}")

    def __len__(self) -> int:
        return int(self.action.shape[0])


def concat_transition_data(parts: list[TransitionData]) -> TransitionData:
    """Several splits as one: object slots padded to the widest, episode ids kept apart per part."""
    if not parts:
        raise ValueError("no transition data to join")
    k = max(p.mask.shape[1] for p in parts)

    def pad(a: np.ndarray) -> np.ndarray:
        return np.pad(a, [(0, 0), (0, k - a.shape[1])] + [(0, 0)] * (a.ndim - 2))

    offsets = np.cumsum([0] + [int(p.episode.max()) + 1 if len(p) else 0 for p in parts[:-1]])
    return TransitionData(before=np.concatenate([pad(p.before) for p in parts]),
                          action=np.concatenate([p.action for p in parts]),
                          after=np.concatenate([pad(p.after) for p in parts]),
                          mask=np.concatenate([pad(p.mask) for p in parts]),
                          episode=np.concatenate([p.episode + o for p, o in zip(parts, offsets)]).astype(np.int32),
                          step=np.concatenate([p.step for p in parts]))


@torch.no_grad()
def encode_crops(model: AttentiveDeepSym, depth: np.ndarray, origin: np.ndarray, mask: np.ndarray,
                 batch_size: int = 256, image_size: int = 256) -> np.ndarray:
    """(N, K, S, S) depth crops, (N, K, 2) origins, (N, K) mask -> (N, K, bits) float32 codes (eval mode)."""
    model.eval()
    device = next(model.parameters()).device
    out = []
    for i in range(0, depth.shape[0], batch_size):
        d = torch.from_numpy(np.asarray(depth[i:i + batch_size], np.float32))  # (B, K, S, S)
        o = torch.from_numpy(np.asarray(origin[i:i + batch_size], np.float32))  # (B, K, 2)
        m = torch.from_numpy(np.asarray(mask[i:i + batch_size], bool))  # (B, K)
        crops = model_inputs(d, o, image_size)  # (B, K, 3, S, S)
        codes, _ = model.encode(crops.to(device), m.to(device))  # (B, K, bits)
        out.append(codes.float().cpu().numpy())
    bits = model.cfg.bits
    return np.concatenate(out) if out else np.zeros((0, depth.shape[1], bits), np.float32)


@dataclass(frozen=True)
class SymbolReader:
    """What planning calls an object's symbol: the effect model's code, then `location_bits` location bits."""

    model: AttentiveDeepSym
    camera: CameraConfig | None = None  # the camera the crops were rendered with; needed with location bits
    location_bits: int = 0  # 0: the learned code alone; else one of location_codec.LOCATION_BITS

    def __post_init__(self) -> None:
        if self.location_bits not in (0, *LOCATION_BITS) or (self.location_bits > 0) != (self.camera is not None):
            raise ValueError(f"location_bits={self.location_bits!r} must be 0 (no camera) or one of "
                             f"{LOCATION_BITS} (with the camera the crops were rendered with)")

    @property
    def bits(self) -> int:
        return int(self.model.cfg.bits) + self.location_bits

    def encode(self, depth: np.ndarray, origin: np.ndarray, mask: np.ndarray, batch_size: int = 256,
               image_size: int = 256) -> np.ndarray:
        """(N, K, S, S) depth crops, (N, K, 2) origins, (N, K) mask -> (N, K, bits) float32 0/1, padding zero."""
        codes = encode_crops(self.model, depth, origin, mask, batch_size, image_size)
        if not self.location_bits:
            return codes
        loc = np.zeros((*codes.shape[:2], self.location_bits), np.float32)
        for i in range(0, depth.shape[0], batch_size):  # chunks: the back-projection holds (B, K, S, S) floats
            d, o = depth[i:i + batch_size], origin[i:i + batch_size]
            heighted = self.location_bits in HEIGHTED_BITS  # only these read heights
            top = crop_tops_z(d, o, self.camera) if heighted else None
            loc[i:i + batch_size] = location_bits(crop_centres_xy(d, o, self.camera), self.location_bits, top)
        return np.concatenate([codes, np.where(np.asarray(mask, bool)[..., None], loc, 0.0)], -1).astype(np.float32)


def symbol_reader(model: AttentiveDeepSym | SymbolReader) -> SymbolReader:
    """A SymbolReader as given, or one that reads the learned code alone."""
    return model if isinstance(model, SymbolReader) else SymbolReader(model)


def build_transition_data(model: AttentiveDeepSym | SymbolReader, data: InteractionData,
                          batch_size: int = 256) -> TransitionData:
    """Encode a split's before- and after-crops with the effect model's encoder (and location bits, if read)."""
    mask, reader = data.mask, symbol_reader(model)
    before = reader.encode(data.pre_depth, data.pre_origin, mask, batch_size)
    after = reader.encode(data.post_depth, data.post_origin, mask, batch_size)
    return TransitionData(before, data.action.astype(np.int64), after, mask,
                          data.episode.astype(np.int32), data.step.astype(np.int64))


def encode_observation(model: AttentiveDeepSym | SymbolReader, obs) -> np.ndarray:
    """A live simulator Observation -> (k,) int64 codes, one per object, MSB first.

    Crops go through float16 first, as they are stored in the data set the encoder was trained on,
    so a live scene and its recorded twin get the same codes.
    """
    crops = np.asarray(obs.crops, np.float16).astype(np.float32)[None]  # (1, k, S, S)
    origins = np.asarray(obs.origins, np.float32)[None]  # (1, k, 2)
    if crops.shape[1] == 0:
        return np.zeros(0, np.int64)
    mask = np.ones(crops.shape[:2], bool)
    bits = symbol_reader(model).encode(crops, origins, mask, image_size=int(obs.depth.shape[0]))  # (1, k, bits)
    return codes_from_bits(bits[0])
