import numpy as np
import pybullet as pb

from symlearn.sim.ur10_urdf import forward_kinematics


def test_generated_urdf_matches_dh_forward_kinematics(sim):
    """The URDF written from the DH table moves exactly as the DH equations say."""
    rng = np.random.default_rng(0)
    saved = [pb.getJointState(sim.robot, j, physicsClientId=sim.cid)[0] for j in range(6)]
    try:
        for _ in range(5):
            q = rng.uniform(-3, 3, 6)
            for j in range(6):
                pb.resetJointState(sim.robot, j, q[j], physicsClientId=sim.cid)
            pos, orn = pb.getLinkState(sim.robot, 6, computeForwardKinematics=True, physicsClientId=sim.cid)[4:6]
            p, R = forward_kinematics(q)
            np.testing.assert_allclose(np.asarray(pos), p + np.asarray(sim.cfg.robot_base), atol=1e-6)
            np.testing.assert_allclose(np.reshape(pb.getMatrixFromQuaternion(orn), (3, 3)), R, atol=1e-6)
    finally:
        for j, v in enumerate(saved):
            pb.resetJointState(sim.robot, j, v, physicsClientId=sim.cid)


def test_ur10_reach_matches_published_arm_lengths():
    # Fully stretched along x: shoulder lift and elbow at zero put the wrist at a2 + a3.
    p, _ = forward_kinematics(np.zeros(6))
    assert abs(p[0] - (-0.612 - 0.5723)) < 1e-9
