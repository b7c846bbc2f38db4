"""A UR10 URDF written from the published Denavit-Hartenberg parameters, with primitive shapes.

pybullet's data package has no UR10, so the model is generated: joint i+1 sits at the DH
offset (a_i, 0, d_i) with roll alpha_i in link i's frame, and each link is drawn as a cylinder
along that offset. A short suction tool hangs from the flange; only the tool collides, since
the arm itself never touches the objects and arm-table contacts would only cost physics time.

    >>> text = ur10_urdf()
    >>> text.count("<joint")
    7
"""
from __future__ import annotations

import math

# Universal Robots UR10 (CB3) standard DH table: (d, a, alpha) per joint, metres and radians.
UR10_DH: tuple[tuple[float, float, float], ...] = (
    (0.1273, 0.0, math.pi / 2),
    (0.0, -0.612, 0.0),
    (0.0, -0.5723, 0.0),
    (0.163941, 0.0, math.pi / 2),
    (0.1157, 0.0, -math.pi / 2),
    (0.0922, 0.0, 0.0),
)
LINK_MASS = (3.7, 8.4, 4.6, 1.4, 1.4, 0.4)
LINK_RADIUS = (0.075, 0.06, 0.05, 0.045, 0.045, 0.045)
TOOL_LENGTH = 0.10  # suction tool, from flange to cup
TOOL_RADIUS = 0.015
JOINT_NAMES = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3")


def _inertial(mass: float, r: float, length: float) -> str:
    ixx = mass * (3 * r * r + length * length) / 12.0 + 1e-4
    izz = mass * r * r / 2.0 + 1e-4
    return (f'<inertial><origin xyz="0 0 0"/><mass value="{mass}"/>'
            f'<inertia ixx="{ixx:.6f}" ixy="0" ixz="0" iyy="{ixx:.6f}" iyz="0" izz="{izz:.6f}"/></inertial>')


def _cylinder_to(dx: float, dz: float, r: float, colour: str) -> str:
    """A visual cylinder from the link origin to (dx, 0, dz); UR10 offsets lie on x or on z."""
    length = max(abs(dx), abs(dz), 1e-3)
    rpy = f"0 {math.pi / 2:.6f} 0" if abs(dx) > abs(dz) else "0 0 0"
    return (f'<visual><origin xyz="{dx / 2:.6f} 0 {dz / 2:.6f}" rpy="{rpy}"/>'
            f'<geometry><cylinder radius="{r}" length="{length:.6f}"/></geometry>'
            f'<material name="{colour}"/></visual>')


def ur10_urdf() -> str:
    """The URDF text of a UR10 with a suction tool; link 'tool' ends at the cup (its frame)."""
    parts = ['<?xml version="1.0"?>', '<robot name="ur10_suction">',
             '<material name="grey"><color rgba="0.6 0.6 0.65 1"/></material>',
             '<material name="blue"><color rgba="0.2 0.4 0.8 1"/></material>',
             '<material name="black"><color rgba="0.1 0.1 0.1 1"/></material>',
             f'<link name="base">{_inertial(4.0, 0.08, 0.05)}'
             f'<visual><origin xyz="0 0 0.025"/><geometry><cylinder radius="0.08" length="0.05"/>'
             f'</geometry><material name="grey"/></visual></link>']
    parent = "base"
    prev_offset = ((0.0, 0.0, 0.0), 0.0)  # joint 1 sits at the base origin
    for i, ((d, a, alpha), name) in enumerate(zip(UR10_DH, JOINT_NAMES)):
        link = f"link{i + 1}"
        (ox, oy, oz), roll = prev_offset
        parts.append(
            f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{link}"/>'
            f'<origin xyz="{ox:.6f} {oy:.6f} {oz:.6f}" rpy="{roll:.6f} 0 0"/><axis xyz="0 0 1"/>'
            f'<limit lower="{-2 * math.pi:.6f}" upper="{2 * math.pi:.6f}" effort="330" velocity="3.2"/>'
            f'<dynamics damping="0.5"/></joint>')
        colour = "blue" if i % 2 else "grey"
        length = max(abs(a), abs(d), 0.05)
        parts.append(f'<link name="{link}">{_inertial(LINK_MASS[i], LINK_RADIUS[i], length)}'
                     f'{_cylinder_to(a, d, LINK_RADIUS[i], colour)}</link>')
        parent = link
        prev_offset = ((a, 0.0, d), alpha)
    (ox, oy, oz), roll = prev_offset
    half = TOOL_LENGTH / 2
    parts.append(
        f'<joint name="tool_mount" type="fixed"><parent link="{parent}"/><child link="tool"/>'
        f'<origin xyz="{ox:.6f} {oy:.6f} {oz + TOOL_LENGTH:.6f}" rpy="{roll:.6f} 0 0"/></joint>')
    shape = f'<cylinder radius="{TOOL_RADIUS}" length="{TOOL_LENGTH}"/>'
    parts.append(
        f'<link name="tool">{_inertial(0.2, TOOL_RADIUS, TOOL_LENGTH)}'
        f'<visual><origin xyz="0 0 {-half}"/><geometry>{shape}</geometry><material name="black"/></visual>'
        f'<collision><origin xyz="0 0 {-half}"/><geometry>{shape}</geometry></collision></link>')
    parts.append("</robot>")
    return "\n".join(parts)


def forward_kinematics(q) -> tuple:
    """Tool cup position (3,) and rotation matrix (3, 3) for joint angles q, from the DH table."""
    import numpy as np

    T = np.eye(4)
    for qi, (d, a, alpha) in zip(q, UR10_DH):
        ct, st, ca, sa = np.cos(qi), np.sin(qi), np.cos(alpha), np.sin(alpha)
        T = T @ np.array([[ct, -st * ca, st * sa, a * ct],
                          [st, ct * ca, -ct * sa, a * st],
                          [0.0, sa, ca, d],
                          [0.0, 0.0, 0.0, 1.0]])
    tip = T @ np.array([0.0, 0.0, TOOL_LENGTH, 1.0])
    return tip[:3], T[:3, :3]
