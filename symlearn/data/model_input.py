"""The effect model's input: each depth crop stacked with its pixels' image x and y (one implementation).

Training, evaluation, Table I, the symbol analysis and the encoders of the transition data and of
live observations all build their model inputs here, so a crop gets the same numbers everywhere.

    >>> x = model_inputs(data.pre_depth, data.pre_origin)   # numpy in, numpy (N, K, 3, S, S) out  # doctest: +SKIP
"""
from __future__ import annotations

import numpy as np
import torch

from symlearn.data.dataset import DataError

IMAGE_SIZE = 256  # side of the camera image the crop origins refer to


def model_inputs(depth: np.ndarray | torch.Tensor, origin: np.ndarray | torch.Tensor,
                 image_size: int = IMAGE_SIZE) -> np.ndarray | torch.Tensor:
    """(N, K, S, S) depth crops and (N, K, 2) origins -> (N, K, 3, S, S) float32: depth, x, y.

    x is each pixel's image column and y its row, divided by image_size - 1 (so [0, 1] inside the
    image). Torch tensors in give a tensor on their device; numpy arrays in give a numpy array.
    """
    if isinstance(depth, torch.Tensor):
        return _stack_channels(depth, torch.as_tensor(origin, device=depth.device), image_size)
    depth_t = torch.from_numpy(np.asarray(depth, np.float32))
    origin_t = torch.from_numpy(np.asarray(origin, np.float32))
    return _stack_channels(depth_t, origin_t, image_size).numpy()


def _stack_channels(depth: torch.Tensor, origin: torch.Tensor, image_size: int) -> torch.Tensor:
    """The tensor work of model_inputs, after its shape checks."""
    if depth.dim() != 4 or depth.shape[-1] != depth.shape[-2]:
        raise DataError(f"depth crops must have shape (N, K, S, S), got {tuple(depth.shape)}")
    if tuple(origin.shape) != tuple(depth.shape[:-2]) + (2,):
        raise DataError(f"origins must have shape {tuple(depth.shape[:-2]) + (2,)}, got {tuple(origin.shape)}")
    depth = depth.float()
    s = depth.shape[-1]
    offs = torch.arange(s, dtype=torch.float32, device=depth.device)
    rows = (origin[..., 0:1].float() + offs) / (image_size - 1)  # (N, K, S)
    cols = (origin[..., 1:2].float() + offs) / (image_size - 1)
    x = cols[..., None, :].expand(*depth.shape)
    y = rows[..., :, None].expand(*depth.shape)
    return torch.stack([depth, x, y], dim=2)
