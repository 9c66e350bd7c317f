"""``[simulation]``: duration, control period, integrator and divergence bounds."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import choice, integer, number, optional_number
from coopctrl.scenario.schema import key, limits

#: Fixed-step schemes (one step of ``control_period / substeps``).
FIXED_STEP_INTEGRATORS = ("rk4", "euler", "symplectic_euler", "implicit_midpoint", "implicit_euler")
#: Error-controlled schemes (steps chosen inside each control period to meet ``rtol``/``atol``).
ADAPTIVE_INTEGRATORS = ("rk23", "rk45", "trbdf2")
INTEGRATORS = FIXED_STEP_INTEGRATORS + ADAPTIVE_INTEGRATORS
STARTS = ("loaded", "unloaded")
#: Largest seed: TOML integers are 64-bit signed.
MAX_SEED = 2**63 - 1


@dataclass(frozen=True)
class SimulationConfig:
    """How the closed loop is simulated.

    Attributes:
        duration: Simulated time in [s], > 0 and >= control_period.
        control_period: Control period in [s] (zero-order hold on the torques), > 0.
        integrator: Fixed step: ``"rk4"``, ``"euler"``, ``"symplectic_euler"``, ``"implicit_midpoint"``
            or ``"implicit_euler"`` (L-stable: for stiff interconnections at steps far beyond the
            explicit limits). Error-controlled (the step is chosen inside each control period so
            that the local error meets ``rtol`` and ``atol``): ``"rk23"`` (Bogacki-Shampine 3(2)),
            ``"rk45"`` (Dormand-Prince 5(4)) or ``"trbdf2"`` (TR-BDF2, L-stable, for stiff grasps).
        substeps: Plant integration steps per control period (>= 1); step = period / substeps.
            The error-controlled schemes ignore it.
        rtol: Relative tolerance [-] of the error-controlled schemes: each step's local error
            estimate ``e_c`` must satisfy ``RMS_c(e_c / (atol_c + rtol max(|x_c|, |x_c'|))) <= 1``.
        atol: Absolute tolerance of the positions [m for lengths, rad for angles].
        atol_velocity: Absolute tolerance of the velocities [m/s, rad/s]; ``None`` (absent) =
            ``atol / control_period``.
        min_step: Smallest step [s] an error-controlled scheme may take; below it the run stops
            (the state, the time and the stiffest mode are named).
        accuracy: Accuracy target [m] of the object's position error (maximum over the run), or
            ``None``. When set, ``coopctrl run`` measures a short prefix of the run against the
            reference (and the error's growth after it against a compiled run), runs the cheapest
            setting (integrator, step or tolerances) predicted to meet it, and says which on one
            line (``coopctrl tradeoff --target``; coopctrl.analysis.accuracy_target).
        seed: Seed of the sensor noise generator.
        max_deformation: Divergence bound on any interconnection deformation in [m], > 0.
        max_energy: Divergence bound on the total energy in [J], or ``None``.
        start: ``"loaded"`` starts at rest in the loaded state (object on its nominal pose,
            interconnections deformed to carry the QP split of t = 0, arms placed by inverse
            kinematics); ``"unloaded"`` starts with every interconnection at rest length (the
            gripping phase: forces build up from zero).
        record_every: Keep every how many control ticks in the record (>= 1; the last tick is always
            kept): the returned result and its files (``--out``) hold about
            ``duration / (control_period * record_every)`` samples. The summary's metrics are
            computed on every tick whatever its value.
    """

    duration: float = key(1.5, unit="s", gt=0, le=1e4,
                          why="2.8 h of simulated time; the record grows with duration / control_period "
                          "(1e300 s overflowed its allocation)")
    control_period: float = key(0.001, unit="s", ge=1e-6, le=1.0,
                                why="1 us is faster than any arm controller (the extremes grid goes down to it); "
                                "a period above 1 s controls no arm")
    integrator: str = key("rk4", allowed=INTEGRATORS)
    substeps: int = key(1, ge=1, le=10000, why="an integration step of at least 1e-4 control periods")
    rtol: float = key(1e-6, ge=1e-13, le=0.1,
                      why="below 1e-13 the error estimate is round-off (scipy's solve_ivp floors rtol at 100 eps); "
                          "above 0.1 no step is controlled")
    atol: float = key(1e-8, unit="m", gt=0, le=1.0, why="an absolute position error above 1 m controls nothing")
    atol_velocity: float | None = key(None, unit="m/s", gt=0, le=100.0,
                                      why="absent = atol / control_period; above 100 m/s controls nothing")
    min_step: float = key(1e-10, unit="s", ge=1e-15, le=1.0,
                          why="a step of 1 fs is below any grasp's time scale; it must be below the control period")
    accuracy: float | None = key(None, unit="m", ge=1e-12, le=1.0,
                                 why="absent = run the scene's own setting; 1e-12 m is the accuracy reference's own "
                                 "error, below it nothing can be measured; above 1 m there is nothing to meet")
    seed: int = key(0, ge=0, le=MAX_SEED, why="a 64-bit signed integer, as TOML's integers")
    max_deformation: float = key(0.05, unit="m", gt=0, le=10.0, why="no grasp deforms by metres")
    max_energy: float | None = key(None, unit="J", gt=0, le=1e12, why="absent = no energy bound")
    start: str = key("loaded", allowed=STARTS)
    record_every: int = key(1, ge=1, le=1_000_000,
                            why="a sample at least every 1e6 control periods (1000 s at the default period)")

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "duration", number("duration", self.duration, **limits(self, "duration")))
        s(self, "control_period", number("control_period", self.control_period, **limits(self, "control_period")))
        if self.control_period > self.duration:
            raise ScenarioError("control_period", self.control_period, f"a period <= duration = {self.duration} s")
        s(self, "integrator", choice("integrator", self.integrator, INTEGRATORS))
        s(self, "substeps", integer("substeps", self.substeps, minimum=1, maximum=10000))
        s(self, "rtol", number("rtol", self.rtol, **limits(self, "rtol")))
        s(self, "atol", number("atol", self.atol, **limits(self, "atol")))
        s(self, "atol_velocity", optional_number("atol_velocity", self.atol_velocity, **limits(self, "atol_velocity")))
        s(self, "min_step", number("min_step", self.min_step, **limits(self, "min_step")))
        if self.min_step >= self.control_period:
            raise ScenarioError("min_step", self.min_step, f"a step < control_period = {self.control_period} s")
        s(self, "accuracy", optional_number("accuracy", self.accuracy, **limits(self, "accuracy")))
        s(self, "seed", integer("seed", self.seed, minimum=0, maximum=MAX_SEED))
        s(self, "max_deformation", number("max_deformation", self.max_deformation, **limits(self, "max_deformation")))
        s(self, "max_energy", optional_number("max_energy", self.max_energy, **limits(self, "max_energy")))
        s(self, "start", choice("start", self.start, STARTS))
        s(self, "record_every", integer("record_every", self.record_every, minimum=1, maximum=1_000_000))

    @property
    def adaptive(self) -> bool:
        """Whether the integrator is error-controlled (:data:`ADAPTIVE_INTEGRATORS`)."""
        return self.integrator in ADAPTIVE_INTEGRATORS

    @property
    def velocity_tolerance(self) -> float:
        """``atol_velocity`` [m/s, rad/s], or its default ``atol / control_period``."""
        return self.atol / self.control_period if self.atol_velocity is None else self.atol_velocity

    @property
    def step(self) -> float:
        """Integration step [s]: ``control_period / substeps``."""
        return self.control_period / self.substeps

    @property
    def control_steps(self) -> int:
        """Number of control periods in ``duration`` (rounded to the nearest)."""
        return max(1, round(self.duration / self.control_period))
