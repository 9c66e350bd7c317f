"""Named robots shipped with the package: Franka Panda, UR5e, KUKA iiwa 14 (URDF in ``data/``).

Each file names its source and licence in its header. They are cut down to kinematics, inertia,
limits and joint dynamics: no meshes.
"""

from __future__ import annotations

from importlib import resources

import numpy as np

from plants.arms.urdf import from_urdf

#: Robot name -> (URDF file in ``plants/arms/data``, base link, tip link).
NAMED_ROBOTS = {
    "panda": ("panda.urdf", "panda_link0", "panda_hand_tcp"),
    "ur5e": ("ur5e.urdf", "base_link", "tool0"),
    "iiwa14": ("iiwa14.urdf", "base", "iiwa_link_ee"),
}


#: Node frame in the tip link frame such that the node's x axis is the approach axis (as the
#: Puma's ``GRIPPER_TOOL``): a node frame aligned with the object frame is approached along +x,
#: away from the ZYX singularity at pitch +-90 deg. Panda and UR5e tips approach along their z,
#: the iiwa's ``iiwa_link_ee`` along its x.
_Z_TO_X = np.array([[0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
APPROACH_TOOLS = {"panda": _Z_TO_X, "ur5e": _Z_TO_X, "iiwa14": np.eye(4)}


def urdf_path(robot: str) -> str:
    """Path of the shipped URDF of a named robot."""
    return str(resources.files("plants.arms").joinpath("data", NAMED_ROBOTS[robot][0]))


def named_robot(robot: str, tool=None, **kwargs):
    """A named robot as a :class:`ChainArm` (``tool`` 4x4 in its tip link frame, see
    :func:`plants.arms.from_urdf` for the keyword arguments)."""
    _, base_link, tip_link = NAMED_ROBOTS[robot]
    kwargs.setdefault("name", robot)
    return from_urdf(urdf_path(robot), base_link, tip_link, tool, **kwargs)


def panda(tool=None, **kwargs):
    """Franka Emika Panda (7 joints), ``panda_link0`` to ``panda_hand_tcp``, the hand and its
    fingers folded into link 7 (fingers closed). Source: franka_description, Apache-2.0."""
    return named_robot("panda", tool, **kwargs)


def ur5e(tool=None, **kwargs):
    """Universal Robots UR5e (6 joints), ``base_link`` to ``tool0``.
    Source: Universal_Robots_ROS2_Description, BSD-3-Clause."""
    return named_robot("ur5e", tool, **kwargs)


def iiwa14(tool=None, **kwargs):
    """KUKA LBR iiwa 14 R820 (7 joints), ``base`` to ``iiwa_link_ee`` (x along the flange
    axis). Source: Drake / iiwa_stack, BSD."""
    return named_robot("iiwa14", tool, **kwargs)
