"""The closed loop's parts grouped by concern, frozen and checked when made: its controllers
(:class:`LoopControllers`), its timing (:class:`LoopTiming`) and its guards (:class:`LoopGuards`).

:func:`coopctrl.simulator.closed_loop` makes them from a scenario's ``[controllers]`` and ``[simulation]`` tables
and hands them to :class:`~coopctrl.closed_loop.ClosedLoop` with the plant, the trajectory, the grasps, the load
distribution and the sensors.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import coopctrl.arguments as arguments


@dataclass(frozen=True)
class LoopControllers:
    """The loop's controllers.

    Attributes:
        leader: The leader's controller (:class:`~coopctrl.controllers.LeaderController`, or a tuning probe).
        followers: Arm index -> the follower's controller (:class:`~coopctrl.controllers.FollowerForceController`,
            or a tuning probe); read-only.
        compliance: The grasp compliance the leader's and the followers' targets use
            (:class:`~coopctrl.controllers.GraspCompliance`).
        leader_law: The leader node's law (:class:`~coopctrl.controllers.leader_law.LeaderLaw`), or None: the
            computed torque with the leader's gains.
        follower_law: The followers' nodes' law, or None: their computed torque with the followers' gains.
        enabled: False: a passive run (no QP, no controllers, zero torques).
    """

    leader: Any
    followers: Mapping[int, Any]
    compliance: Any
    leader_law: Any = None
    follower_law: Any = None
    enabled: bool = True

    def __post_init__(self):
        from coopctrl.controllers.leader_law import LeaderLaw

        if not isinstance(self.followers, Mapping):
            raise arguments.invalid("followers", self.followers, "a mapping arm index -> follower controller",
                                    TypeError)
        object.__setattr__(self, "followers", MappingProxyType(dict(self.followers)))
        for name in ("leader_law", "follower_law"):
            law = getattr(self, name)
            if law is not None and not isinstance(law, LeaderLaw):
                raise TypeError(f"{name} = {law!r}: expected a coopctrl.controllers.leader_law.LeaderLaw "
                                "(e.g. object_impedance(...)) or None (the node's computed torque)")
        object.__setattr__(self, "enabled", arguments.flag("enabled", self.enabled))


@dataclass(frozen=True)
class LoopTiming:
    """When the controller runs and how the plant is integrated between its ticks.

    Attributes:
        integrator: The plant's integrator (:class:`~coopctrl.integrators.Integrator`: ``step(f, t, x, u, h)``).
        control_period: The controller's period ``T`` [s], > 0.
        substeps: Integration steps per period, ``h = T / substeps`` (an integer >= 1).
        step: A free plant step ``0 < h <= T`` [s] instead of ``T / substeps``
            (:meth:`~coopctrl.closed_loop.ClosedLoop.set_step`), or None.
    """

    integrator: Any
    control_period: float
    substeps: int = 1
    step: float | None = None

    def __post_init__(self):
        if not callable(getattr(self.integrator, "step", None)):
            raise arguments.invalid("integrator", self.integrator, "an integrator with step(f, t, x, u, h)", TypeError)
        object.__setattr__(self, "control_period",
                           arguments.number("control_period", self.control_period, positive=True, unit="s"))
        if isinstance(self.substeps, bool) or not isinstance(self.substeps, numbers.Integral) or self.substeps < 1:
            raise arguments.invalid("substeps", self.substeps, "an integer >= 1 (integration steps per period)")
        object.__setattr__(self, "substeps", int(self.substeps))
        if self.step is not None:
            object.__setattr__(self, "step", arguments.number("step", self.step, positive=True, unit="s"))


@dataclass(frozen=True)
class LoopGuards:
    """The bounds that stop a diverging run.

    Attributes:
        max_deformation: The largest displacement of a contact node from its rigid place on the object [m], > 0.
        max_energy: The largest total energy [J], or None: no bound.
    """

    max_deformation: float
    max_energy: float | None = field(default=None)

    def __post_init__(self):
        object.__setattr__(self, "max_deformation",
                           arguments.number("max_deformation", self.max_deformation, positive=True, finite=False,
                                            unit="m"))
        if self.max_energy is not None:
            object.__setattr__(self, "max_energy",
                               arguments.number("max_energy", self.max_energy, positive=True, finite=False, unit="J"))


__all__ = ["LoopControllers", "LoopGuards", "LoopTiming"]
