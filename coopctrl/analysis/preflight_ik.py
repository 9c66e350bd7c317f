"""Compiled, warm-started inverse kinematics for pre-flight (:mod:`coopctrl.analysis.preflight`).

Pre-flight follows each arm along the nominal path: the joints found at one sample seed the next, so
one damped least-squares solve of a few iterations suffices where the motion is smooth. :func:`warm_ik`
runs that solve in the C++ core (``coopctrl._core.spatial_ik``, ``refine_posture``, ``planar_ik``,
coopctrl/core/preflight_ik.h), on the plants' own forward kinematics (plants/core: the DH and chain arms' tips,
the planar arm's terms): the same iteration as the arms' Python :meth:`inverse_kinematics` (one seed, no
restart),

.. math::

    \\Delta q = J_e^T (J_e J_e^T + \\lambda I)^{-1} e, \\qquad q \\leftarrow \\mathrm{clip}(q + \\Delta q,
    q_{lower}, q_{upper})

kept when ``|e|^2`` falls (then ``lambda <- max(0.3 lambda, 1e-12)``, else ``lambda <- 5 lambda``, given
up above ``1e6``), from ``lambda = 1e-2``, at most 200 iterations (``IK_MAX_ITERATIONS``), until the position
residual ``|e_p|`` [m] and the rotation residual ``|e_r|`` [rad] are both at most
:data:`~plants.arms.spatial_ik.IK_TOLERANCE`. Spatial: ``e_p = p_target - p(q)``,
``e_r`` the rotation vector of ``R_target R(q)^T`` (through its unit quaternion, no Euler-angle
difference); ``J_e`` the geometric Jacobian. Planar: ``e = Y_target - Y(q)`` with its angle wrapped to
``(-pi, pi]``; ``J_e`` the analytic Jacobian.

A redundant spatial arm (more than 6 joints) is then moved along its self-motion manifold toward its
rest posture, as its Python solve does (``refine_posture``). A solve that does not converge returns
``False``: the caller falls back to the arm's own :meth:`inverse_kinematics` with its random restarts,
which also measures the residual it reports.

At velocity level, the core's ``square_joint_rates_into`` gives the joint rates that follow the nodes' nominal
rates, ``J_i dq_i = dY_i`` (LU with partial pivoting), where every arm's Jacobian is square and regular
(pre-flight calls it; it returns ``False`` otherwise, and pre-flight solves that case in the least-squares sense).
"""

from __future__ import annotations

import numpy as np

from plants.arms.spatial_ik import IK_TOLERANCE, POSTURE_ITERATIONS, POSTURE_STEP

#: ``kind`` of a spatial arm: standard DH table (``SerialArm.dh_array``) or general chain
#: (``ChainArm.kernel_table``).
KIND_DH, KIND_CHAIN = 0, 1


def warm_ik(arm):
    """``solve(target, q0) -> q or None`` for ``arm``: the core's ``spatial_ik`` or ``planar_ik`` from the seed
    ``q0`` (not changed) toward the node pose ``target`` [m, rad], ``None`` where it does not converge; or
    ``None`` for an arm not solved here (a contact point, an arm of another class) (module docstring)."""
    from coopctrl._core import planar_ik, refine_posture, spatial_ik
    from plants.arms.chain_arm import ChainArm
    from plants.arms.planar_arm import PlanarArm
    from plants.arms.serial_arm import SerialArm

    def f64(a):
        return np.array(a, dtype=np.float64, order="C")  # writable C-contiguous copies, as the core takes them

    if isinstance(arm, (SerialArm, ChainArm)):
        kind = KIND_DH if isinstance(arm, SerialArm) else KIND_CHAIN
        table = f64(arm.dh_array() if kind == KIND_DH else arm.kernel_table())
        base, tool, posture = f64(arm.base), f64(arm.tool), f64(arm.rest_posture())
        lower, upper = f64(arm.q_limits[:, 0]), f64(arm.q_limits[:, 1])

        def solve(target, q0):
            q, target = f64(q0), f64(target)
            if not spatial_ik(kind, table, base, tool, lower, upper, target, q, IK_TOLERANCE):
                return None
            if q.shape[0] > 6:
                refine_posture(kind, table, base, tool, lower, upper, posture, target, q, IK_TOLERANCE,
                               POSTURE_ITERATIONS, POSTURE_STEP)
            return q

        return solve
    if isinstance(arm, PlanarArm):
        links, base, tool, gravity = f64(arm.link_array()), f64(arm.base), f64(arm.tool), f64(arm.gravity)
        lower, upper = f64(arm.q_limits[:, 0]), f64(arm.q_limits[:, 1])

        def solve(target, q0):
            q = f64(q0)
            return q if planar_ik(links, base, tool, gravity, lower, upper, f64(target), q, IK_TOLERANCE) else None

        return solve
    return None
