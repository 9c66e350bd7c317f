"""``[load_distribution]``: options of the load-distribution QP (MODEL.md §6)."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import boolean, choice, integer, number, optional_number, optional_vector, scalar_or_vector

SPLITS = ("pseudo_inverse", "elastic")
SOLVERS = ("proxsuite", "daqp", "quadprog")


@dataclass(frozen=True)
class LoadDistributionConfig:
    """How the nominal load is split among the contacts.

    Attributes:
        split: Preferred split: ``"pseudo_inverse"`` (equal weights) or ``"elastic"`` (in
            proportion to the interconnection stiffnesses).
        shares: Optional preferred share of each arm (m values >= 0, not all 0), or ``None``.
        squeeze: Desired internal squeeze per contact pair in [N], >= 0: a scalar broadcast
            to all m(m-1)/2 pairs, or one value per pair.
        min_grip: Minimum normal (grip) force per contact in [N], or ``None`` (no constraint).
        friction_coefficient: Coulomb friction coefficient (> 0) of the friction pyramids, or
            ``None`` (no friction constraint).
        friction_facets: Number of facets of each friction pyramid (>= 3).
        torque_limits: Enforce ``|J_i^T F_i + bias| <= tau_max`` in the QP.
        solver: QP backend: ``"proxsuite"``, ``"daqp"`` or ``"quadprog"``.
        eps_abs: Absolute tolerance of the solver (> 0) [N].
        max_consecutive_failures: Failed solves in a row (>= 1) before the run stops with
            status ``"qp_failed"``.
    """

    split: str = "pseudo_inverse"
    shares: tuple[float, ...] | None = None
    squeeze: float | tuple[float, ...] = 5.0
    min_grip: float | None = None
    friction_coefficient: float | None = None
    friction_facets: int = 4
    torque_limits: bool = False
    solver: str = "proxsuite"
    eps_abs: float = 1e-9
    max_consecutive_failures: int = 5

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "split", choice("split", self.split, SPLITS))
        s(self, "shares", optional_vector("shares", self.shares, nonnegative=True, what="one share per arm"))
        if self.shares is not None and sum(self.shares) <= 0.0:
            raise ScenarioError("shares", list(self.shares), "shares >= 0 that are not all 0")
        s(self, "squeeze", scalar_or_vector("squeeze", self.squeeze, nonnegative=True, unit="N"))
        s(self, "min_grip", optional_number("min_grip", self.min_grip, nonnegative=True, unit="N"))
        s(self, "friction_coefficient", optional_number("friction_coefficient", self.friction_coefficient, positive=True))
        s(self, "friction_facets", integer("friction_facets", self.friction_facets, minimum=3))
        s(self, "torque_limits", boolean("torque_limits", self.torque_limits))
        s(self, "solver", choice("solver", self.solver, SOLVERS))
        s(self, "eps_abs", number("eps_abs", self.eps_abs, positive=True))
        s(self, "max_consecutive_failures", integer("max_consecutive_failures", self.max_consecutive_failures, minimum=1))

    def squeeze_per_pair(self, arms: int) -> tuple[float, ...]:
        """Desired squeeze of each of the m(m-1)/2 contact pairs [N]."""
        n = arms * (arms - 1) // 2
        return self.squeeze if isinstance(self.squeeze, tuple) else (self.squeeze,) * n
