"""Errors raised by the physics package.

Every error subclasses :class:`PlantError` and the builtin it specialises, so callers can
catch either. Each carries the data needed to act on it as attributes, and its message says
how to fix the problem.
"""

from __future__ import annotations


class PlantError(Exception):
    """Base class of every error raised by :mod:`plants`."""


class ParameterError(PlantError, ValueError):
    """A physical parameter is invalid.

    Attributes:
        parameter: Dotted name of the offending parameter (``"nodes[2].mass"``).
        value: The value received.
        allowed: What would have been accepted.
    """

    def __init__(self, parameter: str, value, allowed: str):
        self.parameter = parameter
        self.value = value
        self.allowed = allowed
        super().__init__(f"{parameter} = {value!r} is invalid: expected {allowed}")


class EulerSingularityError(PlantError, ArithmeticError):
    """A ZYX Euler-angle map was evaluated where ``cos(theta)`` is (almost) zero.

    The body-rate map ``L(A)`` of docs/model.md section 2 is singular at ``theta = +-pi/2``; the
    Euler-angle coordinates cannot represent angular velocity there.

    Attributes:
        where: Which node or arm tip hit the singularity.
        theta: The pitch angle in [rad].
        cos_theta: ``cos(theta)``.
    """

    def __init__(self, where: str, theta: float, cos_theta: float):
        self.where = where
        self.theta = theta
        self.cos_theta = cos_theta
        super().__init__(
            f"Euler-angle singularity at {where}: theta = {theta:.6f} rad, cos(theta) = "
            f"{cos_theta:.2e}; the ZYX body-rate map L(A) is singular at theta = +-pi/2. "
            "Re-orient the node frame (grasp or object frame) so that its pitch stays away "
            "from +-90 deg"
        )


class UnreachablePoseError(PlantError, ValueError):
    """Inverse kinematics found no joint vector reaching a pose.

    Attributes:
        arm: Name of the arm.
        target: The requested pose ``Y`` (position [m], ZYX Euler angles [rad]).
        residual: Norm of the remaining pose error.
    """

    def __init__(self, arm: str, target, residual: float, hint: str = ""):
        self.arm = arm
        self.target = target
        self.residual = residual
        super().__init__(
            f"pose {list(map(float, target))} is out of reach of arm '{arm}' "
            f"(best residual {residual:.3g}); {hint or 'move the grasp or the arm base closer'}"
        )


class SingularJacobianError(PlantError, ArithmeticError):
    """A Jacobian or mass matrix that must be invertible is singular.

    Attributes:
        where: What was being inverted.
        condition: Its condition number estimate (``inf`` if exactly singular).
    """

    def __init__(self, where: str, condition: float):
        self.where = where
        self.condition = condition
        super().__init__(
            f"{where} is singular (condition number {condition:.3g}); move away from the "
            "kinematic singularity or change the configuration"
        )
