"""The tabletop simulator: a UR10 with a suction tool picks and releases cubes and sticks.

This is the only module that imports pybullet. It owns one physics client (DIRECT unless
`gui=True`), passes `physicsClientId` on every call, and exposes plain data: `reset(scene)`,
`step(action) -> StepResult`, `get_scene()`, `observe() -> Observation`.

An action (pick location, release location) runs as a real arm motion: inverse kinematics
for each waypoint, joint targets interpolated with a smooth profile and tracked by the
engine's position controllers. The topmost object covering the pick location (found with a
downward ray, as a depth sensor would) is held by a suction constraint made on contact; it is
released just above whatever lies under its footprint, and the arm returns home out of the
camera's view before the after-image is rendered.

    >>> sim = TabletopSimulator()
    >>> sim.reset(Scene((ObjectState(ObjectType.CUBE, (0.5, 0.0, 0.45)),)))
    >>> res = sim.step(Action(pick=4, release=1))
    >>> np.round(res.effect[0] * 1000)  # doctest: +SKIP
    array([300.,   0.,   0.])
"""
from __future__ import annotations

import math
import os
import secrets
import signal
import sys
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np


def _quiet_import_pybullet():
    """Import pybullet without the build-time line it prints on stderr, so CLI errors stay one line."""
    sys.stderr.flush()
    saved, devnull = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    try:
        import pybullet
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)
    return pybullet


pb = _quiet_import_pybullet()

from symlearn.config_file import Bound, check_bounds
from symlearn.sim.camera import CameraConfig, crop_origins, cut_crops, metric_depth
from symlearn.sim.ur10_urdf import forward_kinematics, ur10_urdf
from symlearn.world import (LOCATIONS, OBJECT_MASS, OBJECT_SIZE, TABLE_TOP_Z, Action, ObjectState,
                            ObjectType, Scene)

DOWN = (1.0, 0.0, 0.0, 0.0)  # tool z axis pointing at the table
N_ARM_JOINTS = 6
TOOL_LINK = 6
REST_POSE = (0.0, -1.6, -1.6, 1.6, -1.57, 0.0)  # elbow up, wrist over the table


def _load_urdf_text(text: str, base: tuple[float, float, float], client: int) -> int:
    """Load a URDF given as text (pybullet reads files only) through a temp file that never outlives the call.

    SIGTERM and SIGINT are held back in this thread while the file exists. That alone is not enough where another
    thread takes the signal (a collect worker's parent watcher): Python then runs the handler in this thread at the
    next bytecode, which may fall inside tempfile.mkstemp, after the file is made and before its name is returned. So
    the name is chosen first and the file made inside the try whose finally removes it."""
    held = {signal.SIGTERM, signal.SIGINT}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    path = os.path.join(tempfile.gettempdir(), f"symlearn-ur10-{os.getpid()}-{secrets.token_hex(8)}.urdf")
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o600)
        with os.fdopen(fd, "w") as f:
            f.write(text)
        return pb.loadURDF(path, base, useFixedBase=True, physicsClientId=client)
    finally:
        try:
            os.unlink(path)
        except FileNotFoundError:  # the signal came before the file was made
            pass
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@dataclass(frozen=True)
class SimConfig:
    """Physics and motion settings; durations are simulated seconds per arm motion segment."""

    # 120 Hz with 20 solver iterations runs 1.6x faster than pybullet's 240 Hz / 50 and gives the
    # same effect statistics (bench/collect.py); the scenario tests check stacks and riders.
    time_step: float = 1.0 / 120.0
    solver_iterations: int = 20
    # Each motion segment takes the time a bang-bang profile needs at this peak acceleration.
    # Loaded moves stay gentle: a tall cube riding on a carried stick tips over at about
    # 4.9 m/s^2 (half its width over its centre's height, times g), a tower of two at 2.5.
    # Vertical loaded moves must stay well below g: while decelerating upwards, gravity felt by a
    # rider drops and it tips at smaller sideways accelerations. With 1.5 and 3.0, a tower of two
    # cubes on a stick's end (table1_case3) rides along intact.
    accel_free: float = 20.0  # m/s^2, tool without a load
    accel_loaded: float = 1.5  # m/s^2, horizontal moves holding a stick (riders may sit on it)
    accel_loaded_vertical: float = 3.0  # m/s^2, lifting or lowering a stick
    accel_cube: float = 6.0  # m/s^2, any move holding a cube: only the topmost object is taken, so none rides on it
    min_segment_s: float = 0.08
    pause_s: float = 0.05  # hold still before releasing, so the object does not swing off
    settle_max_s: float = 1.0  # extra settling, stopped early once everything is still
    min_travel_z: float = 0.15  # travel at least this high above the table
    max_travel_z: float = 0.55  # and at most this high: the arm's reach above the far row
    clearance: float = 0.04  # margin above the highest object while travelling
    grasp_reach: float = 0.02  # suction takes hold within this distance of the surface
    release_gap: float = 0.004  # held object's bottom above the surface when released
    home: tuple[float, float, float] = (0.25, 0.0, 0.95)  # tool position out of the camera's view
    # The UR10 stands on a pedestal level with the table: with its base at z = 0 (docs/DESIGN.md)
    # the tool cannot point down above the far row higher than 0.25 m over the table.
    robot_base: tuple[float, float, float] = (0.0, 0.0, TABLE_TOP_Z)
    friction: float = 1.0  # lateral friction of objects and table: objects ride on a carried stick
    position_gain: float = 0.6  # joint tracking stiffness: 0.1 lags 2.5 cm behind a 0.25 s descent
    crop: int = 64  # crop window size in pixels
    camera: CameraConfig = field(default_factory=CameraConfig)

    def __post_init__(self) -> None:
        """Refuse settings the simulator cannot run with (a zero time step divides; [collect.sim] in a file)."""
        if not Bound(1, self.camera.size, integer=True).holds(self.crop):
            raise ValueError(f"crop size {self.crop!r} must be in 1..{self.camera.size}")
        check_bounds(self, SIM_BOUNDS)
        if self.min_travel_z > self.max_travel_z:
            raise ValueError(f"min_travel_z={self.min_travel_z!r} must not exceed max_travel_z={self.max_travel_z!r}")


_ACCEL = Bound(0.0, 1000.0, lo_open=True)  # m/s^2: each motion's duration divides by it
SIM_BOUNDS = {
    "time_step": Bound(1e-4, 0.1),  # seconds: every duration is divided by it into simulation steps
    "solver_iterations": Bound(1, 1000, integer=True),
    "accel_free": _ACCEL, "accel_loaded": _ACCEL, "accel_loaded_vertical": _ACCEL, "accel_cube": _ACCEL,
    "min_segment_s": Bound(0.0, 10.0), "pause_s": Bound(0.0, 10.0), "settle_max_s": Bound(0.0, 60.0),
    "min_travel_z": Bound(0.0, 2.0), "max_travel_z": Bound(0.0, 2.0), "clearance": Bound(0.0, 1.0),
    "grasp_reach": Bound(0.0, 0.5, lo_open=True), "release_gap": Bound(0.0, 0.5),
    "home": Bound(-10.0, 10.0), "robot_base": Bound(-10.0, 10.0),
    "friction": Bound(0.0, 10.0), "position_gain": Bound(0.0, 10.0, lo_open=True),
}


@dataclass(frozen=True)
class Observation:
    """A rendered view: metric depth, segmentation, and the crops of every object."""

    depth: np.ndarray  # (H, W) float32, metres
    seg: np.ndarray  # (H, W) int32, body ids (-1 background)
    crops: np.ndarray  # (k, crop, crop) float32, depth masked to the object
    origins: np.ndarray  # (k, 2) int16 crop top-left (row, col)
    pixels: np.ndarray  # (k,) int32 visible pixel count


@dataclass(frozen=True)
class StepResult:
    """What one action did: poses before and after, effects, and whether anything was grasped."""

    action: Action
    before: Scene
    after: Scene
    effect: np.ndarray  # (k, 3) float32 displacement in metres, world frame
    grasped: int  # index of the object held, or -1
    off_table: bool  # some object left the table top


def bang_bang(n: int) -> np.ndarray:
    """Path fraction at n steps under constant acceleration then deceleration (peak 4 d / T^2)."""
    t = np.arange(1, n + 1) / n
    return np.where(t < 0.5, 2 * t**2, 1 - 2 * (1 - t) ** 2)


class TabletopSimulator:
    """A UR10 tabletop in its own pybullet client."""

    def __init__(self, config: SimConfig | None = None, gui: bool = False) -> None:
        self.cfg = config or SimConfig()
        self.gui = gui
        self.cid = pb.connect(pb.GUI if gui else pb.DIRECT)
        cam = self.cfg.camera
        self._view = pb.computeViewMatrix(cam.eye, cam.target, cam.up, physicsClientId=self.cid)
        self._proj = pb.computeProjectionMatrixFOV(cam.fov_deg, 1.0, cam.near, cam.far,
                                                   physicsClientId=self.cid)
        self.body_ids: list[int] = []
        self.types: list[ObjectType] = []
        self._last_origins: np.ndarray | None = None
        self._build_world()

    # ---------------------------------------------------------------- world
    def _build_world(self) -> None:
        c = self.cid
        pb.resetSimulation(physicsClientId=c)
        pb.setGravity(0, 0, -9.81, physicsClientId=c)
        pb.setPhysicsEngineParameter(fixedTimeStep=self.cfg.time_step,
                                    numSolverIterations=self.cfg.solver_iterations, physicsClientId=c)
        half = (0.45, 0.65, TABLE_TOP_Z / 2)
        col = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=half, physicsClientId=c)
        vis = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half, rgbaColor=(0.75, 0.6, 0.45, 1),
                                   physicsClientId=c)
        self.table = pb.createMultiBody(0, col, vis, (0.70, 0.0, TABLE_TOP_Z / 2), physicsClientId=c)
        pb.changeDynamics(self.table, -1, lateralFriction=self.cfg.friction, physicsClientId=c)
        self.table_extent = ((0.70 - half[0], 0.70 + half[0]), (-half[1], half[1]))
        self.robot = _load_urdf_text(ur10_urdf(), self.cfg.robot_base, c)
        self._shapes = {}
        for t, size in OBJECT_SIZE.items():
            he = [s / 2 for s in size]
            colour = (0.9, 0.5, 0.1, 1) if t == ObjectType.STICK else (0.2, 0.7, 0.3, 1)
            self._shapes[t] = (pb.createCollisionShape(pb.GEOM_BOX, halfExtents=he, physicsClientId=c),
                               pb.createVisualShape(pb.GEOM_BOX, halfExtents=he, rgbaColor=colour,
                                                    physicsClientId=c))
        for j, v in enumerate(REST_POSE):
            pb.resetJointState(self.robot, j, v, physicsClientId=c)
        self._q_home = self._ik(self.cfg.home)
        self._hold: int | None = None
        self._home_arm()

    def _home_arm(self) -> None:
        """Put the arm at rest at home (used between scenes, never during an action)."""
        for j in range(N_ARM_JOINTS):
            pb.resetJointState(self.robot, j, self._q_home[j], 0.0, physicsClientId=self.cid)
        self._q = self._q_home.copy()
        self._command(self._q)

    def close(self) -> None:
        if pb.isConnected(self.cid):
            pb.disconnect(self.cid)

    def __enter__(self) -> "TabletopSimulator":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ---------------------------------------------------------------- scenes
    def reset(self, scene: Scene, settle_s: float = 0.5) -> None:
        """Remove all objects, place the scene's objects at their poses and let them settle."""
        c = self.cid
        self._release()
        for b in self.body_ids:
            pb.removeBody(b, physicsClientId=c)
        self.body_ids, self.types = [], []
        self._home_arm()
        self._add_objects(list(scene.objects))
        self._last_origins = None
        self._run(int(settle_s / self.cfg.time_step))

    def drop_object(self, otype: ObjectType, location: int, settle_s: float = 0.4) -> None:
        """Add an object just above whatever lies at a location and let it fall into place."""
        x, y = LOCATIONS[location]
        size = OBJECT_SIZE[otype]
        top = self._surface_under(x, y, size[0], size[1], z_from=2.0)
        objs = list(self.get_scene().objects) + [
            ObjectState(otype, (x, y, top + size[2] / 2 + 0.005))]
        self._add_objects(objs[len(self.body_ids):])
        self._run(int(settle_s / self.cfg.time_step))

    def build(self, spec) -> None:
        """A fresh scene made by dropping (type, location) objects one after another."""
        self.reset(Scene(), settle_s=0.0)
        for otype, loc in spec:
            self.drop_object(otype, loc)

    def occupied(self) -> np.ndarray:
        """(6,) bool: which locations have an object under a downward ray, as the camera would tell."""
        starts = [(x, y, 2.0) for x, y in LOCATIONS]
        ends = [(x, y, 0.0) for x, y in LOCATIONS]
        hits = pb.rayTestBatch(starts, ends, physicsClientId=self.cid)
        return np.array([h[0] in self.body_ids for h in hits])

    def _add_objects(self, objs: list[ObjectState]) -> None:
        c = self.cid
        for o in objs:
            if o.type == ObjectType.STICK and ObjectType.STICK in self.types:
                raise ValueError("a scene holds at most one stick")
            col, vis = self._shapes[o.type]
            b = pb.createMultiBody(OBJECT_MASS[o.type], col, vis, o.position, o.orientation,
                                   physicsClientId=c)
            pb.changeDynamics(b, -1, lateralFriction=self.cfg.friction, physicsClientId=c)
            self.body_ids.append(b)
            self.types.append(o.type)

    def get_scene(self) -> Scene:
        """The current object poses, in identity order."""
        objs = []
        for b, t in zip(self.body_ids, self.types):
            pos, orn = pb.getBasePositionAndOrientation(b, physicsClientId=self.cid)
            objs.append(ObjectState(t, pos, orn))
        return Scene(tuple(objs))

    # ---------------------------------------------------------------- camera
    def observe(self) -> Observation:
        """Render depth and segmentation and cut each object's crop."""
        cam = self.cfg.camera
        _, _, _, buf, seg = pb.getCameraImage(cam.size, cam.size, self._view, self._proj,
                                              renderer=pb.ER_TINY_RENDERER,
                                              flags=pb.ER_NO_SEGMENTATION_MASK * 0,
                                              physicsClientId=self.cid)
        depth = metric_depth(np.reshape(buf, (cam.size, cam.size)), cam)
        seg = np.reshape(np.asarray(seg, np.int32), (cam.size, cam.size))
        ids = np.asarray(self.body_ids, np.int32)
        origins, pixels = crop_origins(seg, ids, self.cfg.crop, self._last_origins)
        self._last_origins = origins
        crops = cut_crops(depth, seg, ids, origins, self.cfg.crop)
        return Observation(depth, seg, crops, origins, pixels)

    def rgb_camera(self, width: int, height: int, fov_deg: float | None = None) -> tuple[tuple, tuple]:
        """(view, projection) matrices, column-major 4x4 as pybullet gives them, of the RGB view: the depth camera's."""
        cam = self.cfg.camera
        proj = pb.computeProjectionMatrixFOV(fov_deg or cam.fov_deg, width / height, cam.near, cam.far,
                                             physicsClientId=self.cid)
        return tuple(self._view), tuple(proj)

    def render_rgb(self, width: int = 320, height: int = 240, fov_deg: float | None = None) -> np.ndarray:
        """(height, width, 3) uint8 colour image from the depth camera's viewpoint (tiny renderer: headless)."""
        if width <= 0 or height <= 0:
            raise ValueError(f"image size {width}x{height} must be positive")
        view, proj = self.rgb_camera(width, height, fov_deg)
        _, _, rgba, _, _ = pb.getCameraImage(width, height, view, proj, renderer=pb.ER_TINY_RENDERER,
                                             flags=pb.ER_NO_SEGMENTATION_MASK, physicsClientId=self.cid)
        return np.reshape(np.asarray(rgba, np.uint8), (height, width, 4))[..., :3].copy()

    # ---------------------------------------------------------------- acting
    def step(self, action: Action) -> StepResult:
        """Execute one pick-and-release with the arm and report every object's displacement."""
        if not isinstance(action, Action):
            raise TypeError(f"step() takes an Action, not {type(action).__name__}")
        cfg = self.cfg
        before = self.get_scene()
        px, py = LOCATIONS[action.pick]
        rx, ry = LOCATIONS[action.release]
        free, loaded, vertical = cfg.accel_free, cfg.accel_loaded, cfg.accel_loaded_vertical
        top = max([pb.getAABB(b, physicsClientId=self.cid)[1][2] for b in self.body_ids] + [TABLE_TOP_Z])
        hit, hit_z = self._ray_down(px, py)
        above = min(max(top, TABLE_TOP_Z + cfg.min_travel_z) + cfg.clearance, TABLE_TOP_Z + cfg.max_travel_z)
        self._move((px, py, above), free)
        self._move((px, py, hit_z + 0.004), free)
        grasped = self._grasp(hit) if hit in self.body_ids else -1
        if grasped >= 0:
            if self.types[grasped] == ObjectType.CUBE:
                loaded = vertical = cfg.accel_cube
            lo, _ = pb.getAABB(self.body_ids[grasped], physicsClientId=self.cid)
            travel = min(above + (self._tool_pos()[2] - lo[2]), TABLE_TOP_Z + cfg.max_travel_z)
            self._move((px, py, travel), vertical)
            self._move((rx, ry, travel), loaded)
            lo, hi = pb.getAABB(self.body_ids[grasped], physicsClientId=self.cid)
            surface = self._surface_under((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[0] - lo[0],
                                          hi[1] - lo[1], z_from=lo[2] - 1e-3)
            drop = (self._tool_pos()[2] - lo[2]) + max(surface, TABLE_TOP_Z) + cfg.release_gap
            self._move((rx, ry, drop), vertical)
            self._run(int(cfg.pause_s / cfg.time_step))
            self._release()
            self._move((rx, ry, travel), free)
        else:
            self._move((px, py, above), free)
        self._move(cfg.home, free)
        self._settle()
        after = self.get_scene()
        effect = (after.positions() - before.positions()).astype(np.float32)
        return StepResult(action, before, after, effect, grasped, self._off_table(after))

    # ---------------------------------------------------------------- internals
    def _tool_pos(self) -> tuple[float, float, float]:
        return pb.getLinkState(self.robot, TOOL_LINK, computeForwardKinematics=True,
                               physicsClientId=self.cid)[4]

    def _ik(self, pos) -> np.ndarray:
        """Joint angles putting the tool cup at `pos`, pointing down, seeded by the arm's current state."""
        q = np.asarray(pb.calculateInverseKinematics(
            self.robot, TOOL_LINK, pos, DOWN, maxNumIterations=100, residualThreshold=1e-6,
            physicsClientId=self.cid)[:N_ARM_JOINTS])
        err = np.linalg.norm(forward_kinematics(q)[0] + self.cfg.robot_base - np.asarray(pos))
        if err > 5e-3:
            raise RuntimeError(f"tool target {tuple(np.round(pos, 3))} is out of the arm's reach "
                               f"(IK error {err * 1000:.0f} mm)")
        return q

    def _command(self, q: np.ndarray) -> None:
        pb.setJointMotorControlArray(self.robot, list(range(N_ARM_JOINTS)), pb.POSITION_CONTROL,
                                     targetPositions=list(q), forces=[500.0] * N_ARM_JOINTS,
                                     positionGains=[self.cfg.position_gain] * N_ARM_JOINTS,
                                     physicsClientId=self.cid)

    def _move(self, pos, accel: float) -> None:
        """Move the tool to `pos` (pointing down) along a joint-space path, timed for `accel`."""
        q0 = self._q
        q1 = self._ik(pos)
        dist = float(np.linalg.norm(np.asarray(pos) - forward_kinematics(q0)[0] - self.cfg.robot_base))
        duration = max(self.cfg.min_segment_s, 2.0 * math.sqrt(dist / accel))
        for s in bang_bang(max(1, int(math.ceil(duration / self.cfg.time_step)))):
            self._command(q0 + s * (q1 - q0))
            pb.stepSimulation(physicsClientId=self.cid)
            if self.gui:
                time.sleep(self.cfg.time_step)
        self._q = q1

    def _run(self, n: int) -> None:
        for _ in range(n):
            pb.stepSimulation(physicsClientId=self.cid)

    def _settle(self) -> None:
        """Step until no object moves faster than 1 cm/s (checked every 12 steps) or time runs out."""
        for _ in range(int(self.cfg.settle_max_s / self.cfg.time_step) // 12):
            moving = False
            for b in self.body_ids:
                v, w = pb.getBaseVelocity(b, physicsClientId=self.cid)
                if np.dot(v, v) > 1e-4 or np.dot(w, w) > 1e-2:
                    moving = True
                    break
            if not moving:
                return
            self._run(12)

    def _ray_down(self, x: float, y: float, z_from: float = 2.0) -> tuple[int, float]:
        """First body hit by a vertical ray at (x, y), and the hit height."""
        res = pb.rayTest((x, y, z_from), (x, y, 0.0), physicsClientId=self.cid)[0]
        return res[0], res[3][2]

    def _surface_under(self, cx, cy, size_x, size_y, z_from) -> float:
        """Highest surface below z_from under a footprint of size_x by size_y centred at (cx, cy)."""
        gx = np.linspace(cx - size_x / 2 * 0.9, cx + size_x / 2 * 0.9, 3)
        gy = np.linspace(cy - size_y / 2 * 0.9, cy + size_y / 2 * 0.9, max(3, int(size_y / 0.02)))
        starts = [(a, b, z_from) for a in gx for b in gy]
        ends = [(a, b, 0.0) for a in gx for b in gy]
        hits = pb.rayTestBatch(starts, ends, physicsClientId=self.cid)
        zs = [h[3][2] for h in hits if h[0] >= 0]
        return max(zs) if zs else TABLE_TOP_Z

    def _grasp(self, body: int) -> int:
        pts = pb.getClosestPoints(self.robot, body, self.cfg.grasp_reach, linkIndexA=TOOL_LINK,
                                  physicsClientId=self.cid)
        if not pts:
            return -1
        tpos, torn = pb.getLinkState(self.robot, TOOL_LINK, computeForwardKinematics=True,
                                     physicsClientId=self.cid)[4:6]
        opos, oorn = pb.getBasePositionAndOrientation(body, physicsClientId=self.cid)
        ipos, iorn = pb.invertTransform(tpos, torn)
        rpos, rorn = pb.multiplyTransforms(ipos, iorn, opos, oorn)
        self._hold = pb.createConstraint(self.robot, TOOL_LINK, body, -1, pb.JOINT_FIXED, (0, 0, 0),
                                         rpos, (0, 0, 0), rorn, physicsClientId=self.cid)
        pb.changeConstraint(self._hold, maxForce=300, physicsClientId=self.cid)
        return self.body_ids.index(body)

    def _release(self) -> None:
        if getattr(self, "_hold", None) is not None:
            pb.removeConstraint(self._hold, physicsClientId=self.cid)
            self._hold = None

    def _off_table(self, scene: Scene) -> bool:
        (x0, x1), (y0, y1) = self.table_extent
        p = scene.positions()
        return bool(np.any((p[:, 2] < TABLE_TOP_Z) | (p[:, 0] < x0) | (p[:, 0] > x1)
                           | (p[:, 1] < y0) | (p[:, 1] > y1)))
