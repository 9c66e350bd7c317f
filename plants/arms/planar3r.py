"""A planar three-link (3R) arm in the vertical x-z plane as a :class:`PlanarArm`."""

from __future__ import annotations

import numpy as np

from plants.arms.planar_arm import PlanarArm
from plants.arms.planar_link import PlanarLink
from plants.errors import ParameterError

#: Design payload at the tip [kg] that the default torque limits hold with margin.
DESIGN_PAYLOAD = 5.0
#: Margin factor on the worst-case static torque (arm stretched horizontally).
TORQUE_MARGIN = 2.0
#: Least gravity [m/s^2] the default torque limits are sized for: the motors of an arm do not vanish
#: in weightlessness, so a scene at ``gravity = 0`` keeps the limits of standard gravity.
DESIGN_GRAVITY = 9.81


def planar3r(
    base=None,
    tool=None,
    lengths=(0.4, 0.4, 0.15),
    masses=(4.0, 3.0, 1.0),
    tau_max=None,
    motor_inertia=(0.0, 0.0, 0.0),
    viscous_friction=(0.0, 0.0, 0.0),
    q_limits=None,
    gravity=(0.0, -9.81),
    name: str = "planar3r",
) -> PlanarArm:
    """A planar 3R arm with uniform-rod links (COM at mid-length, ``Izz = m l^2 / 12``).

    Args:
        base: ``(x, z, theta)`` of joint 1 [m, m, rad] (default origin, pointing along +x).
        tool: ``(dx, dz, dtheta)`` of the node frame from the end of link 3 (default zero).
        lengths: Link lengths [m].
        masses: Link masses [kg].
        tau_max: Torque limits [N m]; default: ``TORQUE_MARGIN`` times the static torque of
            the horizontally stretched arm carrying ``DESIGN_PAYLOAD`` kg at the tip, under
            ``max(|gravity|, DESIGN_GRAVITY)`` (never zero, also at zero gravity).
        motor_inertia: Reflected motor inertias [kg m^2] (default off).
        viscous_friction: Joint viscous friction [N m s/rad] (default off).
        q_limits: Joint limits (3, 2) [rad]; default ``[-pi, pi]`` for each joint.
        gravity: ``(gx, gz)`` [m/s^2].
        name: Name used in error messages.
    """
    lengths = np.asarray(lengths, dtype=float)
    masses = np.asarray(masses, dtype=float)
    for label, arr in (("lengths", lengths), ("masses", masses)):
        if arr.shape != (3,):
            raise ParameterError(label, arr.tolist(), "3 numbers")
    links = tuple(
        PlanarLink.named(
            f"links[{i}]",
            length=lengths[i],
            mass=masses[i],
            rc=(0.5 * lengths[i], 0.0),
            izz=masses[i] * lengths[i] ** 2 / 12.0,
            motor_inertia=motor_inertia[i],
            viscous=viscous_friction[i],
        )
        for i in range(3)
    )
    if tau_max is None:
        g = max(float(np.hypot(*gravity)), DESIGN_GRAVITY)
        tool_dx = 0.0 if tool is None else float(tool[0])
        static = np.empty(3)
        for j in range(3):
            # torque at joint j of links j.. and the payload, all stretched horizontally
            torque = 0.0
            reach = 0.0
            for k in range(j, 3):
                torque += masses[k] * g * (reach + 0.5 * lengths[k])
                reach += lengths[k]
            torque += DESIGN_PAYLOAD * g * (reach + max(tool_dx, 0.0))
            static[j] = torque
        tau_max = TORQUE_MARGIN * static
    return PlanarArm(
        name=name,
        links=links,
        base=np.zeros(3) if base is None else base,
        tool=np.zeros(3) if tool is None else tool,
        gravity=gravity,
        tau_max=tau_max,
        q_limits=q_limits,
    )
