"""The compiled QP backend: the Goldfarb-Idnani solver of :mod:`.goldfarb_idnani`, warm started.

It calls the C++ core's solver (``coopctrl._core.gi_solve``, coopctrl/core/goldfarb_idnani.h: the same bits, on
the same workspace, as the compiled tick's).

Selected with ``load_distribution.solver = "compiled"``. It solves the same problem as the
other backends,

.. math::

    \\min_F \\tfrac12 F^T P F + g^T F \\quad \\text{s.t.} \\quad G F = w_N, \\quad l \\le C F \\le u,

reading the stacked arrays ``M = [G; C]``, ``lo = [w_N; l]``, ``hi = [w_N; u]`` of
:class:`~coopctrl.load_distribution.problem.LoadDistributionProblem` in place (no copies), and
keeps one workspace (the factor of ``P`` and the active set) from one call to the next.
"""

from __future__ import annotations

import time

import numpy as np

from coopctrl._core import gi_solve

from .goldfarb_idnani import STATUS_NAMES, gi_cold_start, gi_workspace
from .solvers import BackendResult

#: Status names of the compiled solver mapped to those of :class:`~coopctrl.load_distribution.solvers.QPStats`.
_STATUS = {"solved": "solved", "infeasible": "infeasible", "max_iter": "max_iter", "not_convex": "failed"}


class CompiledSolver:
    """One workspace of the compiled dual active-set QP, warm started from the last active set.

    The workspace is allocated again when the dimensions change; ``P`` is factorised again only
    when ``problem.P_changed`` (the elastic split with a new ``K``) or after a new allocation.

    Args:
        eps_abs: Primal feasibility tolerance: the largest violation of a row, divided by the
            row's Euclidean norm, that counts as satisfied [N].
        max_iter: Iteration limit (constraint additions and drops per solve).
    """

    name = "compiled"

    def __init__(self, eps_abs: float = 1e-9, max_iter: int = 1000):
        self.eps_abs = float(eps_abs)
        self.max_iter = int(max_iter)
        self._dims = None
        self._ws = None
        self._x = self._z = None

    def reset(self) -> None:
        """Start the next solve cold (empty active set), e.g. after a failed or rejected solve."""
        if self._ws is not None:
            gi_cold_start(self._ws)

    def solve(self, problem) -> BackendResult:
        """Solve ``problem`` (a :class:`LoadDistributionProblem` after ``update``)."""
        dims = problem.dims
        t0 = time.perf_counter()
        new_H = bool(problem.P_changed)
        if dims != self._dims:
            n, n_eq, n_in = dims
            self._ws = gi_workspace(n, n_eq + n_in)
            self._x = np.zeros(n)
            self._z = np.zeros(n_eq + n_in)
            self._dims = dims
            new_H = True
        code, iters = gi_solve(
            problem.P, problem.g, problem.M, problem.lo, problem.hi, dims[1],
            self._x, self._z, self._ws, new_H, self.eps_abs, self.max_iter,
        )
        elapsed = time.perf_counter() - t0
        problem.P_changed = False
        status = _STATUS[STATUS_NAMES[code]]
        x = self._x.copy() if code != 3 else None
        z = self._z[dims[1]:].copy() if dims[2] else None
        return BackendResult(x, z, status, int(iters), elapsed)
