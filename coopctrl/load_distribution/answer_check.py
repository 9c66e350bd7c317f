"""The check of a QP answer and its binding families, compiled: the one definition the compiled tick and
:class:`~coopctrl.load_distribution.LoadDistribution` run (docs/model.md section 6).

On the stacked problem of :class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`,
``M = [G; C]`` (``k`` balance rows, then the inequality rows), ``lo = [w_N; l]``, ``hi = [w_N; u]``, an
answer ``F`` (n,) [N, N m] is accepted when it is finite and

.. math::

    v = \\max_r \\max(lo_r - (M F)_r,\\; (M F)_r - hi_r) \\le tol, \\qquad
    tol = \\min\\big(100\\, eps_{abs} (1 + s),\\; \\rho L\\big), \\quad s = \\max_r |(M F)_r|,

    L = \\max(1, |w_N|_\\infty, |l|_\\infty, |u|_\\infty) \\text{ (finite bounds only)}:

the solver's own tolerance, never more than the fraction ``rho`` (``ANSWER_TOLERANCE_OF_LOAD``) of the
load [N, N m]. The cap is evaluated only when ``v`` exceeds ``min(100 eps_abs (1 + s), rho)`` (``L >= 1``, so
below that it cannot bind).

The binding families of an accepted answer are those with a multiplier ``|z_r| > 1e-7 (1 + |g|_inf)``
(``g`` the QP's linear term), as a mask of :data:`FAMILY_MIN_GRIP`, :data:`FAMILY_FRICTION`,
:data:`FAMILY_TORQUE` (the record's ``qp_binding``).

Each function reads the arrays it is given and allocates nothing (the compiled tick calls them per tick).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Bits of the binding-families mask, in the row order of the problem.
FAMILY_MIN_GRIP = 1
FAMILY_FRICTION = 2
FAMILY_TORQUE = 4
#: The family of each bit, by the names of ``LoadDistributionProblem.rows``.
FAMILY_NAMES = ((FAMILY_MIN_GRIP, "min_grip"), (FAMILY_FRICTION, "friction"), (FAMILY_TORQUE, "torque_limits"))


@njit(cache=True)
def answer_violation(M, lo, hi, x, n):
    """``(v, s)``: the largest violation ``v`` of ``lo <= M x <= hi`` (balance rows included) and the
    scale ``s = max |M x|`` [N, N m] of the answer ``x[:n]`` (module docstring)."""
    viol = -np.inf
    scale = 0.0
    for r in range(M.shape[0]):
        s = 0.0
        for c in range(n):
            s += M[r, c] * x[c]
        v = max(lo[r] - s, s - hi[r])
        if v > viol:
            viol = v
        if abs(s) > scale:
            scale = abs(s)
    return viol, scale


@njit(cache=True)
def answer_tolerance(lo, hi, k, viol, scale, eps_abs, rho):
    """``tol`` [N, N m] for an answer of violation ``viol`` and scale ``scale`` (module docstring):
    ``100 eps_abs (1 + scale)``, capped by ``rho L`` when ``viol`` exceeds ``min(that, rho)``; ``lo``, ``hi``
    the stacked bounds, ``k`` the balance rows. ``viol = inf`` gives the capped tolerance."""
    tol = 100.0 * eps_abs * (1.0 + scale)
    if not viol <= min(tol, rho):
        load = 1.0
        for r in range(lo.shape[0]):
            if r < k or math.isfinite(lo[r]):
                load = max(load, abs(lo[r]))
            if r >= k and math.isfinite(hi[r]):
                load = max(load, abs(hi[r]))
        tol = min(tol, rho * load)
    return tol


@njit(cache=True)
def answer_ok(M, lo, hi, x, n, k, eps_abs, rho):
    """Whether the answer ``x[:n]`` is finite and within :func:`answer_tolerance` of ``lo <= M x <= hi``."""
    for c in range(n):
        if not math.isfinite(x[c]):
            return False
    viol, scale = answer_violation(M, lo, hi, x, n)
    return viol <= answer_tolerance(lo, hi, k, viol, scale, eps_abs, rho)


@njit(cache=True)
def binding_families(g, z, z0, n, n_in, m, row_grip, row_fric, n_fric, row_tau):
    """The mask of the families with a non-zero multiplier: ``|z[z0 + r]| > 1e-7 (1 + max |g[:n]|)`` for an
    inequality row ``r < n_in``. Rows ``row_grip .. + m`` are ``min_grip``, ``row_fric .. + m n_fric``
    ``friction``, ``row_tau ..`` ``torque_limits`` (-1: the family is off); ``z0`` the first inequality
    multiplier in ``z`` (the compiled solver's ``z`` starts with the ``k`` balance rows, a backend's with
    the inequalities)."""
    qb = 0
    if n_in > 0:
        gmax = 0.0
        for c in range(n):
            if abs(g[c]) > gmax:
                gmax = abs(g[c])
        thr = 1e-7 * (1.0 + gmax)
        for r in range(n_in):
            if abs(z[z0 + r]) > thr:
                if row_grip >= 0 and row_grip <= r < row_grip + m:
                    qb |= FAMILY_MIN_GRIP
                elif row_fric >= 0 and row_fric <= r < row_fric + m * n_fric:
                    qb |= FAMILY_FRICTION
                elif row_tau >= 0 and r >= row_tau:
                    qb |= FAMILY_TORQUE
    return qb
