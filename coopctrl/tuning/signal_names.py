"""Names of the signals of the linear models (states, inputs, outputs), one convention for all.

Arms are numbered from 1 in signal names (``arm1`` is ``arms[0]``), as in
:meth:`CooperativePlant.state_names`. Poses follow docs/model.md s.2; wrenches are world-frame
``(F, M)`` as a wrist sensor reads them (:meth:`CooperativePlant.contact_wrenches`).

=============================  ==================================  =========
name                           meaning                             unit
=============================  ==================================  =========
``object_x`` ...               object MC pose                      m, rad
``arm2_node_x`` ...            contact node pose of arm 2          m, rad
``arm2_Fx`` ... ``arm2_Mz``    wrench of arm 2's interconnection   N, N m
``arm2_force_error_Fx`` ...    ``F* - F_meas`` of follower 2       N, N m
``arm1_ref_x`` ...             offset of the leader's target pose  m, rad
``arm2_setpoint_Fx`` ...       offset of follower 2's setpoint     N, N m
``arm2_pi_Fx`` ...             follower 2's PI output ``v``        N, N m
``arm2_force_integral_Fx``     follower 2's error integral         N s
=============================  ==================================  =========

Planar wrenches are ``(Fx, Fz, M)``: the couple ``M`` is about the plane's normal, positive
in the sense of ``theta``.
"""

from __future__ import annotations

#: Pose coordinates per space (docs/model.md s.2).
POSE = {"spatial": ("x", "y", "z", "psi", "theta", "phi"), "planar": ("x", "z", "theta")}

#: Wrench components per space (world frame).
WRENCH = {"spatial": ("Fx", "Fy", "Fz", "Mx", "My", "Mz"), "planar": ("Fx", "Fz", "M")}


def arm(i: int) -> str:
    """Signal prefix of ``arms[i]`` (0-based index): ``"arm{i+1}"``."""
    return f"arm{i + 1}"


def object_pose(space: str) -> list[str]:
    return [f"object_{c}" for c in POSE[space]]


def node_pose(space: str, i: int) -> list[str]:
    return [f"{arm(i)}_node_{c}" for c in POSE[space]]


def wrench(space: str, i: int) -> list[str]:
    return [f"{arm(i)}_{c}" for c in WRENCH[space]]


def force_error(space: str, i: int) -> list[str]:
    return [f"{arm(i)}_force_error_{c}" for c in WRENCH[space]]


def leader_reference(space: str, i: int) -> list[str]:
    return [f"{arm(i)}_ref_{c}" for c in POSE[space]]


def force_setpoint(space: str, i: int) -> list[str]:
    return [f"{arm(i)}_setpoint_{c}" for c in WRENCH[space]]


def pi_output(space: str, i: int) -> list[str]:
    return [f"{arm(i)}_pi_{c}" for c in WRENCH[space]]


def force_integral(space: str, i: int) -> list[str]:
    return [f"{arm(i)}_force_integral_{c}" for c in WRENCH[space]]


def component_index(space: str, component: str) -> int:
    """Index of a wrench component name (``"Fx"``) in the space's wrench; ValueError otherwise."""
    names = WRENCH[space]
    if component not in names:
        raise ValueError(f"component = {component!r} is invalid: expected one of {', '.join(names)} in a {space} scene")
    return names.index(component)


def axis_index(space: str, axis: str) -> int:
    """Index of a pose coordinate name (``"x"``, ``"theta"``); ValueError otherwise."""
    names = POSE[space]
    if axis not in names:
        raise ValueError(f"axis = {axis!r} is invalid: expected one of {', '.join(names)} in a {space} scene")
    return names.index(axis)
