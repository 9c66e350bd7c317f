"""``[simulation]``: duration, control period, integrator and divergence bounds."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import choice, integer, number, optional_number

INTEGRATORS = ("rk4", "euler", "symplectic_euler", "implicit_midpoint", "implicit_euler")
STARTS = ("loaded", "unloaded")


@dataclass(frozen=True)
class SimulationConfig:
    """How the closed loop is simulated.

    Attributes:
        duration: Simulated time in [s], > 0 and >= control_period.
        control_period: Control period in [s] (zero-order hold on the torques), > 0.
        integrator: ``"rk4"``, ``"euler"``, ``"symplectic_euler"``, ``"implicit_midpoint"`` or
            ``"implicit_euler"`` (L-stable: for stiff interconnections at steps far beyond the
            explicit limits).
        substeps: Plant integration steps per control period (>= 1); step = period / substeps.
        seed: Seed of the sensor noise generator.
        max_deformation: Divergence bound on any interconnection deformation in [m], > 0.
        max_energy: Divergence bound on the total energy in [J], or ``None``.
        start: ``"loaded"`` starts at rest in the loaded state (object on its nominal pose,
            interconnections deformed to carry the QP split of t = 0, arms placed by inverse
            kinematics); ``"unloaded"`` starts with every interconnection at rest length (the
            gripping phase: forces build up from zero).
    """

    duration: float = 1.5
    control_period: float = 0.001
    integrator: str = "rk4"
    substeps: int = 1
    seed: int = 0
    max_deformation: float = 0.05
    max_energy: float | None = None
    start: str = "loaded"

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "duration", number("duration", self.duration, positive=True, unit="s"))
        s(self, "control_period", number("control_period", self.control_period, positive=True, unit="s"))
        if self.control_period > self.duration:
            raise ScenarioError("control_period", self.control_period, f"a period <= duration = {self.duration} s")
        s(self, "integrator", choice("integrator", self.integrator, INTEGRATORS))
        s(self, "substeps", integer("substeps", self.substeps, minimum=1))
        s(self, "seed", integer("seed", self.seed, minimum=0))
        s(self, "max_deformation", number("max_deformation", self.max_deformation, positive=True, unit="m"))
        s(self, "max_energy", optional_number("max_energy", self.max_energy, positive=True, unit="J"))
        s(self, "start", choice("start", self.start, STARTS))

    @property
    def step(self) -> float:
        """Integration step [s]: ``control_period / substeps``."""
        return self.control_period / self.substeps

    @property
    def control_steps(self) -> int:
        """Number of control periods in ``duration`` (rounded to the nearest)."""
        return max(1, round(self.duration / self.control_period))
