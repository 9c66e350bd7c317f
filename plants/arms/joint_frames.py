"""Joint frame positions of an arm, for drawing it (the replay of ``coopctrl view``).

:func:`arm_polyline` gives the world points of an arm's links from its base to its node frame.
It recomputes the forward kinematics in plain numpy from the same link tables the kernels use
(standard DH for :class:`~plants.arms.SerialArm`, (168); the planar chain for
:class:`~plants.arms.PlanarArm`), and changes nothing in the arm classes. An arm class may
provide its own ``joint_polyline(q)``; any other arm is drawn as its base-to-node segment.
"""

from __future__ import annotations

import math

import numpy as np

from plants.arms.planar_arm import PlanarArm
from plants.arms.serial_arm import SerialArm


def serial_arm_polyline(arm: SerialArm, q) -> np.ndarray:
    """(2n + 2, 3) world points [m]: frame 0's origin; per joint k the point after ``Tz(d_k)``
    and frame k's origin (``Rz(q_k + offset_k) Tz(d_k) Tx(a_k) Rx(alpha_k)``); the node frame's
    origin (``tool``) last."""
    q = np.asarray(q, dtype=float).reshape(-1)
    T = np.array(arm.base, dtype=float)
    points = [T[:3, 3].copy()]
    for link, qk in zip(arm.links, q):
        th = qk + link.offset
        ct, st = math.cos(th), math.sin(th)
        ca, sa = math.cos(link.alpha), math.sin(link.alpha)
        A = np.array([[ct, -st * ca, st * sa, link.a * ct],
                      [st, ct * ca, -ct * sa, link.a * st],
                      [0.0, sa, ca, link.d],
                      [0.0, 0.0, 0.0, 1.0]])
        points.append(T[:3, 3] + T[:3, 2] * link.d)
        T = T @ A
        points.append(T[:3, 3].copy())
    points.append((T @ np.asarray(arm.tool, dtype=float))[:3, 3])
    return np.array(points)


def planar_arm_polyline(arm: PlanarArm, q) -> np.ndarray:
    """(n + 2, 3) world points ``(x, 0, z)`` [m]: joint 1, each next joint, the node frame."""
    q = np.asarray(q, dtype=float).reshape(-1)
    ox, oz, th = (float(v) for v in arm.base)
    points = [(ox, 0.0, oz)]
    for link, qk in zip(arm.links, q):
        th += qk
        ox += link.length * math.cos(th)
        oz += link.length * math.sin(th)
        points.append((ox, 0.0, oz))
    ct, st = math.cos(th), math.sin(th)
    tool = arm.tool
    points.append((ox + ct * tool[0] - st * tool[1], 0.0, oz + st * tool[0] + ct * tool[1]))
    return np.array(points)


def arm_polyline(arm, q) -> np.ndarray | None:
    """World points [m] of the arm's links from base to node (planar arms at y = 0), or
    ``None`` for an arm this module cannot draw (the caller draws the base-to-node segment)."""
    own = getattr(arm, "joint_polyline", None)
    if callable(own):
        return np.asarray(own(q), dtype=float)
    if isinstance(arm, SerialArm):
        return serial_arm_polyline(arm, q)
    if isinstance(arm, PlanarArm):
        return planar_arm_polyline(arm, q)
    return None
