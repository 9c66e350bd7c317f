"""The Unimation Puma 560 as a :class:`SerialArm` (standard DH)."""

from __future__ import annotations

import functools

import numpy as np

from plants.arms.dh_link import DHLink
from plants.arms.serial_arm import SerialArm

# Standard DH, masses, COMs and inertias exactly as Corke's Robotics Toolbox
# ``roboticstoolbox.models.DH.Puma560()`` (v1.5), which takes them from
# B. Armstrong, O. Khatib, J. Burdick, "The explicit dynamic model and inertial parameters of
# the PUMA 560 arm", Proc. IEEE ICRA 1986, pp. 510-518 (the toolbox folds the base height
# into d1 = 0.67183 m). Columns: a [m], alpha [rad], d [m], mass [kg], rc [m], inertia about
# the COM (Ixx, Iyy, Izz, Ixy, Iyz, Ixz) [kg m^2], motor inertia Jm [kg m^2], gear ratio G,
# motor viscous friction B [N m s/rad] (referred to the motor).
_HALF_PI = np.pi / 2
#: The Puma 560's DH and inertial parameters, one row per link (columns as above).
PUMA_TABLE = (
    # a,      alpha,     d,       m,    rc,                        I,                                      Jm,      G,        B
    (0.0, _HALF_PI, 0.67183, 0.0, (0.0, 0.0, 0.0), (0.0, 0.35, 0.0, 0.0, 0.0, 0.0), 200e-6, -62.6111, 1.48e-3),
    (0.4318, 0.0, 0.0, 17.4, (-0.3638, 0.006, 0.2275), (0.13, 0.524, 0.539, 0.0, 0.0, 0.0), 200e-6, 107.815, 0.817e-3),
    (0.0203, -_HALF_PI, 0.15005, 4.8, (-0.0203, -0.0141, 0.07), (0.066, 0.086, 0.0125, 0.0, 0.0, 0.0), 200e-6, -53.7063, 1.38e-3),
    (0.0, _HALF_PI, 0.4318, 0.82, (0.0, 0.019, 0.0), (1.8e-3, 1.3e-3, 1.8e-3, 0.0, 0.0, 0.0), 33e-6, 76.0364, 71.2e-6),
    (0.0, -_HALF_PI, 0.0, 0.34, (0.0, 0.0, 0.0), (0.3e-3, 0.4e-3, 0.3e-3, 0.0, 0.0, 0.0), 33e-6, 71.923, 82.6e-6),
    (0.0, 0.0, 0.0, 0.09, (0.0, 0.0, 0.032), (0.15e-3, 0.15e-3, 0.04e-3, 0.0, 0.0, 0.0), 33e-6, 76.686, 36.7e-6),
)

#: Joint limits [rad], as ``rtb.models.DH.Puma560().qlim``.
PUMA560_Q_LIMITS = np.deg2rad(
    [[-160.0, 160.0], [-45.0, 225.0], [-225.0, 45.0], [-110.0, 170.0], [-100.0, 100.0], [-266.0, 266.0]]
)

#: Maximum joint torques [N m]: the widely used set attributed to Armstrong, Khatib & Burdick
#: (ICRA 1986, table of maximum torques), used e.g. in time-optimal trajectory studies of the
#: Puma 560. (Quoted from secondary sources; not checked against the original table here.)
PUMA560_TAU_MAX = np.array([97.6, 186.4, 89.4, 24.2, 20.1, 21.3])


def puma560(base=None, tool=None, motor_inertia: bool = False, viscous_friction: bool = False, name: str = "puma560") -> SerialArm:
    """The classic Puma 560 (Armstrong, Khatib & Burdick 1986, via Corke's toolbox).

    Args:
        base: World pose of the base frame, 4x4 [m] (default identity: the toolbox's d1
            already puts the shoulder 0.67183 m above the floor).
        tool: Node frame in the last DH frame, 4x4 [m] (default identity).
        motor_inertia: Add the reflected motor inertias ``Jm G^2`` [kg m^2] to ``H``'s diagonal.
        viscous_friction: Add viscous joint friction ``B G^2`` [N m s/rad] to ``h``.
        name: Name used in error messages.

    Torque limits are :data:`PUMA560_TAU_MAX`, joint limits :data:`PUMA560_Q_LIMITS`.
    """
    return SerialArm(
        name=name,
        links=_puma_links(bool(motor_inertia), bool(viscous_friction)),
        base=np.eye(4) if base is None else base,
        tool=np.eye(4) if tool is None else tool,
        tau_max=PUMA560_TAU_MAX,
        q_limits=PUMA560_Q_LIMITS,
    )


@functools.lru_cache(maxsize=4)
def _puma_links(motor_inertia: bool, viscous_friction: bool) -> tuple:
    """The six :class:`DHLink` of :data:`PUMA_TABLE` (frozen: built and checked once, then shared)."""
    links = []
    for i, (a, alpha, d, m, rc, inertia, Jm, G, B) in enumerate(PUMA_TABLE):
        links.append(
            DHLink.named(
                f"links[{i}]",
                a=a,
                alpha=alpha,
                d=d,
                mass=m,
                rc=rc,
                inertia=inertia,
                motor_inertia=Jm * G * G if motor_inertia else 0.0,
                viscous=B * G * G if viscous_friction else 0.0,
                # Armstrong et al.'s link 3 (0.066, 0.086, 0.0125) violates I1 + I2 >= I3 by
                # 9 %; the published numbers are kept (they are still PSD).
                check_triangle_inequality=False,
            )
        )
    return tuple(links)


#: Node frame of a Puma 560 gripper [4x4]: the node's x axis is the flange's approach axis (z6),
#: and the node sits 5 cm beyond the flange. With it, a node whose frame is aligned with the
#: object's frame is approached along +x, away from the ZYX singularity at pitch +-90 deg.
GRIPPER_TOOL = np.array([[0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.05], [0.0, 0.0, 0.0, 1.0]])
