"""Error-controlled schemes: ``rk23``, ``rk45`` and ``trbdf2``, their tableaux and tolerances.

These run compiled (:mod:`coopctrl.integrators.adaptive_plans` integrates a control period with them:
in the loop, and in :meth:`ErrorControlled.step` on a cooperative plant's ``rhs``); the classes here
hold what a run needs: the tableau, the tolerances and the step controller. The step is chosen by the error estimate, not by a stability limit:
:meth:`ErrorControlled.predicted_max_step` is ``inf`` (an unstable step has a large error and is
rejected; a stiff mode makes an explicit pair take many small steps, which the run's step
statistics show, and ``trbdf2`` is L-stable).

=============  ======================================  =====  ==============  ===========
name           scheme                                  order  error estimate  stages
=============  ======================================  =====  ==============  ===========
``"rk23"``     Bogacki-Shampine 3(2), FSAL             3      order 2         3 (+1 FSAL)
``"rk45"``     Dormand-Prince 5(4), FSAL               5      order 4         6 (+1 FSAL)
``"trbdf2"``   TR-BDF2 (ESDIRK, L-stable, stiffly      2      order 2 (a 3rd  3 (2 implicit)
               accurate; Hosea and Shampine 1996)             order pair)
=============  ======================================  =====  ==============  ===========

The explicit tableaux are scipy's ``RK23`` and ``RK45`` (``tests/test_integrators_error_controlled.py``
compares them entry by entry).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import coopctrl.arguments as arguments
import coopctrl.integrators.stepping as stepping
from coopctrl.integrators.base import FrozenSettings, Integrator

#: Step controllers: Gustafsson's PI controller (the default), scipy's elementary controller.
CONTROLLERS = ("pi", "elementary")


class ErrorControlled(FrozenSettings, Integrator):
    """A scheme whose step inside each control period is chosen by its local error estimate.

    Args:
        rtol: Relative tolerance [-], in [1e-13, 0.1].
        atol: Absolute tolerance of the positions [m, rad], > 0.
        atol_velocity: Absolute tolerance of the velocities [m/s, rad/s], > 0; ``None``: ``atol``
            divided by the control period (set when the run starts: :meth:`tolerances`).
        min_step: Smallest step [s] before the run stops, > 0.
        controller: ``"pi"`` (Gustafsson) or ``"elementary"`` (scipy's ``solve_ivp``).
    """

    adaptive = True
    error_order = 0

    def __init__(self, rtol: float = 1e-6, atol: float = 1e-8, atol_velocity: float | None = None,
                 min_step: float = 1e-10, controller: str = "pi"):
        self.rtol = arguments.number("rtol", rtol, minimum=1e-13)
        if self.rtol > 0.1:
            raise arguments.invalid("rtol", rtol, "a finite number >= 1e-13 and <= 0.1")
        self.atol = arguments.number("atol", atol, positive=True, unit="m")
        self.atol_velocity = None if atol_velocity is None else arguments.number(
            "atol_velocity", atol_velocity, positive=True, unit="m/s")
        self.min_step = arguments.number("min_step", min_step, positive=True, unit="s")
        if controller not in CONTROLLERS:
            raise arguments.invalid("controller", controller, f"one of {', '.join(map(repr, CONTROLLERS))}")
        self.controller = controller
        self._stepper = stepping.Stepper()

    def tolerances(self, nz: int, control_period: float) -> np.ndarray:
        """``atol_c`` of the state ``x = (z, dz)``: ``atol`` on the ``nz`` positions, ``atol_velocity``
        (default ``atol / control_period`` [1/s]) on the ``nz`` velocities."""
        v = self.atol / control_period if self.atol_velocity is None else self.atol_velocity
        return np.concatenate([np.full(nz, self.atol), np.full(nz, v)])

    def step(self, f, t: float, x: np.ndarray, u: Any, h: float) -> np.ndarray:
        """The state at ``t + h`` [s] from ``x`` at ``t``, ``u`` held, ``h`` being one control period: the
        compiled period of :mod:`coopctrl.integrators.adaptive_plans` on a cooperative plant's ``rhs``
        (the step it chose carries over to the next call with the same ``f`` and ``h``; :meth:`reset`
        forgets it). Another ``f`` raises ``NotImplementedError`` (use :func:`scipy.integrate.solve_ivp`).

        Raises:
            StepTooSmall: when a step below ``min_step`` would be needed (:class:`~coopctrl.errors.StepTooSmall`).
        """
        return self._stepper.step(self, f, t, x, u, h)

    def reset(self) -> None:
        """Forget the step carried from one call to the next."""
        self._stepper.reset()

    def predicted_max_step(self, omega_max: float, damping_ratio: float = 0.0) -> float:
        """``inf``: the error estimate, not a stability limit, chooses the step."""
        return math.inf

    def max_stable_step(self, A) -> float:
        return math.inf

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(rtol={self.rtol:g}, atol={self.atol:g}, atol_velocity={self.atol_velocity}, "
                f"min_step={self.min_step:g}, controller={self.controller!r})")


class BogackiShampine(ErrorControlled):
    """Bogacki-Shampine 3(2), ``"rk23"``: three stages and the first-same-as-last slope."""

    name = "rk23"
    order = 3
    error_order = 2
    C = (0.0, 1 / 2, 3 / 4)
    A = ((0.0, 0.0, 0.0), (1 / 2, 0.0, 0.0), (0.0, 3 / 4, 0.0))
    B = (2 / 9, 1 / 3, 4 / 9)
    E = (5 / 72, -1 / 12, -1 / 9, 1 / 8)


class DormandPrince(ErrorControlled):
    """Dormand-Prince 5(4), ``"rk45"``: six stages and the first-same-as-last slope."""

    name = "rk45"
    order = 5
    error_order = 4
    C = (0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0)
    A = ((0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
         (1 / 5, 0.0, 0.0, 0.0, 0.0, 0.0),
         (3 / 40, 9 / 40, 0.0, 0.0, 0.0, 0.0),
         (44 / 45, -56 / 15, 32 / 9, 0.0, 0.0, 0.0),
         (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0, 0.0),
         (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0.0))
    B = (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84)
    E = (-71 / 57600, 0.0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40)


class TRBDF2(ErrorControlled):
    """TR-BDF2, ``"trbdf2"``: L-stable, for stiff grasps (see :mod:`coopctrl.integrators.adaptive_plans`).

    Newton's stages converge when the scaled correction is below ``newton_tol`` [-] (a fraction
    of the error tolerance; default 0.03, Hairer and Wanner's kappa) within ``max_iterations``.
    """

    name = "trbdf2"
    order = 2
    error_order = 2

    def __init__(self, rtol: float = 1e-6, atol: float = 1e-8, atol_velocity: float | None = None,
                 min_step: float = 1e-10, controller: str = "pi", newton_tol: float = 0.03, max_iterations: int = 8):
        super().__init__(rtol, atol, atol_velocity, min_step, controller)
        self.newton_tol = arguments.number("newton_tol", newton_tol, positive=True)
        if self.newton_tol > 1.0:
            raise arguments.invalid("newton_tol", newton_tol, "a finite number > 0 and <= 1")
        if isinstance(max_iterations, bool) or not isinstance(max_iterations, int) or not 1 <= max_iterations <= 100:
            raise arguments.invalid("max_iterations", max_iterations, "an integer in [1, 100]")
        self.max_iterations = max_iterations

    def stability_function(self, z):
        """``R(z)`` of TR-BDF2 (the trapezoid to ``gamma``, BDF2 to 1): ``R(inf) = 0``."""
        g = 2.0 - math.sqrt(2.0)
        d, w = g / 2.0, math.sqrt(2.0) / 4.0
        z = np.asarray(z, dtype=complex)
        r2 = (1.0 + d * z) / (1.0 - d * z)  # stage 2 / x (the trapezoidal rule)
        k1 = z  # h k_i = z * stage_i (per unit x)
        return (1.0 + w * k1 + w * z * r2) / (1.0 - d * z)
