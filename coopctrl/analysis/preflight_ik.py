"""Compiled, warm-started inverse kinematics for pre-flight (:mod:`coopctrl.analysis.preflight`).

Pre-flight follows each arm along the nominal path: the joints found at one sample seed the next, so
one damped least-squares solve of a few iterations suffices where the motion is smooth. :func:`warm_ik`
runs that solve in the C++ core (``coopctrl._core.spatial_ik``, ``refine_posture``, ``planar_ik``,
coopctrl/core/preflight_ik.h: the port, bit for bit, of this module's numba kernels, which stay as the
tests' reference), on the plants' own tip kernels
(:func:`plants.arms._spatial_kernels.spatial_arm_tip`, :func:`plants.arms._chain_kernels.chain_arm_tip`,
:func:`plants.arms._planar_kernels.planar_arm_terms`): the same iteration as the arms' Python
:meth:`inverse_kinematics` (:func:`plants.arms._dls_ik.damped_least_squares`, one seed, no restart),

.. math::

    \\Delta q = J_e^T (J_e J_e^T + \\lambda I)^{-1} e, \\qquad q \\leftarrow \\mathrm{clip}(q + \\Delta q,
    q_{lower}, q_{upper})

kept when ``|e|^2`` falls (then ``lambda <- max(0.3 lambda, 1e-12)``, else ``lambda <- 5 lambda``, given
up above ``1e6``), from ``lambda = 1e-2``, at most :data:`MAX_ITERATIONS` iterations, until the position
residual ``|e_p|`` [m] and the rotation residual ``|e_r|`` [rad] are both at most
:data:`~plants.arms.spatial_ik.IK_TOLERANCE`. Spatial: ``e_p = p_target - p(q)``,
``e_r`` the rotation vector of ``R_target R(q)^T`` (through its unit quaternion, no Euler-angle
difference); ``J_e`` the geometric Jacobian. Planar: ``e = Y_target - Y(q)`` with its angle wrapped to
``(-pi, pi]``; ``J_e`` the analytic Jacobian.

A redundant spatial arm (more than 6 joints) is then moved along its self-motion manifold toward its
rest posture, as its Python solve does (:func:`refine_posture`). A solve that does not converge returns
``False``: the caller falls back to the arm's own :meth:`inverse_kinematics` with its random restarts,
which also measures the residual it reports.

At velocity level, :func:`square_joint_rates_into` gives the joint rates that follow the nodes' nominal
rates, ``J_i dq_i = dY_i``, where every arm's Jacobian is square and regular (pre-flight calls its C++ port,
``coopctrl._core.square_joint_rates_into``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.arms._chain_kernels import chain_arm_tip
from plants.arms._planar_kernels import planar_arm_terms
from plants.arms._spatial_kernels import spatial_arm_tip
from plants.arms.spatial_ik import IK_TOLERANCE, POSTURE_ITERATIONS, POSTURE_STEP
from plants.frames import rotation_vector_into, rotation_zyx_into

#: Iteration budget of one solve (as :func:`plants.arms._dls_ik.damped_least_squares`).
MAX_ITERATIONS = 200
#: ``kind`` of a spatial arm: standard DH table (``SerialArm.dh_array``) or general chain
#: (``ChainArm.kernel_table``).
KIND_DH, KIND_CHAIN = 0, 1


@njit(cache=True)
def _dls_trial(Je, e, lam, q, lower, upper, A, y, q_new):
    """``q_new = clip(q + Je^T (Je Je^T + lam I)^-1 e, lower, upper)`` (Cholesky of the SPD ``A``)."""
    m, n = Je.shape
    for i in range(m):
        for j in range(i + 1):
            s = 0.0
            for k in range(n):
                s += Je[i, k] * Je[j, k]
            if i == j:
                s += lam
            A[i, j] = s
    for j in range(m):  # A = L L^T in the lower triangle
        d = A[j, j]
        for k in range(j):
            d -= A[j, k] * A[j, k]
        d = math.sqrt(d)
        A[j, j] = d
        for i in range(j + 1, m):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    for i in range(m):
        s = e[i]
        for k in range(i):
            s -= A[i, k] * y[k]
        y[i] = s / A[i, i]
    for i in range(m - 1, -1, -1):
        s = y[i]
        for k in range(i + 1, m):
            s -= A[k, i] * y[k]
        y[i] = s / A[i, i]
    for k in range(n):
        s = q[k]
        for i in range(m):
            s += Je[i, k] * y[i]
        q_new[k] = min(max(s, lower[k]), upper[k])


@njit(cache=True)
def _spatial_error(kind, table, base, tool, p_target, R_target, q, T, Jg, M, e):
    """Pose error ``e`` (6,) and geometric Jacobian ``Jg`` at ``q`` (module docstring)."""
    if kind == KIND_DH:
        spatial_arm_tip(q, table, base, tool, T, Jg)
    else:
        chain_arm_tip(q, table, base, tool, T, Jg)
    for i in range(3):
        e[i] = p_target[i] - T[i, 3]
        for j in range(3):
            M[i, j] = R_target[i, 0] * T[j, 0] + R_target[i, 1] * T[j, 1] + R_target[i, 2] * T[j, 2]
    rotation_vector_into(M, e[3:])
    return e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3] + e[4] * e[4] + e[5] * e[5]


@njit(cache=True)
def _spatial_converged(e, tol):
    return (math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) <= tol
            and math.sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]) <= tol)


@njit(cache=True)
def _spatial_dls(kind, table, base, tool, lower, upper, p_target, R_target, q):
    """The damped least-squares iteration (module docstring) from ``q``, which gets the answer; returns
    whether it converged."""
    n = q.shape[0]
    T = np.empty((4, 4))
    M = np.empty((3, 3))
    Je = np.empty((6, n))
    Je_new = np.empty((6, n))
    e = np.empty(6)
    e_new = np.empty(6)
    A = np.empty((6, 6))
    y = np.empty(6)
    q_new = np.empty(n)
    for k in range(n):
        q[k] = min(max(q[k], lower[k]), upper[k])
    cost = _spatial_error(kind, table, base, tool, p_target, R_target, q, T, Je, M, e)
    lam = 1e-2
    for _ in range(MAX_ITERATIONS):
        if _spatial_converged(e, IK_TOLERANCE):
            break
        _dls_trial(Je, e, lam, q, lower, upper, A, y, q_new)
        cost_new = _spatial_error(kind, table, base, tool, p_target, R_target, q_new, T, Je_new, M, e_new)
        if cost_new < cost:
            q[:] = q_new
            e[:] = e_new
            Je[:, :] = Je_new
            cost = cost_new
            lam = max(lam * 0.3, 1e-12)
        else:
            lam *= 5.0
            if lam > 1e6:
                break
    return _spatial_converged(e, IK_TOLERANCE)


@njit(cache=True)
def _null_space_residual(kind, table, base, tool, posture, q, d):
    """``d = (I - J_g^+ J_g)(posture - q)`` at ``q``; returns ``|d|``."""
    n = q.shape[0]
    T = np.empty((4, 4))
    Jg = np.empty((6, n))
    if kind == KIND_DH:
        spatial_arm_tip(q, table, base, tool, T, Jg)
    else:
        chain_arm_tip(q, table, base, tool, T, Jg)
    P = np.eye(n) - np.linalg.pinv(Jg) @ Jg
    d[:] = P @ (posture - q)
    return math.sqrt(np.sum(d * d))


@njit(cache=True)
def spatial_ik(kind, table, base, tool, lower, upper, target, q):
    """Damped least squares from ``q`` (n,) [rad or m] toward the node pose ``target`` (6,): position [m],
    ZYX Euler angles [rad]; ``q`` gets the answer. ``kind``: :data:`KIND_DH` (``table`` a DH table) or
    :data:`KIND_CHAIN` (a chain table); ``base``, ``tool`` 4x4; ``lower``, ``upper`` the joint limits.
    Returns whether it converged (both residuals at most ``IK_TOLERANCE``)."""
    R_target = np.empty((3, 3))
    rotation_zyx_into(target[3:], R_target)
    return _spatial_dls(kind, table, base, tool, lower, upper, target[:3], R_target, q)


@njit(cache=True)
def refine_posture(kind, table, base, tool, lower, upper, posture, target, q):
    """Move the answer ``q`` of a redundant arm's :func:`spatial_ik` (same arguments) along its self-motion
    manifold toward ``posture`` (n,), as :meth:`SpatialInverseKinematics._posture_refine
    <plants.arms.spatial_ik.SpatialInverseKinematics>` does: ``q <- q + s (I - J_g^+ J_g)(posture - q)``
    from ``s = POSTURE_STEP``, each trial pulled back onto the target by the damped least squares and kept
    if it converged and reduced the null-space residual (then ``s <- min(1, 2 s)``, else ``s <- s / 2``,
    given up below 1e-3), at most ``POSTURE_ITERATIONS`` trials, until that residual is at most 1e-10.
    (A function of its own: the pseudo-inverse is compiled only for a redundant arm.)"""
    n = q.shape[0]
    R_target = np.empty((3, 3))
    rotation_zyx_into(target[3:], R_target)
    p_target = target[:3]
    d = np.empty(n)
    d_new = np.empty(n)
    trial = np.empty(n)
    r = _null_space_residual(kind, table, base, tool, posture, q, d)
    step = POSTURE_STEP
    for _ in range(POSTURE_ITERATIONS):
        if r <= 1e-10:
            break
        for k in range(n):
            trial[k] = min(max(q[k] + step * d[k], lower[k]), upper[k])
        if _spatial_dls(kind, table, base, tool, lower, upper, p_target, R_target, trial):
            r_new = _null_space_residual(kind, table, base, tool, posture, trial, d_new)
            if r_new < r:
                q[:] = trial
                d[:] = d_new
                r = r_new
                step = min(1.0, 2.0 * step)
                continue
        step *= 0.5
        if step < 1e-3:
            break


@njit(cache=True)
def _planar_error(links, base, tool, gravity, target, q, dq, H, h, Y, Jdq, Je, e):
    planar_arm_terms(q, dq, links, base, tool, gravity, H, h, Y, Je, Jdq)
    e[0] = target[0] - Y[0]
    e[1] = target[1] - Y[1]
    e[2] = (target[2] - Y[2] + math.pi) % (2.0 * math.pi) - math.pi
    return e[0] * e[0] + e[1] * e[1] + e[2] * e[2]


@njit(cache=True)
def _planar_converged(e, tol):
    return math.sqrt(e[0] * e[0] + e[1] * e[1]) <= tol and abs(e[2]) <= tol


@njit(cache=True)
def planar_ik(links, base, tool, gravity, lower, upper, target, q):
    """:func:`spatial_ik` of a planar arm (``links`` its link table, ``base``, ``tool`` ``(x, z, theta)``,
    ``gravity`` ``(g_x, g_z)``) toward ``target = (x, z, theta)`` [m, m, rad]; ``q`` gets the answer.
    Returns whether it converged."""
    n = q.shape[0]
    dq = np.zeros(n)
    H = np.empty((n, n))
    h = np.empty(n)
    Y = np.empty(3)
    Jdq = np.empty(3)
    Je = np.empty((3, n))
    Je_new = np.empty((3, n))
    e = np.empty(3)
    e_new = np.empty(3)
    A = np.empty((3, 3))
    y = np.empty(3)
    q_new = np.empty(n)
    for k in range(n):
        q[k] = min(max(q[k], lower[k]), upper[k])
    cost = _planar_error(links, base, tool, gravity, target, q, dq, H, h, Y, Jdq, Je, e)
    lam = 1e-2
    for _ in range(MAX_ITERATIONS):
        if _planar_converged(e, IK_TOLERANCE):
            break
        _dls_trial(Je, e, lam, q, lower, upper, A, y, q_new)
        cost_new = _planar_error(links, base, tool, gravity, target, q_new, dq, H, h, Y, Jdq, Je_new, e_new)
        if cost_new < cost:
            q[:] = q_new
            e[:] = e_new
            Je[:, :] = Je_new
            cost = cost_new
            lam = max(lam * 0.3, 1e-12)
        else:
            lam *= 5.0
            if lam > 1e6:
                break
    return _planar_converged(e, IK_TOLERANCE)


def warm_ik(arm):
    """``solve(target, q0) -> q or None`` for ``arm``: :func:`spatial_ik` or :func:`planar_ik` from the seed
    ``q0`` (not changed) toward the node pose ``target`` [m, rad], ``None`` where it does not converge; or
    ``None`` for an arm not solved here (a contact point, an arm of another class). Runs the C++ core's
    ports of those kernels (module docstring)."""
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


@njit(cache=True)
def square_joint_rates_into(J, dY, dofs, out):
    """Each arm's joint rates ``out[i, :n_i]`` solving ``J[i, :, :n_i] dq_i = dY[i + 1]`` (LU with partial
    pivoting) where every arm's Jacobian is square (``n_i`` = the pose size) and regular; returns ``False``
    (``out`` then undefined) if one is not: the caller solves that case in the least-squares sense."""
    m, p = dofs.shape[0], J.shape[1]
    A = np.empty((p, p))
    b = np.empty(p)
    for i in range(m):
        if dofs[i] != p:
            return False
        for r in range(p):
            b[r] = dY[i + 1, r]
            for c in range(p):
                A[r, c] = J[i, r, c]
        for c in range(p):
            piv = c
            for r in range(c + 1, p):
                if abs(A[r, c]) > abs(A[piv, c]):
                    piv = r
            if A[piv, c] == 0.0:
                return False
            if piv != c:
                for k in range(p):
                    A[c, k], A[piv, k] = A[piv, k], A[c, k]
                b[c], b[piv] = b[piv], b[c]
            for r in range(c + 1, p):
                f = A[r, c] / A[c, c]
                for k in range(c, p):
                    A[r, k] -= f * A[c, k]
                b[r] -= f * b[c]
        for r in range(p - 1, -1, -1):
            s = b[r]
            for k in range(r + 1, p):
                s -= A[r, k] * out[i, k]
            out[i, r] = s / A[r, r]
    return True
