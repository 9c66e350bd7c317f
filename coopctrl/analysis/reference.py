"""The reference solution of a closed loop: scipy's adaptive ``solve_ivp`` inside each plant step.

:class:`ReferenceIntegrator` has the fixed-step :class:`~coopctrl.integrators.Integrator`
interface, so it drops into the same :class:`~coopctrl.closed_loop.ClosedLoop` as the schemes it
judges. With ``substeps = 1`` one "step" is one control period ``[t_k, t_k + T]``: the torque
``u_k`` is held (zero-order hold) and the plant is integrated by
:func:`scipy.integrate.solve_ivp` (DOP853 or Radau) to tight tolerances. The controller is
therefore sampled at exactly the instants ``t_k = k T`` of every fixed-step run, with the same
sensor readings of the same states up to the integration error: the difference between a
fixed-step run and the reference measures the integration error alone.

Restarting the adaptive solver at each ``t_k`` is also what makes it accurate: the right-hand
side jumps there (the held torque changes) and an adaptive method must not step across the jump.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from coopctrl.errors import DivergenceError, ScenarioError
from coopctrl.integrators.base import Integrator, check_omega_max

#: Methods of :func:`scipy.integrate.solve_ivp` offered as references, and their orders.
REFERENCE_METHODS = {"DOP853": 8, "Radau": 5}

#: The smallest relative tolerance accepted: scipy raises anything below ``100 eps`` to it.
MIN_RTOL = 100.0 * float(np.finfo(float).eps)


@dataclass(frozen=True)
class ReferenceConfig:
    """How the reference solution is computed.

    Attributes:
        method: ``"DOP853"`` (explicit Runge-Kutta of order 8, the default: the fastest at tight
            tolerances on the non-stiff and mildly stiff scenes) or ``"Radau"`` (implicit, order
            5, L-stable: for scenes whose stiff modes would force DOP853 to tiny steps).
        rtol: Relative tolerance [-] of the local error, ``>= 100 eps`` (scipy's floor) and < 1.
        atol: Absolute tolerance, > 0, in the units of each state component ([m], [rad],
            [m/s], [rad/s]; a joint angle [rad]).

    How tight is tight enough: on ``planar_two_arm_lift`` (0.2 s) the reference with the defaults
    (``rtol = 1e-11``, ``atol = 1e-12``) agrees with RK4 at ``T / 64`` (an independent method whose
    own error is below rounding there) to 3e-15 m, 6e-15 rad and 4e-11 N: rounding. The errors
    it is used to measure are above 10 times that, except RK4's at ``T / 16``, which is at the
    rounding floor itself (``tests/test_order_of_accuracy.py``). DOP853 often crosses a whole
    control period in one or two steps on soft scenes, its local error estimate being below the
    tolerance: a tighter tolerance then changes nothing. On ``stiff_grasp_extreme`` with 5e7 N/m
    grasps and T = 3 ms, DOP853 and Radau (rtol 1e-10) agree to 8e-11 m and 8e-7 N over 0.3 s.
    """

    method: str = "DOP853"
    rtol: float = 1e-11
    atol: float = 1e-12

    def __post_init__(self) -> None:
        if self.method not in REFERENCE_METHODS:
            allowed = ", ".join(repr(m) for m in REFERENCE_METHODS)
            raise ScenarioError("reference.method", self.method, f"one of {allowed}")
        for name, low in (("rtol", MIN_RTOL), ("atol", 0.0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ScenarioError(f"reference.{name}", value, "a finite number")
            if name == "rtol" and not (low <= value < 1.0):
                raise ScenarioError("reference.rtol", value, f"a relative tolerance in [{low:.3g}, 1) (scipy's floor "
                                    "is 100 machine epsilons)")
            if name == "atol" and not value > 0.0:
                raise ScenarioError("reference.atol", value, "an absolute tolerance > 0")
            object.__setattr__(self, name, float(value))

    def to_dict(self) -> dict:
        return {"method": self.method, "rtol": self.rtol, "atol": self.atol}


class ReferenceIntegrator(Integrator):
    """One plant "step" = one :func:`scipy.integrate.solve_ivp` call over ``[t, t + h]``, ``u`` held.

    .. math::

        x(t + h) = x(t) + \\int_t^{t + h} f(s, x(s), u)\\, ds

    solved by ``config.method`` with ``config.rtol`` and ``config.atol``. Use it with
    ``substeps = 1`` (``h = T``): the solver then restarts at every control instant, never steps
    across a jump of the held torque, and is not limited to a fixed step.

    The last step size the solver accepted is passed on as ``first_step`` of the next call (it
    saves the initial step guess); :meth:`reset` forgets it. A solver failure (step size
    underflow, non-finite state) raises :class:`~coopctrl.errors.DivergenceError`, which the loop
    records as status ``"diverged"``.

    Attributes:
        config: The :class:`ReferenceConfig`.
        name: ``"reference"``.
        order: Order of the method (8 for DOP853, 5 for Radau).
    """

    name = "reference"

    def __init__(self, config: ReferenceConfig | None = None):
        self.config = config if config is not None else ReferenceConfig()
        if not isinstance(self.config, ReferenceConfig):
            raise TypeError(f"config is a {type(self.config).__name__}: expected a ReferenceConfig")
        self.order = REFERENCE_METHODS[self.config.method]
        self.reset()

    def __repr__(self) -> str:
        c = self.config
        return f"ReferenceIntegrator(ReferenceConfig(method={c.method!r}, rtol={c.rtol!r}, atol={c.atol!r}))"

    def reset(self) -> None:
        self._last_step = None
        self.steps_taken = 0  # accepted steps since the reset (the loop's step budget counts them)

    def predicted_max_step(self, omega_max: float) -> float:
        check_omega_max(omega_max)
        return math.inf

    def step(self, f, t, x, u, h):
        c = self.config
        t_end = t + h
        first = None if self._last_step is None else min(self._last_step, t_end - t)
        with np.errstate(over="ignore", invalid="ignore"):  # a blow-up is reported below
            sol = solve_ivp(lambda s, y: f(s, y, u), (t, t_end), x, method=c.method, rtol=c.rtol, atol=c.atol,
                            first_step=first)
        x_next = sol.y[:, -1].copy() if sol.y.shape[1] else np.full_like(x, np.nan)
        if sol.status != 0 or not np.all(np.isfinite(x_next)):
            raise DivergenceError(float(sol.t[-1]) if sol.t.size else t,
                                  f"reference solver {c.method} ({sol.message.rstrip('.')}) state max-norm",
                                  float(np.max(np.abs(x_next))) if x_next.size else math.nan)
        self.steps_taken += max(1, sol.t.size - 1)
        if sol.t.size >= 2:
            self._last_step = float(np.max(np.diff(sol.t)))
        return x_next
