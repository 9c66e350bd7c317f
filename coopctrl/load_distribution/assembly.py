"""The load-distribution QP's rows, filled in place by numba functions: the one definition of each family.

:meth:`LoadDistributionProblem.update <coopctrl.load_distribution.problem.LoadDistributionProblem.update>`
(the public ``LoadDistribution.solve``, the pre-flight and the loaded start), the public helpers
:func:`~coopctrl.load_distribution.grasp_matrix.grasp_matrix` and
:func:`~coopctrl.load_distribution.grasp_matrix.internal_force_basis`, and the compiled tick
(:mod:`coopctrl.loop.kernel`) all call these functions; the Python side only checks its inputs. They
work on the stacked arrays ``M = [G; C]`` (rows ``0..k-1`` the wrench balance, then the inequality
families), ``lo = [w_N; l]``, ``hi = [w_N; u]``:

- :func:`fill_grasp_rows`: the moment arms of ``G`` (``S(r_i - r_0)`` spatial, ``(-d_z, d_x)``
  planar, ``d = r_i - r_0``); the identity blocks are set once by the caller;
- :func:`pseudo_inverse_external`: ``A w_N = W^-1 G^T (G W^-1 G^T)^-1 w_N`` (the pseudo-inverse split)
  by a Cholesky solve of the k x k matrix (the elastic split's ``K G^T (G K G^T)^-1 w_N`` is in
  :mod:`.elastic_assembly` for the compiled tick; the Python problem, which takes any ``K``, solves it
  with numpy);
- :func:`fill_squeeze_basis`: the virtual-linkage columns ``e_ij`` (``t_ij = (r_j - r_i) / |r_j - r_i|``);
- :func:`fill_grip_rows`, :func:`fill_friction_rows`, :func:`fill_torque_rows`: the ``min_grip``
  (``n_i^T f_i >= f_min``), ``friction`` (the inscribed pyramid) and ``torque_limits``
  (``-tau_max - bias <= J_i^T F_i <= tau_max - bias``) families, as documented on
  :class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`.

The inputs of the last three from the plant's state, the unit normals ``n_i`` and the torque model
``(J_i, bias_i)``, are defined once too, in :mod:`.contact_model` (the compiled tick, the loaded start and
the pre-flight call it; ``LoadDistributionProblem.update`` takes them as arguments).

Each returns ``False`` (and writes nothing meaningful) where the Python side raises ``ScenarioError``:
a singular ``G W^-1 G^T`` or coincident contacts. Callers pass C-contiguous float64 arrays, int64
integers and a bool ``spatial``, the compiled tick's argument types, so that one compiled (and cached)
specialisation serves both (``tests/test_load_distribution_assembly.py``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.cooperative._linalg import cholesky_solve_n


@njit(cache=True)
def fill_grasp_rows(M, r, r0, spatial):
    """Write the moment-arm entries of ``G = M[:k]`` for contacts ``r`` (m, npos) about ``r0`` [m]."""
    m = r.shape[0]
    if spatial:
        for i in range(m):
            d0 = r[i, 0] - r0[0]
            d1 = r[i, 1] - r0[1]
            d2 = r[i, 2] - r0[2]
            c = 6 * i
            M[3, c + 1] = -d2
            M[3, c + 2] = d1
            M[4, c + 0] = d2
            M[4, c + 2] = -d0
            M[5, c + 0] = -d1
            M[5, c + 1] = d0
    else:
        for i in range(m):
            M[2, 3 * i] = -(r[i, 1] - r0[1])
            M[2, 3 * i + 1] = r[i, 0] - r0[0]


@njit(cache=True)
def pseudo_inverse_external(M, k, W_inv_diag, w, external, A, y):
    """``external = W^-1 G^T (G W^-1 G^T)^-1 w`` with ``G = M[:k]``; ``A`` (k, k) and ``y`` (k) are
    scratch. Returns False if ``G W^-1 G^T`` is not positive definite."""
    n = W_inv_diag.shape[0]
    for a in range(k):
        for b in range(a, k):
            s = 0.0
            for c in range(n):
                s += M[a, c] * W_inv_diag[c] * M[b, c]
            A[a, b] = s
            A[b, a] = s
    if not cholesky_solve_n(A, w, y, k):  # A = L L^T in place (lower triangle), then A y = w
        return False
    for c in range(n):
        s = 0.0
        for a in range(k):
            s += M[a, c] * y[a]
        external[c] = W_inv_diag[c] * s
    return True


@njit(cache=True)
def fill_squeeze_basis(E, r, k):
    """Virtual-linkage columns of ``E`` (n, pairs), pairs ``i < j`` in lexicographic order; the moment
    entries stay as they are (zero). Returns False if two contacts coincide."""
    m = r.shape[0]
    npos = r.shape[1]
    col = 0
    for i in range(m):
        for j in range(i + 1, m):
            s = 0.0
            for a in range(npos):
                t = r[j, a] - r[i, a]
                s += t * t
            length = math.sqrt(s)
            if length < 1e-12:
                return False
            for a in range(npos):
                t = (r[j, a] - r[i, a]) / length
                E[k * i + a, col] = t
                E[k * j + a, col] = -t
            col += 1
    return True


@njit(cache=True)
def fill_grip_rows(M, row0, nrm, k):
    """``min_grip`` rows: row ``row0 + i`` holds the unit normal ``n_i`` on arm i's force entries."""
    m = nrm.shape[0]
    for i in range(m):
        for a in range(nrm.shape[1]):
            M[row0 + i, k * i + a] = nrm[i, a]


@njit(cache=True)
def fill_friction_rows(M, row0, nrm, k, nf, mu_c, cos_phi, sin_phi, spatial):
    """``friction`` rows (``nf`` per contact): ``(cos phi t_1 + sin phi t_2 - mu_c n)^T f <= 0`` spatial,
    ``(+-t - mu_c n)^T f <= 0`` planar (``t = (-n_z, n_x)``), ``mu_c = mu cos(pi / nf)``."""
    m = nrm.shape[0]
    for i in range(m):
        if spatial:
            nx, ny, nz = nrm[i, 0], nrm[i, 1], nrm[i, 2]
            if abs(nx) < 0.9:
                ax, ay, az = 1.0 - nx * nx, -nx * ny, -nx * nz
            else:
                ax, ay, az = -ny * nx, 1.0 - ny * ny, -ny * nz
            s = 1.0 / math.sqrt(ax * ax + ay * ay + az * az)
            t1x, t1y, t1z = ax * s, ay * s, az * s
            t2x = ny * t1z - nz * t1y
            t2y = nz * t1x - nx * t1z
            t2z = nx * t1y - ny * t1x
            for f in range(nf):
                row = row0 + nf * i + f
                c, sn = cos_phi[f], sin_phi[f]
                M[row, k * i] = c * t1x + sn * t2x - mu_c * nx
                M[row, k * i + 1] = c * t1y + sn * t2y - mu_c * ny
                M[row, k * i + 2] = c * t1z + sn * t2z - mu_c * nz
        else:
            nx, nz = nrm[i, 0], nrm[i, 1]
            row = row0 + 2 * i
            M[row, k * i] = -nz - mu_c * nx
            M[row, k * i + 1] = nx - mu_c * nz
            M[row + 1, k * i] = nz - mu_c * nx
            M[row + 1, k * i + 1] = -nx - mu_c * nz


@njit(cache=True)
def fill_torque_rows(M, lo, hi, row0, Jg, dofs, k, tau_qp, bias):
    """``torque_limits`` rows: arm i's ``n_i`` rows hold ``J_i^T`` (``Jg[i]`` is (k, nmax)) on its
    wrench entries, with ``lo = -tau_qp - bias``, ``hi = tau_qp - bias`` (``tau_qp`` and ``bias``
    stacked over the arms' joints) [N m]."""
    row = row0
    j = 0
    for i in range(dofs.shape[0]):
        for r in range(dofs[i]):
            for a in range(k):
                M[row, k * i + a] = Jg[i, a, r]
            hi[row] = tau_qp[j] - bias[j]
            lo[row] = -tau_qp[j] - bias[j]
            row += 1
            j += 1
