"""Assemble a cooperative plant from an object, arms and grasps, and its unloaded initial state."""

from __future__ import annotations

from typing import Sequence

import numpy as np

from plants.cooperative.contact_point import ContactPoint
from plants.cooperative.cooperative_plant import CooperativePlant
from plants.cooperative.loaded_state import nominal_node_poses
from plants.elastic import ElasticSystem, Interconnection, Node
from plants.errors import ParameterError


def assemble_plant(
    space: str,
    object_node: Node,
    object_pose,
    arms: Sequence,
    grasps,
    contact_nodes: Sequence[Node],
    interconnections: Sequence[Interconnection],
    gravity=9.81,
    unloaded_state: str = "mobile",
    leader: int = 0,
    q0: Sequence | None = None,
):
    """Build the plant whose unloaded state has every contact node at its grasp, and that state.

    The reference (unloaded) node poses are the nominal poses (148) of the object at
    ``object_pose`` with contact j at ``grasps[j]`` in the object frame; every arm's joints are
    found by inverse kinematics so that its tip is at its node
    (:class:`~plants.errors.UnreachablePoseError` if it cannot be).

    Returns:
        ``(plant, x0)``: the :class:`CooperativePlant` and the state at rest in the unloaded
        configuration (springs undeformed; gravity is not yet balanced).
    """
    Y0 = np.asarray(object_pose, dtype=float)
    grasps = np.atleast_2d(np.asarray(grasps, dtype=float))
    m = len(arms)
    if grasps.shape[0] != m or len(contact_nodes) != m:
        raise ParameterError("grasps", grasps.shape, f"one grasp and one contact node per arm ({m})")
    Y_ref = nominal_node_poses(Y0, grasps, space)
    elastic = ElasticSystem(space, [object_node, *contact_nodes], interconnections, Y_ref, gravity, unloaded_state)
    qs = []
    for i, arm in enumerate(arms):
        seed = None if q0 is None or q0[i] is None else q0[i]
        if isinstance(arm, ContactPoint):
            qs.append(Y_ref[i + 1].copy())
        else:
            qs.append(arm.inverse_kinematics(Y_ref[i + 1], seed))
    plant = CooperativePlant(elastic, arms, leader=leader)
    z = np.concatenate([*qs, Y0])
    return plant, np.concatenate([z, np.zeros_like(z)])
