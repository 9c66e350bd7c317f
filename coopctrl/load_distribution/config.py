"""Configuration of the load-distribution QP (docs/model.md section 6)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral, Real

from ..errors import ScenarioError

#: Splits of the external load that the preferred split ``F_pref`` can use.
SPLITS = ("pseudo_inverse", "elastic")


def _available_qpsolvers() -> list[str]:
    import qpsolvers

    return list(qpsolvers.available_solvers)


def solver_allowed_message() -> str:
    """What ``solver`` accepts on this machine, with the command that installs more."""
    return (
        f"'proxsuite' (persistent dense QP), 'compiled' (the compiled core's Goldfarb-Idnani) or an installed "
        f"qpsolvers backend (found: {', '.join(_available_qpsolvers()) or 'none'}); "
        "to add one: pip install qpsolvers[<name>]"
    )


def _positive(name: str, value, allow_zero: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value) or (
        value < 0 or (value == 0 and not allow_zero)
    ):
        raise ScenarioError(name, value, "a finite number " + (">= 0" if allow_zero else "> 0"))
    return float(value)


@dataclass(frozen=True)
class LoadDistributionConfig:
    """Settings of :class:`~coopctrl.load_distribution.LoadDistribution`.

    The QP over the stacked contact wrenches ``F`` (6m spatial, 3m planar) is

    .. math::

        \\min_F \\tfrac12 (F - F_{pref})^T P (F - F_{pref}) \\quad \\text{s.t.} \\quad G F = w_N,
        \\qquad F_{pref} = A w_N + E s_{des},

    plus the inequality families switched on here (``min_grip``, ``friction_coefficient``,
    ``torque_limits``).

    Attributes:
        split: ``"pseudo_inverse"``: ``A = W^{-1} G^T (G W^{-1} G^T)^{-1}`` and ``P = W`` with
            ``W_i = diag(force_weight I, moment_weight I) / share_i``. ``"elastic"``: the
            elastic-energy-minimising split ``A_K = K G^T (G K G^T)^{-1}`` and ``P = K^{-1}``
            for the block-diagonal grasp stiffness ``K`` passed to each solve
            (``shares`` and the weights are then unused).
        shares: Preferred share of the load per arm (positive weights, e.g. ``(2, 1)`` for a
            leader carrying twice what the follower carries), or ``None`` for equal shares.
        force_weight: Cost weight of the force components [1/N^2].
        moment_weight: Cost weight of the moment components [1/(N m)^2].
        squeeze: Desired virtual-linkage squeeze ``s_des`` [N] per contact pair (pairs ``i < j``
            in lexicographic order): one number for every pair or a tuple of m(m-1)/2 numbers.
            Positive squeezes (compression).
        min_grip: Minimum normal force ``n_i^T f_i >= min_grip`` [N] along each inward contact
            normal, or ``None`` (off).
        friction_coefficient: Coulomb coefficient ``mu`` [-] of the linearised friction pyramid
            about each contact normal, or ``None`` (off).
        friction_facets: Number of facets of the pyramid (>= 3; planar scenes always use 2).
        torque_limits: Enforce ``-tau_max <= J_i^T F_i + bias_i <= tau_max`` [N m].
        solver: ``"compiled"`` (the default: the compiled core's dual active-set solver of
            :mod:`~coopctrl.load_distribution.goldfarb_idnani`, warm started from the last active
            set, inside the compiled tick of :mod:`coopctrl.loop`), ``"proxsuite"`` (one persistent
            dense QP, warm started) or a qpsolvers backend name such as ``"daqp"`` or
            ``"quadprog"``: the reference path (the same compiled tick, handing each QP to that solver).
        eps_abs: Absolute solver tolerance (proxsuite) [N, N m].
        max_iter: Iteration limit of the proxsuite solver.
        max_consecutive_failures: Consecutive failed solves (answered with the held previous split)
            after which :class:`~coopctrl.errors.InfeasibleLoad` is raised.
    """

    split: str = "pseudo_inverse"
    shares: tuple[float, ...] | None = None
    force_weight: float = 1.0
    moment_weight: float = 1.0
    squeeze: float | tuple[float, ...] = 0.0
    min_grip: float | None = None
    friction_coefficient: float | None = None
    friction_facets: int = 4
    torque_limits: bool = False
    solver: str = "compiled"
    eps_abs: float = 1e-9
    max_iter: int = 1000
    max_consecutive_failures: int = 5

    def __post_init__(self):
        if self.split not in SPLITS:
            raise ScenarioError("split", self.split, " or ".join(repr(s) for s in SPLITS))
        if self.shares is not None:
            try:
                shares = tuple(self.shares)
            except TypeError:
                raise ScenarioError("shares", self.shares, "None or a tuple of positive weights") from None
            if not shares:
                raise ScenarioError("shares", self.shares, "None or a non-empty tuple of positive weights")
            for i, s in enumerate(shares):
                _positive(f"shares[{i}]", s)
            object.__setattr__(self, "shares", tuple(float(s) for s in shares))
        object.__setattr__(self, "force_weight", _positive("force_weight", self.force_weight))
        object.__setattr__(self, "moment_weight", _positive("moment_weight", self.moment_weight))
        if isinstance(self.squeeze, Real) and not isinstance(self.squeeze, bool):
            if not math.isfinite(self.squeeze):
                raise ScenarioError("squeeze", self.squeeze, "a finite squeeze [N]")
            object.__setattr__(self, "squeeze", float(self.squeeze))
        else:
            try:
                sq = tuple(self.squeeze)
            except TypeError:
                raise ScenarioError("squeeze", self.squeeze, "a number or a tuple of numbers [N]") from None
            for i, s in enumerate(sq):
                if isinstance(s, bool) or not isinstance(s, Real) or not math.isfinite(s):
                    raise ScenarioError(f"squeeze[{i}]", s, "a finite squeeze [N]")
            object.__setattr__(self, "squeeze", tuple(float(s) for s in sq))
        if self.min_grip is not None:
            object.__setattr__(self, "min_grip", _positive("min_grip", self.min_grip, allow_zero=True))
        if self.friction_coefficient is not None:
            object.__setattr__(
                self, "friction_coefficient", _positive("friction_coefficient", self.friction_coefficient)
            )
        if isinstance(self.friction_facets, bool) or not isinstance(self.friction_facets, Integral) or (
            self.friction_facets < 3
        ):
            raise ScenarioError("friction_facets", self.friction_facets, "an integer >= 3")
        if not isinstance(self.torque_limits, bool):
            raise ScenarioError("torque_limits", self.torque_limits, "True or False")
        if not isinstance(self.solver, str) or (
            self.solver not in ("proxsuite", "compiled") and self.solver not in _available_qpsolvers()
        ):
            raise ScenarioError("solver", self.solver, solver_allowed_message())
        object.__setattr__(self, "eps_abs", _positive("eps_abs", self.eps_abs))
        for name in ("max_iter", "max_consecutive_failures"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, Integral) or v < 1:
                raise ScenarioError(name, v, "an integer >= 1")

    @property
    def inequality_families(self) -> tuple[str, ...]:
        """Names of the enabled inequality families, in row order of the QP."""
        fam = []
        if self.min_grip is not None:
            fam.append("min_grip")
        if self.friction_coefficient is not None:
            fam.append("friction")
        if self.torque_limits:
            fam.append("torque_limits")
        return tuple(fam)
