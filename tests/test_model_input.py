"""The one model-input implementation equals the two it replaced, number for number."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from symlearn.data.dataset import DataError
from symlearn.data.model_input import model_inputs


def _old_crops_from_depth(depth: torch.Tensor, origin: torch.Tensor, image_size: int = 256) -> torch.Tensor:
    """symlearn/learning/training.py: crops_from_depth as it was at 6d1e502 (training, encoders, Table I)."""
    s = depth.shape[-1]
    offs = torch.arange(s, dtype=torch.float32, device=depth.device)
    rows = (origin[..., 0:1].float() + offs) / (image_size - 1)
    cols = (origin[..., 1:2].float() + offs) / (image_size - 1)
    x = cols[..., None, :].expand(*depth.shape)
    y = rows[..., :, None].expand(*depth.shape)
    return torch.stack([depth, x, y], dim=2)


def _old_model_inputs(depth: np.ndarray, origin: np.ndarray, image_size: int = 256) -> np.ndarray:
    """symlearn/data/dataset.py: model_inputs (numpy, via camera.position_channels), as it was."""
    depth = np.asarray(depth, np.float32)
    origins = np.asarray(origin, np.float32)
    crop = depth.shape[-1]
    offs = np.arange(crop, dtype=np.float32)
    rows = origins[..., 0, None] + offs
    cols = origins[..., 1, None] + offs
    scale = 1.0 / (image_size - 1)
    x = np.broadcast_to(cols[..., None, :], origins.shape[:-1] + (crop, crop)) * scale
    y = np.broadcast_to(rows[..., :, None], origins.shape[:-1] + (crop, crop)) * scale
    xy = np.stack([x, y], axis=-3).astype(np.float32)
    return np.concatenate([depth[:, :, None], xy], axis=2)


@pytest.fixture
def sample():
    rng = np.random.default_rng(7)
    depth = rng.uniform(0.0, 1.6, (5, 3, 16, 16)).astype(np.float16)  # stored as float16, like the data set
    depth[rng.random(depth.shape) < 0.4] = 0  # background pixels
    origin = rng.integers(-16, 256, (5, 3, 2)).astype(np.int16)  # windows may start past the border
    return depth, origin


@pytest.mark.parametrize("image_size", [256, 128])
def test_equals_the_old_torch_implementation_bit_for_bit(sample, image_size):
    depth, origin = sample
    d = torch.from_numpy(depth).float()
    o = torch.from_numpy(origin.astype(np.float32))
    new = model_inputs(d, o, image_size)
    old = _old_crops_from_depth(d, o, image_size)
    assert isinstance(new, torch.Tensor) and new.dtype == torch.float32
    assert torch.equal(new, old)
    # numpy in gives the same numbers as numpy out
    assert np.array_equal(model_inputs(depth, origin, image_size), old.numpy())


def test_matches_the_old_numpy_implementation_to_one_float32_ulp(sample):
    """The old numpy path multiplied by 1/255, the torch path divides by 255: they differed in the last bit."""
    depth, origin = sample
    new = model_inputs(depth, origin)
    old = _old_model_inputs(depth, origin)
    assert isinstance(new, np.ndarray) and new.dtype == np.float32 and new.shape == old.shape == (5, 3, 3, 16, 16)
    assert np.array_equal(new[:, :, 0], depth.astype(np.float32))  # the depth channel is exact
    assert np.max(np.abs(new - old) / np.maximum(np.spacing(np.abs(old)), np.finfo(np.float32).tiny)) <= 1.0
    # a pixel's x is its image column / 255, y its row / 255
    r, c = int(origin[2, 1, 0]), int(origin[2, 1, 1])
    assert new[2, 1, 1, 4, 9] == np.float32(c + 9) / np.float32(255)
    assert new[2, 1, 2, 4, 9] == np.float32(r + 4) / np.float32(255)


def test_refuses_wrong_shapes(sample):
    depth, origin = sample
    with pytest.raises(DataError, match="shape"):
        model_inputs(depth[:, :, 0], origin)
    with pytest.raises(DataError, match="origins"):
        model_inputs(depth, origin[:, :2])
