"""Small reference scenes for the physics tests (plants only; no control layer)."""

from __future__ import annotations

import numpy as np

from plants.arms import planar3r, puma560
from plants.cooperative import ContactPoint, assemble_plant
from plants.elastic import Interconnection, Node
from plants.frames import rotation_zyx

from plants.arms.puma560 import GRIPPER_TOOL as PUMA_TOOL  # noqa: E402


def _T(xyz, A):
    T = np.eye(4)
    T[:3, :3] = rotation_zyx(np.asarray(A, dtype=float))
    T[:3, 3] = xyz
    return T


def scene(space="spatial", m=2, arms="full", element="offset", stiffness=2e4, torsion=200.0,
          damping=0.0, torsion_damping=0.0, unloaded_state="mobile", gravity=9.81, node_springs=False,
          damping_form="frame_invariant"):
    """A symmetric grasp: m arms around the object, contacts 0.15 m (0.1 m planar) from its MC."""
    if space == "spatial":
        obj = Node(2.0, (0.02, 0.025, 0.03), name="object")
        pose = np.array([0.0, 0.0, 0.5, 0.0, 0.0, 0.0])
        arm_list, grasps = [], []
        for k in range(m):
            phi = np.pi + 2 * np.pi * k / m
            c, s = np.cos(phi), np.sin(phi)
            grasps.append([0.15 * c, 0.15 * s, 0.0, phi + np.pi, 0.0, 0.0])
            if arms == "full":
                arm_list.append(puma560(base=_T([0.7 * c, 0.7 * s, 0.0], [phi + np.pi, 0, 0]), tool=PUMA_TOOL))
            else:
                arm_list.append(ContactPoint("spatial", name=f"arm{k}"))
        nodes = [Node(0.3, (1e-3, 1.2e-3, 1.4e-3), name=f"nodes[{k + 1}]") for k in range(m)]
    else:
        obj = Node(2.0, (0.02,), name="object")
        pose = np.array([0.0, 0.4, 0.0])
        bases = [(-0.6, 0.0, 0.0), (0.6, 0.0, np.pi), (0.0, -0.3, np.pi / 2)]
        grasps_all = [(-0.1, 0.0, 0.0), (0.1, 0.0, np.pi), (0.0, -0.08, np.pi / 2)]
        grasps = [grasps_all[k] for k in range(m)]
        arm_list = [planar3r(base=bases[k]) if arms == "full" else ContactPoint("planar", name=f"arm{k}")
                    for k in range(m)]
        nodes = [Node(0.3, (1e-3,), name=f"nodes[{k + 1}]") for k in range(m)]
    springs = [Interconnection((0, k + 1), stiffness=stiffness, torsion=torsion, damping=damping,
                               torsion_damping=torsion_damping, element=element, damping_form=damping_form)
               for k in range(m)]
    if node_springs:
        springs += [Interconnection((k, k + 1), stiffness=stiffness / 4, damping=damping, damping_form=damping_form)
                    for k in range(1, m)]
    q0 = None
    if arms == "full" and space == "planar":
        q0 = [np.array([0.8, -1.6, 0.8]), np.array([-0.8, 1.6, -0.8]), np.array([0.3, 0.5, 0.8])][:m]
    return assemble_plant(space, obj, pose, arm_list, np.array(grasps), nodes, springs, gravity=gravity,
                          unloaded_state=unloaded_state, q0=q0)
