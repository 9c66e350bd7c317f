"""Errors of the tuning tools, in the :class:`~coopctrl.errors.CoopctrlError` tree."""

from __future__ import annotations

from coopctrl.errors import CoopctrlError


class TuningError(CoopctrlError, ValueError):
    """An argument of a tuning tool is invalid (the message names it, its value and what is allowed).

    Attributes:
        name: The argument.
        value: The value received.
        allowed: What would have been accepted.
    """

    def __init__(self, name: str, value, allowed: str):
        self.name = name
        self.value = value
        self.allowed = allowed
        super().__init__(f"{name} = {value!r} is invalid: expected {allowed}")


class UnachievableDesign(CoopctrlError, ValueError):
    """A gain design cannot meet its targets on the linear model.

    Attributes:
        target: The requested specification, e.g. ``{"bandwidth_rad_s": 300.0, "phase_margin_deg": 60.0}``.
        reason: Why, and what to change.
        closest: The closest specification reached (same keys), or ``None`` if none was computed.
    """

    def __init__(self, target: dict, reason: str, closest: dict | None = None):
        self.target = dict(target)
        self.reason = reason
        self.closest = None if closest is None else dict(closest)
        spec = ", ".join(f"{k} = {v:.4g}" for k, v in self.target.items())
        near = ""
        if self.closest:
            near = " (closest reached: " + ", ".join(f"{k} = {v:.4g}" for k, v in self.closest.items()) + ")"
        super().__init__(f"cannot reach {spec}: {reason}{near}")


class NoOperatingPoint(CoopctrlError, ArithmeticError):
    """The closed loop has no equilibrium near the scene's initial state to linearize about.

    Attributes:
        residual: The norm of the equilibrium equations at the last iterate.
    """

    def __init__(self, scenario: str, residual: float, detail: str = ""):
        self.residual = residual
        super().__init__(
            f"{scenario}: no closed-loop equilibrium holding the initial pose was found (residual {residual:.3g})"
            f"{': ' + detail if detail else ''}; check that `coopctrl run` holds the scene at rest "
            "(e.g. with a trajectory of one via point)")
