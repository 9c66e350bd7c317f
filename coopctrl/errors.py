"""Errors raised by the control layer.

One small tree: :class:`CoopctrlError` is the parent; each subclass also inherits the builtin it
specialises. Errors carry their data as attributes and say how to fix the problem.
"""

from __future__ import annotations


class CoopctrlError(Exception):
    """Base class of every error raised by :mod:`coopctrl`."""


class ScenarioError(CoopctrlError, ValueError):
    """A scenario file or override is invalid.

    Attributes:
        path: Dotted path of the offending field (``"arms[1].grasp"``), or ``""`` for the file.
        value: The value received.
        allowed: What would have been accepted.
    """

    def __init__(self, path: str, value, allowed: str, source: str | None = None):
        self.path = path
        self.value = value
        self.allowed = allowed
        self.source = source
        where = f"{source}: " if source else ""
        field = path or "<scenario>"
        super().__init__(f"{where}{field} = {value!r} is invalid: expected {allowed}")


class InfeasibleLoad(CoopctrlError, ArithmeticError):
    """The load-distribution QP has no feasible split, or the solver failed.

    Attributes:
        status: The solver's status string.
        binding: Names of the enabled constraint families that make the load infeasible
            (``"torque_limits"``, ``"friction"``, ``"min_grip"``); empty when the solver itself
            failed (iteration limit, inaccurate answer, numerical failure).
        advice: How to fix it (one clause).
    """

    #: The fix when constraint families bind: the load, or the constraints, must give.
    BINDING_ADVICE = "reduce the payload or the acceleration of the trajectory, or relax those constraints"

    def __init__(self, status: str, binding: tuple[str, ...] = (), detail: str = "", advice: str | None = None):
        self.status = status
        self.binding = tuple(binding)
        self.advice = advice if advice is not None else (self.BINDING_ADVICE if self.binding else
                                                         "check the load_distribution settings")
        fam = f" (binding: {', '.join(self.binding)})" if self.binding else ""
        super().__init__(
            f"load distribution failed with status '{status}'{fam}{': ' + detail if detail else ''}; {self.advice}"
        )


class DivergenceError(CoopctrlError, ArithmeticError):
    """A simulation left its bounds (non-finite state, energy or deformation beyond a bound).

    Attributes:
        time: Simulation time [s] at detection.
        quantity: What went out of bounds.
        value: Its value.
        suggested_step: A step [s] expected to be stable, or ``None``.
    """

    def __init__(self, time: float, quantity: str, value: float, suggested_step: float | None = None):
        self.time = time
        self.quantity = quantity
        self.value = value
        self.suggested_step = suggested_step
        hint = f"; try a step of at most {suggested_step:.3g} s or a stiff integrator" if suggested_step else ""
        super().__init__(f"diverged at t = {time:.6g} s: {quantity} = {value:.6g}{hint}")


class StepTooSmall(DivergenceError):
    """An error-controlled integrator needed a step below ``simulation.min_step``.

    Attributes:
        time: Time [s] of the step that could not be taken; step: the step [s] it needed;
        min_step: the bound [s]; integrator: its name; mode: the state coordinate that moves most
        in the stiffest mode of the linearization there; omega: that mode's frequency [rad/s];
        object_pose: the object's pose in the state where the step failed [m, rad].
    """

    def __init__(self, time: float, step: float, min_step: float, integrator: str, mode: str, omega: float,
                 object_pose: tuple = ()):
        self.step, self.min_step, self.integrator, self.mode, self.omega = step, min_step, integrator, mode, omega
        self.object_pose = object_pose
        super().__init__(time, "integration step [s]", step)
        fix = ('use simulation.integrator = "trbdf2" (L-stable: stiff modes do not limit its step)'
               if integrator != "trbdf2" else "loosen simulation.rtol / simulation.atol, or stiffen less")
        where = f" with the object at ({', '.join(f'{v:.4g}' for v in object_pose)}) [m, rad]" if object_pose else ""
        self.args = (f"{integrator} needed a step of {step:.3g} s < simulation.min_step = {min_step:.3g} s at t = "
                     f"{time:.6g} s{where}; the stiffest mode there is {mode} at {omega:.4g} rad/s; {fix}",)


def interruption_in(exc: BaseException | None) -> KeyboardInterrupt | None:
    """The ``KeyboardInterrupt`` (Ctrl-C, or SIGTERM turned into one by the command line) that ``exc`` is,
    or that it was raised while handling: a library may wrap it (a compiled extension's ``SystemError``
    "returned a result with an exception set") or fail in its own clean-up ("Can't close the ZIP file" during
    ``np.savez``). None when ``exc`` is an ordinary error."""
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


class MeasurementError(CoopctrlError, ValueError):
    """A measurement given to :meth:`coopctrl.Controller.step` is missing a field, has a field of the wrong
    shape, or holds a value that is not finite.

    Attributes:
        field: The field's name, with its arm or grasp and component (``"q[1][3]"``, ``"wrench[0]"``).
        value: The value received (a shape, or the bad number).
        allowed: What would have been accepted, with its unit.
    """

    def __init__(self, field: str, value, allowed: str):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"measurement.{field} = {value} is invalid: expected {allowed}")
