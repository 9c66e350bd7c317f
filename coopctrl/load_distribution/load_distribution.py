"""Load distribution: the contact wrenches that carry the nominal object load (MODEL.md section 6)."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import InfeasibleLoad, ScenarioError
from .config import LoadDistributionConfig
from .grasp_matrix import wrench_dim
from .load_split import LoadSplit
from .problem import LoadDistributionProblem
from .solvers import QPStats, make_solver


class LoadDistribution:
    """Splits the external load ``w_N`` among ``m`` arms, once per control step.

    Each call of :meth:`solve` assembles and solves (with the configured backend; the default
    keeps one proxsuite QP alive and warm starts it)

    .. math::

        \\min_F \\tfrac12 (F - F_{pref})^T P (F - F_{pref}) \\quad\\text{s.t.}\\quad G F = w_N,
        \\quad l \\le C F \\le u, \\qquad F_{pref} = A w_N + E s_{des},

    see :class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`. With no active
    inequality the answer is ``F_pref``: the weighted pseudo-inverse (or elastic) split plus the
    desired virtual-linkage squeeze.

    **Failure policy.** A garbage answer is never returned. A solve fails when the status is not
    ``"solved"`` or when the answer violates ``G F = w_N`` or an inequality by more than
    ``tol = 100 eps_abs (1 + max(|G F|, |C F|))``. Then:

    - if no solve has succeeded yet, :class:`~coopctrl.errors.InfeasibleLoad` is raised at once
      (there is nothing to hold);
    - otherwise the last feasible split is returned with ``held=True``, this step's status,
      iterations and time, and the violated families in ``binding``;
    - the ``max_consecutive_failures``-th failure in a row raises ``InfeasibleLoad``.

    A proxsuite run that stops at its iteration limit with the constraints still violated is
    reported as ``"infeasible"`` (on this convex QP that is what it means in practice; proxsuite
    rarely certifies infeasibility itself). ``binding`` names, on success, the families with a
    non-zero multiplier; on failure, the violated families (``"balance"`` for ``G F = w_N``), the
    most violated first.

    Args:
        config: The settings.
        space: ``"spatial"`` (wrenches in R^6) or ``"planar"`` (``(f_x, f_z, n)``).
        m: Number of arms.
    """

    def __init__(self, config: LoadDistributionConfig, space: str, m: int):
        if not isinstance(config, LoadDistributionConfig):
            raise ScenarioError("config", type(config).__name__, "a LoadDistributionConfig")
        wrench_dim(space)
        self.config = config
        self.space = space
        self.m = m
        self.problem = LoadDistributionProblem(config, space, m)
        self.solver = make_solver(config.solver, config.eps_abs, config.max_iter)
        self._last: LoadSplit | None = None
        self._failures = 0
        self._tol_factor = 100.0 * config.eps_abs
        self._stats: list[QPStats] = []
        self._held: list[bool] = []

    @property
    def last_split(self) -> LoadSplit | None:
        """The last split returned (held or not), or ``None``."""
        return self._last

    @property
    def statistics(self) -> dict[str, list]:
        """Every solve of the run: ``status``, ``iterations``, ``solve_time_s`` [s], ``objective``
        and ``held`` lists, one entry per call of :meth:`solve`."""
        s = self._stats
        return {
            "status": [x.status for x in s],
            "iterations": [x.iterations for x in s],
            "solve_time_s": [x.solve_time_s for x in s],
            "objective": [x.objective for x in s],
            "held": list(self._held),
        }

    def solve(self, r_contacts, r_object, w_N, normals=None, jacobians=None, biases=None, tau_max=None, K=None) -> LoadSplit:
        """Contact wrenches for one step.

        Args:
            r_contacts: Contact points ``r_i``, shape (m, 3) or planar (m, 2) as (x, z) [m].
            r_object: Object mass centre ``r_0``, shape (3,) or (2,) [m].
            w_N: Required object wrench (external load) at ``r_0``, shape (6,) or (3,) [N, N m].
            normals: Inward contact normals ``n_i``, shape (m, 3) or (m, 2) (normalised here);
                required by ``min_grip`` and ``friction_coefficient``.
            jacobians: Per arm ``J_i``, shape (6, n_i) or (3, n_i), with ``tau_i = J_i^T F_i + bias_i``;
                required by ``torque_limits``.
            biases: Per arm ``bias_i``, shape (n_i,) [N m], or ``None`` (zero).
            tau_max: Torque limits [N m]: one number, or per arm a number or an (n_i,) array.
            K: Block-diagonal grasp stiffness (6m × 6m or 3m × 3m), required by ``split="elastic"``.

        Returns:
            The :class:`LoadSplit`.

        Raises:
            InfeasibleLoad: The first solve fails, or ``max_consecutive_failures`` fail in a row.
            ScenarioError: An input has the wrong shape or is missing.
        """
        pb = self.problem
        pb.update(r_contacts, r_object, w_N, normals, jacobians, biases, tau_max, K)
        res = self.solver.solve(pb)
        status = res.status
        x = res.x
        binding: tuple[str, ...] = ()
        ok = status == "solved"
        if x is None or not np.all(np.isfinite(x)):
            ok, x = False, None
        if x is not None:
            viol, scale = pb.max_violation(x)
            tol = self._tol_factor * (1.0 + scale)
            if viol > tol:
                viol = pb.violations(x)
                bad = sorted((v, k) for k, v in viol.items() if v > tol)
                if status in ("solved", "max_iter"):
                    status = "infeasible"
                ok = False
                binding = tuple(k for _, k in reversed(bad))
        objective = pb.objective(x) if x is not None else float("nan")
        self._stats.append(QPStats(status, res.iterations, res.solve_time_s, objective))
        if not ok:
            self.solver.reset()
            cause = self._infeasibility_cause()
            if cause:
                binding = cause
            self._failures += 1
            self._held.append(True)
            if self._last is None:
                raise InfeasibleLoad(status, binding, "first solve failed, no previous split to hold")
            if self._failures >= self.config.max_consecutive_failures:
                raise InfeasibleLoad(status, binding, f"{self._failures} consecutive failed solves")
            held = dataclasses.replace(
                self._last, status=status, iterations=res.iterations, solve_time_s=res.solve_time_s,
                binding=binding, held=True,
            )
            return held
        self._failures = 0
        if res.z is not None:
            binding = self._active_families(res.z)
        shape = (self.m, pb.k)
        external = pb.external.reshape(shape).copy()
        F = x.reshape(shape)
        split = LoadSplit(
            F, external, F - external, np.array(r_contacts, dtype=float), self.space,
            status, res.iterations, res.solve_time_s, binding, False,
        )
        self._held.append(False)
        self._last = split
        return split

    def _infeasibility_cause(self) -> tuple[str, ...]:
        """The inequality families without which the failed problem becomes feasible.

        Each enabled family is dropped in turn and the problem re-solved exactly (daqp); the
        families whose removal restores feasibility are the binding ones. Runs only after a
        failure, so it costs nothing on normal steps.
        """
        import qpsolvers as qps

        pb = self.problem
        families = [name for name, sl in pb.rows.items() if sl.stop > sl.start]
        if not families or "daqp" not in qps.available_solvers:
            return ()
        cause = []
        for drop in families:
            keep = np.ones(pb.n_in, dtype=bool)
            keep[pb.rows[drop]] = False
            C, l, u = pb.C[keep], pb.l[keep], pb.u[keep]
            up, lo = np.isfinite(u), np.isfinite(l)
            Gin = np.vstack((C[up], -C[lo])) if keep.any() else None
            hin = np.concatenate((u[up], -l[lo])) if keep.any() else None
            try:
                sol = qps.solve_problem(qps.Problem(pb.P, pb.g, Gin, hin, pb.G, pb.w), solver="daqp")
                if sol.found and sol.x is not None and np.all(np.isfinite(sol.x)):
                    cause.append(drop)
            except (qps.QPError, ValueError, ArithmeticError):
                pass
        return tuple(cause)

    def _active_families(self, z: np.ndarray) -> tuple[str, ...]:
        pb = self.problem
        thr = 1e-7 * (1.0 + float(np.abs(pb.g).max()))
        za = np.abs(z)
        return tuple(name for name, sl in pb.rows.items() if sl.stop > sl.start and za[sl].max() > thr)
