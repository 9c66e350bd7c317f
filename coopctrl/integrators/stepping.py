"""``step`` of the built-in schemes, fixed-step and error-controlled, on the compiled core's schemes.

A scheme object (:class:`~coopctrl.integrators.RungeKutta4`, ...) is configuration: its name, its
Newton settings, its tolerances. :func:`step` advances a state by one step ``h`` [s] with the scheme's plan
(:func:`~coopctrl.integrators.compiled.make_plan`: work arrays and, for the implicit schemes, the
Newton matrix and stage slopes kept from step to step; for an error-controlled scheme its own steps over ``h``),
through the schemes the loop's tick runs (coopctrl/core: explicit_schemes.h, implicit_schemes.h,
adaptive_schemes.h):

- ``f`` the ``rhs`` of a cooperative plant (a :class:`plants.cooperative.CooperativePlant`): on the plant's own
  compiled kernels (``coopctrl._core.plant_advance``), the bits of the loop's tick;
- any other Python ``f(t, x, u) -> dx``: the core's schemes call ``f`` back at each stage
  (``coopctrl._core.zoh_advance``, ``adaptive_advance_f``): the documented slower path.
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.integrators.base import FrozenSettings, Integrator


def _plant_of(f):
    """The cooperative plant whose own ``rhs`` ``f`` is, else ``None``."""
    owner = getattr(f, "__self__", None)
    if owner is None or getattr(f, "__name__", None) != "rhs":
        return None
    from plants.cooperative import CooperativePlant

    if isinstance(owner, CooperativePlant) and type(owner).rhs is CooperativePlant.rhs:
        return owner
    return None


class Stepper:
    """The plan of one scheme object and what it is for: the right-hand side (plant or Python ``f``)
    and the state size. A new ``f`` or size starts cold (a new plan), as does :meth:`reset`."""

    __slots__ = ("f", "plant", "nx", "period", "plan", "P", "status", "steps", "x_fail", "report", "jacobians")

    def __init__(self):
        self.f = None
        self.plan = None
        self.jacobians = 0.0  # Jacobian evaluations of the plans before the current one

    def reset(self) -> None:
        self.f = None
        self.plan = None
        self.jacobians = 0.0

    def _current(self) -> float:
        memo = getattr(self.plan, "memo", None)  # an ImplicitPlan's memo[2] counts its Jacobians
        return float(memo[2]) if memo is not None and memo.shape[0] == 3 else 0.0

    def jacobian_evaluations(self) -> int:
        """Jacobian evaluations since construction or :meth:`reset` (the implicit plans count them)."""
        return int(self.jacobians + self._current())

    def _prepare(self, scheme, f, nx: int, period):
        if (self.plan is not None and self.nx == nx and self.period == period
                and (self.f is f or self.f == f)):
            return
        import coopctrl.integrators.compiled as compiled

        self.jacobians += self._current()
        self.plan = compiled.make_plan(scheme, nx, period)
        self.f, self.nx, self.period = f, nx, period
        self.plant = _plant_of(f)
        if self.plant is not None and self.plant.state_size == nx:
            self.P = self.plant.plant_args  # the plant's arrays by name
        else:
            self.plant, self.P = None, None
        self.status = np.zeros(2, np.int64)
        self.steps = np.zeros(1)
        self.x_fail = np.zeros(nx)
        import coopctrl._core as _core

        self.report = _core.StopReport()  # how the last step ended, by name

    def step(self, scheme, f, t, x, u, h) -> np.ndarray:
        """One step of ``scheme`` (see :meth:`Integrator.step <coopctrl.integrators.Integrator.step>`)."""
        import coopctrl.integrators.compiled as compiled

        x = np.array(x, dtype=float)  # a new array, advanced in place: the caller's is not modified
        if x.ndim != 1:
            raise ValueError(f"x has shape {x.shape}: expected a 1-D state (z, dz)")
        h = float(h)
        if not (h > 0.0 and math.isfinite(h)):
            raise ValueError(f"h = {h!r} is invalid: expected a finite step > 0 [s]")
        t = float(t)
        adaptive = getattr(scheme, "adaptive", False)  # an error-controlled plan is made for its interval h
        self._prepare(scheme, f, x.shape[0], h if adaptive else None)
        self.steps[0] = h
        self.status[:] = 0
        import coopctrl._core as _core

        if self.plant is not None:  # the plant's own kernels in the compiled core, any scheme
            tau = np.ascontiguousarray(u, dtype=float) if u is not None else None
            if tau is None or tau.shape != (self.plant.input_size,):
                f(t, x, u)  # the plant names the bad input
                raise TypeError(f"u = {u!r} is invalid: expected the plant's {self.plant.input_size} joint torques [N m]")
            code = _core.plant_advance(self.plan, x, tau, self.P, self.status, t, self.steps, self.x_fail,
                                       self.report)
        elif adaptive:  # the compiled core's error-controlled schemes on the Python f (adaptive_schemes.h)
            code = _core.adaptive_advance_f(self.plan, f, x, u, t, self.x_fail, self.report)
        else:  # the compiled core's schemes on the Python f (coopctrl/core: explicit_schemes.h, implicit_schemes.h)
            report = _core.zoh_advance(self.plan, f, x, u, t, self.steps, self.x_fail)
            code = report["code"]
            self.report.detail = (report["failed_step"], report["newton_iterations"], 0)
            self.report.value = (report["last_correction"], report["failed_time"])
        if code == compiled.STEP_OK:
            return x
        if code == compiled.STEP_NEWTON_FAILED:
            raise compiled.newton_failure(scheme.name, self.steps, self.report)
        if code == compiled.STEP_TOO_SMALL:
            raise _step_too_small(scheme, self.plant, self.x_fail, self.report)
        if code == compiled.STEP_PLANT_ERROR and self.plant is not None:
            f(t, self.x_fail.copy(), u)  # the plant's own exception for the state it failed at
        raise RuntimeError(f"{scheme.name}: the right-hand side failed at t = {t:.6g} s (code {int(code)}, "
                           f"status {self.status.tolist()})")


def _step_too_small(scheme, plant, x_fail, report):
    """The :class:`~coopctrl.errors.StepTooSmall` of an error-controlled step below ``min_step``, naming
    the stiffest mode at the state it stopped at (as the loop does)."""
    from coopctrl.errors import StepTooSmall
    from coopctrl.loop.stiffest_mode import stiffest_mode

    mode, omega = stiffest_mode(plant, x_fail)
    pose = tuple(float(v) for v in x_fail[plant.nz - plant.p:plant.nz])
    step, time = report.value
    return StepTooSmall(float(time), float(step), scheme.min_step, scheme.name, mode, omega, pose)


class CompiledScheme(FrozenSettings, Integrator):
    """A built-in scheme: :meth:`step` runs the compiled core's scheme on its plan
    (:mod:`coopctrl.integrators.compiled`). The plan (its Newton state) is kept from step to step for the same
    ``f`` and state size; :meth:`reset` drops it. Use one instance per simulation. Its settings are frozen
    (:class:`~coopctrl.integrators.base.FrozenSettings`)."""

    def __init__(self):
        self._stepper = Stepper()

    def step(self, f, t, x, u, h):
        return self._stepper.step(self, f, t, x, u, h)

    def reset(self) -> None:
        """Forget the plan kept between steps (the implicit schemes' Newton matrix and stage slopes)."""
        self._stepper.reset()
