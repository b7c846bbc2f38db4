"""The table locations as entities of their own: a fixed depth window over each table cell.

The relational model (symlearn.learning.relational) reads a scene as entities: every object's crop, and one
crop per table location cut from the same depth image at a window that never moves. "Which location an
object is at" is then a relation the network learns between two crops, not a rule: nothing here looks at an
object's position. The window is where the camera sees the location's centre (a constant of the camera and
the table layout, as the crops' own position channels are); what lies in it is whatever the camera saw.

The data set stores each object's visible pixels in its own window (docs/DATA_FORMAT.md), and visible
pixels belong to one object each, so the scene's depth image is the sum of the object crops pasted at their
origins; a location's crop is that image cut at the location's window.

    >>> windows = location_windows(CameraConfig(), 64)
    >>> windows.shape, windows.dtype
    ((6, 2), dtype('int16'))
"""
from __future__ import annotations

import numpy as np
import torch

from symlearn.data.model_input import model_inputs
from symlearn.sim.camera import CameraConfig, camera_axes
from symlearn.world import LOCATIONS, TABLE_TOP_Z

# The height the window is centred at: a cube standing at a location reaches 10 cm above the table, a stick
# lying there 5 cm; the middle of what stands on a cell.
WINDOW_HEIGHT_M = 0.05


def project_to_pixels(points: np.ndarray, cam: CameraConfig) -> np.ndarray:
    """(..., 3) world points -> (..., 2) image (row, col) in pixels, the inverse of the crops' view rays
    (symlearn.sim.camera: row 0 at the top, pixel centres at +0.5)."""
    p = np.asarray(points, np.float64)
    eye, fwd, right, cam_up, tan = camera_axes(cam)
    v = p - eye
    d = v @ fwd
    x = (v @ right) / d / tan
    y = (v @ cam_up) / d / tan
    col = (x + 1.0) * cam.size / 2 - 0.5
    row = (1.0 - y) * cam.size / 2 - 0.5
    return np.stack([row, col], axis=-1)


def location_windows(cam: CameraConfig, crop: int) -> np.ndarray:
    """(6, 2) int16: the top-left pixel (row, col) of each table location's `crop`-pixel window."""
    centres = np.array([(x, y, TABLE_TOP_Z + WINDOW_HEIGHT_M) for x, y in LOCATIONS])
    return (np.rint(project_to_pixels(centres, cam)).astype(np.int64) - crop // 2).astype(np.int16)


def scene_depth(depth: np.ndarray, origin: np.ndarray, n_objects: np.ndarray, image_size: int) -> np.ndarray:
    """(N, K, S, S) object crops, (N, K, 2) origins, (N,) counts -> (N, H, H) depth image of the objects'
    visible pixels (0 where the camera saw no object), H = image_size."""
    n, k, s, _ = depth.shape
    pad = s
    canvas = np.zeros((n, image_size + 2 * pad, image_size + 2 * pad), np.float32)
    for i in range(n):
        for j in range(int(n_objects[i])):
            r, c = (int(np.clip(v, -s, image_size)) + pad for v in origin[i, j])
            win = canvas[i, r:r + s, c:c + s]
            crop = depth[i, j].astype(np.float32)
            np.copyto(win, crop, where=crop > 0)
    return canvas[:, pad:pad + image_size, pad:pad + image_size]


def location_crops(depth: np.ndarray, origin: np.ndarray, n_objects: np.ndarray, windows: np.ndarray,
                   image_size: int = 256, chunk: int = 512) -> np.ndarray:
    """(N, L, S, S) float16: each table location's window of the scene's depth image (L = len(windows))."""
    n, _, s, _ = depth.shape
    out = np.zeros((n, len(windows), s, s), np.float16)
    pad = s
    for a in range(0, n, chunk):
        img = scene_depth(depth[a:a + chunk], origin[a:a + chunk], n_objects[a:a + chunk], image_size)
        padded = np.zeros((img.shape[0], image_size + 2 * pad, image_size + 2 * pad), np.float32)
        padded[:, pad:pad + image_size, pad:pad + image_size] = img
        for li, (r, c) in enumerate(windows):
            r0, c0 = int(r) + pad, int(c) + pad
            out[a:a + chunk, li] = padded[:, r0:r0 + s, c0:c0 + s]
    return out


def entity_inputs(depth: np.ndarray | torch.Tensor, origin: np.ndarray | torch.Tensor,
                  loc_depth: np.ndarray | torch.Tensor, windows: np.ndarray | torch.Tensor
                  ) -> tuple[torch.Tensor, torch.Tensor]:
    """The relational model's inputs: (B, K, S, S) object crops with their (B, K, 2) origins and (B, L, S, S)
    location crops with the (L, 2) windows -> (B, K, 3, S, S) and (B, L, 3, S, S) float32 (depth, image x, y)."""
    loc_depth = torch.as_tensor(loc_depth).float()
    win = torch.as_tensor(windows).float()[None].expand(loc_depth.shape[0], -1, -1)
    return model_inputs(torch.as_tensor(depth).float(), torch.as_tensor(origin).float()), model_inputs(loc_depth, win)
