"""Damped least-squares inverse kinematics shared by the spatial and planar arms."""

from __future__ import annotations

import numpy as np


def damped_least_squares(error_and_jacobian, q0, lower, upper, tol, max_iter=200):
    """Levenberg-Marquardt iteration from ``q0``, clipping to ``[lower, upper]``.

    Args:
        error_and_jacobian: ``q -> (e, Je)`` with ``e`` the pose error (target - current, in a
            vector space: position [m] and rotation vector [rad]) and ``Je = de/d(-q)``, i.e.
            the Jacobian of the current pose in the same coordinates.
        q0: Seed [rad].
        lower, upper: Joint limits [rad].
        tol: Callable ``e -> bool``: converged.
        max_iter: Iteration budget.

    Returns:
        ``(q, e)``: the best joint vector and its error.
    """
    q = np.clip(np.asarray(q0, dtype=float), lower, upper)
    e, Je = error_and_jacobian(q)
    cost = float(e @ e)
    lam = 1e-2
    m = e.shape[0]
    for _ in range(max_iter):
        if tol(e):
            break
        A = Je @ Je.T + lam * np.eye(m)
        step = Je.T @ np.linalg.solve(A, e)
        q_new = np.clip(q + step, lower, upper)
        e_new, Je_new = error_and_jacobian(q_new)
        cost_new = float(e_new @ e_new)
        if cost_new < cost:
            q, e, Je, cost = q_new, e_new, Je_new, cost_new
            lam = max(lam * 0.3, 1e-12)
        else:
            lam *= 5.0
            if lam > 1e6:
                break
    return q, e
