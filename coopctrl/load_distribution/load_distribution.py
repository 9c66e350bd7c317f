"""Load distribution: the contact wrenches that carry the nominal object load (docs/model.md section 6)."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import InfeasibleLoad, ScenarioError
from .config import LoadDistributionConfig
from .grasp_matrix import wrench_dim
from .load_split import LoadSplit
from .problem import LoadDistributionProblem
from .solvers import QPStats, make_solver


#: Largest violation of the balance or an inequality an answer may have, as a fraction of the load
#: (see the failure policy of :class:`LoadDistribution`).
ANSWER_TOLERANCE_OF_LOAD = 1e-4


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

    **Failure policy.** A garbage answer is never returned. Whatever the solver says, its answer is
    checked: a solve fails when the status is not ``"solved"`` or when the answer violates
    ``G F = w_N`` or an inequality by more than

    .. math:: tol = \\min\\big(100\\,eps_{abs} (1 + \\max(|G F|, |C F|)),\\; \\rho\\, L\\big),
        \\qquad L = \\max(1, |w_N|_\\infty, |l|_\\infty, |u|_\\infty) \\text{ (finite bounds)},

    with ``rho = ANSWER_TOLERANCE_OF_LOAD``: the solver's own tolerance, but never more than a small
    fraction of the load [N, N m] (a loose ``eps_abs`` cannot pass a split that does not carry the
    load). Then:

    - if no solve has succeeded yet, :class:`~coopctrl.errors.InfeasibleLoad` is raised at once
      (there is nothing to hold);
    - otherwise the last feasible split is returned with ``held=True``, this step's status,
      iterations and time, and the violated families in ``binding``;
    - the ``max_consecutive_failures``-th failure in a row raises ``InfeasibleLoad``.

    The cause of a failure is found by an exact active-set solver (daqp) on the same problem: if it
    has no solution, the status is ``"infeasible"`` and ``binding`` names the enabled inequality
    families without which it has one (never a family that is not enabled); if it has one, the
    failure is the solver's own, and the error says which: its iteration limit (``"max_iter"``), an
    answer off by more than the tolerance, or a numerical failure (``"failed"``), each with its fix.
    On success ``binding`` names the families with a non-zero multiplier.

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
        self.problem.update(r_contacts, r_object, w_N, normals, jacobians, biases, tau_max, K)
        return self.solve_assembled(r_contacts)

    def solve_assembled(self, r_contacts) -> LoadSplit:
        """:meth:`solve` on the problem as it stands: its arrays filled by :meth:`LoadDistributionProblem.update`
        or in place by the compiled tick's assembly (the reference path of :mod:`coopctrl.loop.run`),
        with ``P_changed`` set when ``P`` changed. The backend's solve, the answer check, the failure
        policy and the binding families, as in :meth:`solve`; ``r_contacts`` (m, npos) [m] only goes
        into the returned split."""
        pb = self.problem
        res = self.solver.solve(pb)
        status = res.status
        x = res.x
        binding: tuple[str, ...] = ()
        ok = status == "solved"
        violated: list[tuple[float, str]] = []
        tol = float("nan")
        if x is None or not np.all(np.isfinite(x)):
            ok, x = False, None
        if x is not None:
            from coopctrl._core import answer_tolerance

            x = np.ascontiguousarray(x, dtype=float)
            viol, scale = pb.max_violation(x)
            tol = answer_tolerance(pb.lo, pb.hi, pb.k, viol, scale, self.config.eps_abs, ANSWER_TOLERANCE_OF_LOAD)
            if not viol <= tol:
                violated = sorted(((v, k) for k, v in pb.violations(x).items() if v > tol), reverse=True)
                ok = False
        objective = pb.objective(x) if x is not None else float("nan")
        if not ok:
            self.solver.reset()
            status, binding, detail, advice = self.failure_cause(status, violated, tol)
            self._stats.append(QPStats(status, res.iterations, res.solve_time_s, objective))
            self._failures += 1
            self._held.append(True)
            if self._last is None:
                raise InfeasibleLoad(status, binding, f"{detail}; first solve failed, no previous split to hold",
                                     advice)
            if self._failures >= self.config.max_consecutive_failures:
                raise InfeasibleLoad(status, binding, f"{detail}; {self._failures} consecutive failed solves", advice)
            held = dataclasses.replace(
                self._last, status=status, iterations=res.iterations, solve_time_s=res.solve_time_s,
                binding=binding, held=True,
            )
            return held
        self._stats.append(QPStats(status, res.iterations, res.solve_time_s, objective))
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

    def answer_tolerance(self, scale: float) -> float:
        """Largest violation [N, N m] a solver's answer may have (see the failure policy): the solver's
        ``100 eps_abs (1 + scale)``, ``scale = max(|G F|, |C F|)``, capped by a fraction of the load: the
        C++ core's ``answer_tolerance`` (coopctrl/core/qp_answer_check.h), the loop's own."""
        from coopctrl._core import answer_tolerance

        pb = self.problem
        return answer_tolerance(pb.lo, pb.hi, pb.k, np.inf, float(scale), self.config.eps_abs, ANSWER_TOLERANCE_OF_LOAD)

    def failure_cause(self, status: str, violated: list[tuple[float, str]], tol: float
                       ) -> tuple[str, tuple[str, ...], str, str | None]:
        """``(status, binding, detail, advice)`` of a failed solve, as it really happened.

        ``violated``: ``(violation, family)`` of the solver's answer beyond ``tol``, largest first
        (empty if it gave no answer)."""
        feasible = self._exactly_feasible(())
        if feasible is False:  # no split exists: name the families that make it so
            families = self._enabled_families()
            cause = self._infeasibility_cause()
            binding = cause or tuple(k for _, k in violated if k in families) or families
            return "infeasible", binding, "no split satisfies the balance and the enabled constraints together", None
        cfg = self.config
        if status == "max_iter":
            return status, (), (f"the solver ({cfg.solver}) reached its iteration limit (max_iter = {cfg.max_iter}) "
                                "although a split exists"), "raise load_distribution.max_iter"
        if violated:
            worst, family = violated[0]
            what = "the wrench balance G F = w_N" if family == "balance" else f"the {family} constraints"
            return "failed", (), (f"the solver's answer violates {what} by {worst:.3g} (tolerance {tol:.3g}, "
                                  f"from the load) although a split exists"), (
                f"tighten load_distribution.eps_abs (now {cfg.eps_abs:g}) or choose another load_distribution.solver")
        return "failed", (), (f"numerical failure of the solver ({cfg.solver}, status '{status}') although a split "
                              "exists"), "choose another load_distribution.solver"

    def _enabled_families(self) -> tuple[str, ...]:
        pb = self.problem
        return tuple(name for name, sl in pb.rows.items() if sl.stop > sl.start)

    def _exactly_feasible(self, drop: tuple[str, ...]) -> bool | None:
        """Whether the problem without the families ``drop`` has a solution, by daqp (exact active
        set); ``None`` when daqp is not available."""
        import qpsolvers as qps

        if "daqp" not in qps.available_solvers:
            return None
        pb = self.problem
        keep = np.ones(pb.n_in, dtype=bool)
        for name in drop:
            keep[pb.rows[name]] = False
        Gin = hin = None
        if keep.any():
            C, l, u = pb.C[keep], pb.l[keep], pb.u[keep]
            up, lo = np.isfinite(u), np.isfinite(l)
            Gin, hin = np.vstack((C[up], -C[lo])), np.concatenate((u[up], -l[lo]))
        try:
            sol = qps.solve_problem(qps.Problem(pb.P, pb.g, Gin, hin, pb.G, pb.w), solver="daqp")
        except (qps.QPError, ValueError, ArithmeticError):
            return None
        return bool(sol.found and sol.x is not None and np.all(np.isfinite(sol.x)))

    def _infeasibility_cause(self) -> tuple[str, ...]:
        """The inequality families without which the failed problem becomes feasible.

        Each enabled family is dropped in turn and the problem re-solved exactly (daqp); the
        families whose removal restores feasibility are the binding ones. Runs only after a
        failure, so it costs nothing on normal steps.
        """
        return tuple(name for name in self._enabled_families() if self._exactly_feasible((name,)))

    def _active_families(self, z: np.ndarray) -> tuple[str, ...]:
        """The families with a non-zero multiplier ``z`` (one per inequality row): the C++ core's
        ``binding_families`` (coopctrl/core/qp_answer_check.h), the loop's own."""
        from coopctrl._core import binding_families

        from .answer_check import FAMILY_NAMES

        pb = self.problem
        rows = pb.rows
        start = {name: (sl.start if sl.stop > sl.start else -1) for name, sl in rows.items()}
        mask = binding_families(pb.g, np.ascontiguousarray(z, dtype=float), 0, pb.n, pb.n_in, pb.m,
                                start.get("min_grip", -1), start.get("friction", -1), pb.n_facets,
                                start.get("torque_limits", -1))
        return tuple(name for bit, name in FAMILY_NAMES if mask & bit)
