"""The joint table of a general serial chain (docs/model.md s.4): one float64 row of :data:`CHAIN_COLUMNS`
per moving joint, written by :meth:`plants.arms.chain_joint.ChainJoint.kernel_row` and read by the compiled
core (plants/core/chain_arm.h, ``ChainJointRow``)::

    [type, ox, oy, oz, R00..R22 (9, row-major), ax, ay, az, mass, rcx, rcy, rcz,
     Ixx, Iyy, Izz, Ixy, Iyz, Ixz, motor_inertia, viscous, coulomb, 0, 0, 0]

``type``: :data:`JOINT_REVOLUTE_Z` (revolute about +z of the joint frame, the fast path),
:data:`JOINT_REVOLUTE` (about ``axis``) or :data:`JOINT_PRISMATIC` (along ``axis``). ``(ox, oy, oz)`` [m]
and ``R`` are the joint's fixed transform in the previous link frame; mass [kg], COM [m] and inertia about
the COM [kg m^2] in the link's own frame; ``motor_inertia`` [kg m^2 or kg] is added to ``H[k, k]``,
``viscous`` [N m s/rad or N s/m] adds ``viscous * dq_k`` to ``h_k`` and ``coulomb`` [N m or N] the smoothed
Coulomb friction ``coulomb * tanh(dq_k / COULOMB_SMOOTHING)``.
"""

from __future__ import annotations

from plants import _core

#: Joint types (column :data:`COL_TYPE`), the compiled core's codes.
JOINT_REVOLUTE_Z, JOINT_REVOLUTE, JOINT_PRISMATIC = _core.JOINT_REVOLUTE_Z, _core.JOINT_REVOLUTE, _core.JOINT_PRISMATIC

# Columns of the joint table.
COL_TYPE = 0
COL_ORIGIN = 1  # 1, 2, 3
COL_ROT = 4  # 4..12
COL_AXIS = 13  # 13, 14, 15
COL_MASS = 16
COL_RC = 17  # 17, 18, 19
COL_I = 20  # Ixx, Iyy, Izz, Ixy, Iyz, Ixz
COL_MOTOR, COL_VISCOUS, COL_COULOMB = 26, 27, 28
CHAIN_COLUMNS = 32
#: Velocity scale [rad/s or m/s] of the smoothed Coulomb friction ``coulomb * tanh(dq / COULOMB_SMOOTHING)``
#: (plants/core/chain_arm.h).
COULOMB_SMOOTHING = _core.COULOMB_SMOOTHING
