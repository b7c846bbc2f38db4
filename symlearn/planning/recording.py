"""Watching an executed plan: one camera frame at the start and one after each action, as a GIF or a filmstrip.

A `PlanRecorder` is handed to `execute_plan` / `run_problem` (argument `recorder`); execution calls
`start(sim)` once the initial scene is placed and `step(sim, action_id)` after every executed action.
Each frame is the simulator's RGB view (`TabletopSimulator.render_rgb`, the depth camera's viewpoint)
with the action just executed drawn as an arrow from its pick to its release location, projected into
the image with the same camera matrices. Files are written atomically (pddl_export.files).

    >>> rec = PlanRecorder(width=320, height=240)
    >>> run_problem(sim, encoder, transition, problem, "astar", fn, recorder=rec)   # doctest: +SKIP
    >>> rec.save_gif(Path("plan.gif")); len(rec.frames)                             # doctest: +SKIP
    3
"""
from __future__ import annotations

import io
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pddl_export.bounded_json import MiB, read_bounded_bytes
from symlearn.provenance import atomic_write_bytes
from symlearn.world import LOCATIONS, TABLE_TOP_Z, decode_action

# What a recording read back (the report's filmstrip) may be: a recorded plan is 320x240 x a few dozen frames.
MAX_GIF_BYTES = 64 * MiB
MAX_FRAME_PIXELS = 4096 * 4096
MAX_FRAMES = 1000
MAX_TOTAL_PIXELS = 64_000_000  # every frame together: ~190 MB as RGB, and the filmstrip as much again
ARROW_RGB = (230, 40, 40)
TEXT_RGB = (255, 255, 255)


def project_points(points: np.ndarray, view: tuple, proj: tuple, width: int, height: int) -> np.ndarray:
    """(n, 3) world points -> (n, 2) pixel (column, row) under OpenGL column-major view/projection matrices."""
    v = np.asarray(view, np.float64).reshape(4, 4).T
    p = np.asarray(proj, np.float64).reshape(4, 4).T
    hom = np.c_[np.asarray(points, np.float64), np.ones(len(points))]
    clip = (p @ v @ hom.T).T
    ndc = clip[:, :3] / clip[:, 3:4]
    return np.c_[(ndc[:, 0] + 1) / 2 * width, (1 - ndc[:, 1]) / 2 * height]


def location_pixels(view: tuple, proj: tuple, width: int, height: int) -> np.ndarray:
    """(6, 2) pixel positions of the six table locations."""
    pts = np.array([(x, y, TABLE_TOP_Z) for x, y in LOCATIONS])
    return project_points(pts, view, proj, width, height)


def draw_action(image: np.ndarray, start: tuple[float, float], end: tuple[float, float], label: str = ""):
    """A PIL image of `image` with an arrow from start to end (pixels) and a caption."""
    from PIL import Image, ImageDraw

    im = Image.fromarray(image)
    d = ImageDraw.Draw(im)
    (x0, y0), (x1, y1) = start, end
    w = max(2, image.shape[1] // 120)
    if (x1 - x0) ** 2 + (y1 - y0) ** 2 < 4:  # pick == release: a ring
        r = 4 * w
        d.ellipse((x0 - r, y0 - r, x0 + r, y0 + r), outline=ARROW_RGB, width=w)
    else:
        d.line((x0, y0, x1, y1), fill=ARROW_RGB, width=w)
        ang = np.arctan2(y1 - y0, x1 - x0)
        head = 5 * w
        left = (x1 - head * np.cos(ang - 0.45), y1 - head * np.sin(ang - 0.45))
        right = (x1 - head * np.cos(ang + 0.45), y1 - head * np.sin(ang + 0.45))
        d.polygon([(x1, y1), left, right], fill=ARROW_RGB)
        d.ellipse((x0 - w * 2, y0 - w * 2, x0 + w * 2, y0 + w * 2), fill=ARROW_RGB)
    if label:
        d.rectangle((0, 0, 8 + 6 * len(label), 14), fill=(0, 0, 0))
        d.text((4, 2), label, fill=TEXT_RGB)
    return im


@dataclass
class PlanRecorder:
    """Collects frames (PIL images, all width x height) while a plan is executed."""

    width: int = 320
    height: int = 240
    fov_deg: float | None = None  # None: the depth camera's field of view
    frames: list = field(default_factory=list)
    actions: list = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.width < 16 or self.height < 16:
            raise ValueError(f"recording size {self.width}x{self.height} is too small (at least 16x16)")

    def start(self, sim) -> None:
        """Forget earlier frames and take the start frame (called after the initial scene is placed)."""
        from PIL import Image, ImageDraw

        self.frames, self.actions = [], []
        im = Image.fromarray(sim.render_rgb(self.width, self.height, self.fov_deg))
        ImageDraw.Draw(im).rectangle((0, 0, 40, 14), fill=(0, 0, 0))
        ImageDraw.Draw(im).text((4, 2), "start", fill=TEXT_RGB)
        self.frames.append(im)

    def step(self, sim, action_id: int) -> None:
        """Take the frame after an executed action, with the action drawn as an arrow."""
        a = decode_action(int(action_id))
        view, proj = sim.rgb_camera(self.width, self.height, self.fov_deg)
        px = location_pixels(view, proj, self.width, self.height)
        img = sim.render_rgb(self.width, self.height, self.fov_deg)
        label = f"{len(self.actions) + 1}: pick {a.pick} -> release {a.release}"
        self.frames.append(draw_action(img, tuple(px[a.pick]), tuple(px[a.release]), label))
        self.actions.append(int(action_id))

    def gif_bytes(self, frame_ms: int = 900) -> bytes:
        """The frames as an animated GIF (looping; the last frame held longer)."""
        if not self.frames:
            raise ValueError("nothing recorded: execution never started")
        buf = io.BytesIO()
        durations = [frame_ms] * (len(self.frames) - 1) + [frame_ms * 2]
        self.frames[0].save(buf, format="GIF", save_all=True, append_images=self.frames[1:],
                            duration=durations if len(self.frames) > 1 else frame_ms * 2, loop=0, disposal=1)
        return buf.getvalue()

    def save_gif(self, path: Path, frame_ms: int = 900) -> Path:
        """Write the animated GIF atomically; returns its path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(path, self.gif_bytes(frame_ms))
        return path

    def filmstrip_bytes(self, gap: int = 4) -> bytes:
        """The frames side by side (start, then after each action) as one PNG."""
        from PIL import Image

        if not self.frames:
            raise ValueError("nothing recorded: execution never started")
        n = len(self.frames)
        strip = Image.new("RGB", (n * self.width + (n - 1) * gap, self.height), (255, 255, 255))
        for i, f in enumerate(self.frames):
            strip.paste(f.convert("RGB"), (i * (self.width + gap), 0))
        buf = io.BytesIO()
        strip.save(buf, format="PNG")
        return buf.getvalue()

    def save_filmstrip(self, path: Path) -> Path:
        """Write the filmstrip PNG atomically; returns its path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(path, self.filmstrip_bytes())
        return path


class RecordingError(ValueError):
    """A recording that cannot be read back within bounds: not a regular file, too large, not a GIF, or more
    pixels (one frame, or all frames together) than the caps allow; the message is one line naming the file."""


def read_gif_frames(gif: Path) -> list:
    """Every frame of a recorded GIF as RGB images, with the pixel caps checked before each frame is decoded.

    A GIF states its size in a few bytes, so a tiny file can declare 60 frames of 9000 x 9000 (30 GB once
    decoded): the frame size is checked against MAX_FRAME_PIXELS on opening, and the running total against
    MAX_TOTAL_PIXELS and MAX_FRAMES before each frame; Pillow's decompression-bomb check becomes the same refusal.
    """
    from PIL import Image, ImageSequence, UnidentifiedImageError

    gif = Path(gif)
    try:
        data = read_bounded_bytes(gif, MAX_GIF_BYTES, "recording")
    except ValueError as e:
        raise RecordingError(str(e)) from None
    frames = []
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(io.BytesIO(data), formats=["GIF"]) as im:
                w, h = im.size
                if w * h > MAX_FRAME_PIXELS:
                    raise RecordingError(f"{gif}: frames of {w} x {h} pixels, more than the {MAX_FRAME_PIXELS} "
                                         f"a recording's frame may have")
                for i, frame in enumerate(ImageSequence.Iterator(im)):
                    if i >= MAX_FRAMES or (i + 1) * w * h > MAX_TOTAL_PIXELS:
                        raise RecordingError(f"{gif}: more than {i} frames of {w} x {h} pixels, beyond the "
                                             f"{MAX_FRAMES} frames or {MAX_TOTAL_PIXELS} pixels a recording may have")
                    frames.append(frame.convert("RGB"))
    except RecordingError:
        raise
    except (Image.DecompressionBombError, Image.DecompressionBombWarning) as e:
        raise RecordingError(f"{gif}: too many pixels ({str(e).splitlines()[0][:120]})") from None
    except (UnidentifiedImageError, OSError, EOFError, SyntaxError, ValueError, MemoryError) as e:
        why = str(e).splitlines()[0][:120] if str(e) else ""
        raise RecordingError(f"{gif}: not a readable GIF ({type(e).__name__}: {why})") from None
    if not frames:
        raise RecordingError(f"{gif}: a GIF without frames")
    return frames


def filmstrip_from_gif(gif: Path, out: Path, gap: int = 4) -> Path:
    """A filmstrip PNG from every frame of a recorded GIF (for the report); RecordingError (one line) for a GIF
    beyond the caps of read_gif_frames."""
    frames = read_gif_frames(gif)
    rec = PlanRecorder(width=frames[0].width, height=frames[0].height, frames=frames)
    return rec.save_filmstrip(out)
