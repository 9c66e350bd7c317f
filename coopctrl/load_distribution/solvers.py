"""QP backends of the load distribution: one persistent proxsuite QP, or any qpsolvers backend.

Both solve

.. math::

    \\min_F \\tfrac12 F^T P F + g^T F \\quad \\text{s.t.} \\quad G F = w_N, \\quad l \\le C F \\le u

as assembled by :class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..errors import ScenarioError
from .config import solver_allowed_message

#: Status strings a backend reports.
STATUSES = ("solved", "infeasible", "max_iter", "failed")


@dataclass(frozen=True)
class QPStats:
    """Record of one solve.

    Attributes:
        status: ``"solved"``, ``"infeasible"``, ``"max_iter"`` or ``"failed"``.
        iterations: Solver iterations (-1 when the backend does not report them).
        solve_time_s: Wall-clock time around the solver call (update and solve) [s].
        objective: ``1/2 (F - F_pref)^T P (F - F_pref)`` at the answer (NaN if none).
    """

    status: str
    iterations: int
    solve_time_s: float
    objective: float

    def __post_init__(self):
        if self.status not in STATUSES:
            raise ValueError(f"QPStats.status = {self.status!r}: expected one of {STATUSES}")


@dataclass(frozen=True)
class BackendResult:
    """Raw answer of a backend: primal ``x`` (or ``None``), inequality multipliers ``z`` per row
    of ``C`` (positive at an active upper bound, negative at an active lower bound, or ``None``),
    the status, the iteration count and the wall-clock time [s]."""

    x: np.ndarray | None
    z: np.ndarray | None
    status: str
    iterations: int
    solve_time_s: float


class ProxsuiteSolver:
    """One persistent ``proxsuite.proxqp.dense.QP``, created and ``init``-ed on the first call,
    then updated in place and warm started from the previous result
    (``InitialGuess.WARM_START_WITH_PREVIOUS_RESULT``). It is created again when the dimensions
    change, and initialised again (cold) after a failed solve, whose iterate is no good start.

    Args:
        eps_abs: Absolute tolerance [N, N m].
        max_iter: Iteration limit.
    """

    name = "proxsuite"

    def __init__(self, eps_abs: float = 1e-9, max_iter: int = 1000):
        import proxsuite

        self._proxqp = proxsuite.proxqp
        self.eps_abs = eps_abs
        self.max_iter = max_iter
        self.qp = None
        self._dims = None
        self._needs_init = True
        out = proxsuite.proxqp.QPSolverOutput
        self._status = {
            out.PROXQP_SOLVED: "solved",
            out.PROXQP_MAX_ITER_REACHED: "max_iter",
            out.PROXQP_PRIMAL_INFEASIBLE: "infeasible",
            out.PROXQP_SOLVED_CLOSEST_PRIMAL_FEASIBLE: "infeasible",
            out.PROXQP_DUAL_INFEASIBLE: "failed",
            out.PROXQP_NOT_RUN: "failed",
        }

    def reset(self) -> None:
        """Start the next solve cold, from a fresh QP object (after a failed or rejected solve)."""
        self._needs_init = True

    def _create(self, dims) -> None:
        n, n_eq, n_in = dims
        qp = self._proxqp.dense.QP(n, n_eq, n_in)
        s = qp.settings
        s.eps_abs = self.eps_abs
        s.eps_rel = 0.0
        s.max_iter = self.max_iter
        s.verbose = False
        s.initial_guess = self._proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
        self.qp = qp
        self._dims = dims

    def _solve_once(self, problem, C, l, u, cold: bool):
        if cold:
            self._create(problem.dims)
            self.qp.init(problem.P, problem.g, problem.G, problem.w, C, l, u)
        else:
            self.qp.update(
                H=problem.P if problem.P_changed else None,
                g=problem.g, A=problem.G, b=problem.w, C=C, l=l, u=u,
            )
        self.qp.solve()
        info = self.qp.results.info
        return self._status.get(info.status, "failed"), int(info.iter)

    def solve(self, problem) -> BackendResult:
        """Update and solve; a warm-started solve that fails is retried once from a cold start
        (a fresh QP object), because a far-away warm start can end in a false infeasibility."""
        dims = problem.dims
        has_in = dims[2] > 0
        C = problem.C if has_in else None
        l = problem.l if has_in else None
        u = problem.u if has_in else None
        t0 = time.perf_counter()
        cold = self._needs_init or dims != self._dims
        status, iters = self._solve_once(problem, C, l, u, cold)
        if status != "solved" and not cold:
            status, it2 = self._solve_once(problem, C, l, u, True)
            iters += it2
        problem.P_changed = False
        elapsed = time.perf_counter() - t0
        self._needs_init = status != "solved"
        res = self.qp.results
        return BackendResult(res.x.copy(), res.z.copy() if has_in else None, status, iters, elapsed)


class QpsolversSolver:
    """Any backend of ``qpsolvers`` by name, through ``qpsolvers.solve_problem`` (the problem is
    rebuilt each call). ``l <= C F <= u`` is passed as ``[C; -C] F <= [u; -l]`` keeping the finite
    rows. A backend that finds no solution reports ``"infeasible"`` if it is an exact active-set
    solver (daqp, quadprog, which fail only that way on a convex QP), else ``"failed"``.

    Raises:
        ScenarioError: ``name`` is not an installed qpsolvers backend (the message lists the
            installed ones and the pip command).
    """

    EXACT = ("daqp", "quadprog", "qpoases", "piqp", "hpipm", "clarabel")

    def __init__(self, name: str, eps_abs: float = 1e-9):
        import qpsolvers

        if name not in qpsolvers.available_solvers:
            raise ScenarioError("solver", name, solver_allowed_message())
        self._qpsolvers = qpsolvers
        self.name = name
        self.eps_abs = eps_abs
        self._kwargs = {"eps_abs": eps_abs, "eps_rel": 0.0} if name == "proxqp" else {}
        self._masks = None

    def reset(self) -> None:
        """Nothing is kept between calls."""

    def solve(self, problem) -> BackendResult:
        qps = self._qpsolvers
        t0 = time.perf_counter()
        if problem.n_in:
            up = np.isfinite(problem.u)
            lo = np.isfinite(problem.l)
            Gin = np.vstack((problem.C[up], -problem.C[lo]))
            hin = np.concatenate((problem.u[up], -problem.l[lo]))
        else:
            Gin = hin = None
        prob = qps.Problem(problem.P, problem.g, Gin, hin, problem.G, problem.w)
        try:
            sol = qps.solve_problem(prob, solver=self.name, **self._kwargs)
            found = bool(sol.found) and sol.x is not None and bool(np.all(np.isfinite(sol.x)))
        except (qps.QPError, ValueError, ArithmeticError):
            sol, found = None, False
        elapsed = time.perf_counter() - t0
        problem.P_changed = False
        if not found:
            status = "infeasible" if self.name in self.EXACT else "failed"
            x = None if sol is None or sol.x is None else np.asarray(sol.x, dtype=float)
            return BackendResult(x, None, status, -1, elapsed)
        z = None
        if problem.n_in and sol.z is not None:
            nu = int(np.count_nonzero(up))
            z = np.zeros(problem.n_in)
            z[up] += sol.z[:nu]
            z[lo] -= sol.z[nu:]
        iters = -1
        info = sol.extras.get("info") if isinstance(sol.extras, dict) else None
        if info is not None and hasattr(info, "iter"):
            iters = int(info.iter)
        return BackendResult(np.asarray(sol.x, dtype=float), z, "solved", iters, elapsed)


def make_solver(name: str, eps_abs: float = 1e-9, max_iter: int = 1000):
    """The backend called ``name``: ``"proxsuite"``, ``"compiled"`` or a qpsolvers backend name."""
    if name == "compiled":
        from .compiled_solver import CompiledSolver

        return CompiledSolver(eps_abs, max_iter)
    if name == "proxsuite":
        return ProxsuiteSolver(eps_abs, max_iter)
    return QpsolversSolver(name, eps_abs)
