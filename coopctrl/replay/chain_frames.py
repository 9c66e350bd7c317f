"""The body frames of a :class:`~plants.arms.ChainArm` (URDF arms), for drawing it.

Body 0 is the base frame ``T_0 = base``; body ``k`` (the child link of moving joint ``k``) is
``T_k = T_{k-1} origin_k M_k(q_k)`` with ``M_k = Rot(axis_k, q_k)`` for a revolute joint
(``q_k`` [rad], Rodrigues' formula) and ``Trans(axis_k q_k)`` for a prismatic one (``q_k``
[m]), as :class:`~plants.arms.ChainJoint` defines it. The node frame is ``T_n tool``. This is the
kernels' forward kinematics redone in plain numpy (the tests compare it with
``ChainArm.tip_transform``).
"""

from __future__ import annotations

import numpy as np

from plants.arms.chain_arm import ChainArm


def _motion(kind: str, axis, q: float) -> np.ndarray:
    M = np.eye(4)
    u = np.asarray(axis, dtype=float)
    if kind == "prismatic":
        M[:3, 3] = u * q
        return M
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    M[:3, :3] = np.eye(3) + np.sin(q) * K + (1.0 - np.cos(q)) * (K @ K)
    return M


def chain_body_frames(arm: ChainArm, q) -> np.ndarray:
    """(n + 1, 4, 4) world poses [m] of the base (body 0) and of each moving link's frame."""
    q = np.asarray(q, dtype=float).reshape(-1)
    T = np.array(arm.base, dtype=float)
    frames = [T]
    for joint, qk in zip(arm.joints, q):
        T = T @ joint.origin @ _motion(joint.kind, joint.axis, float(qk))
        frames.append(T)
    return np.array(frames)


def chain_polyline(arm: ChainArm, q) -> np.ndarray:
    """(n + 2, 3) world points [m]: the base origin, each moving link frame's origin, the node.

    Segment 0 (base to link 1) is the fixed base link; segment ``k`` (link ``k``'s origin to
    link ``k + 1``'s, or to the node for ``k = n``) is moving link ``k``.
    """
    frames = chain_body_frames(arm, q)
    node = frames[-1] @ np.asarray(arm.tool, dtype=float)
    return np.vstack([frames[:, :3, 3], node[:3, 3]])
