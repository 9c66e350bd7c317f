"""``[controllers]``: gains of the leader and of the followers (docs/model.md §6)."""

from __future__ import annotations

from dataclasses import dataclass, field

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import boolean, instance, number
from coopctrl.scenario.schema import key, limits


@dataclass(frozen=True)
class LeaderControllerConfig:
    """``[controllers.leader]``: computed torque on the full model.

    Attributes:
        natural_frequency: Closed-loop natural frequency of the tracking error in [rad/s].
        damping_ratio: Closed-loop damping ratio [-].
    """

    natural_frequency: float = key(30.0, unit="rad/s", gt=0, le=1e5, why="1e5 rad/s (16 kHz) is beyond any motion loop; the gain wn^2 stays far from overflow (1e300 overflowed)")
    damping_ratio: float = key(1.0, gt=0, le=100.0, why="beyond 100 the loop is a pure damper")

    def __post_init__(self) -> None:
        object.__setattr__(self, "natural_frequency", number("natural_frequency", self.natural_frequency, **limits(self, "natural_frequency")))
        object.__setattr__(self, "damping_ratio", number("damping_ratio", self.damping_ratio, **limits(self, "damping_ratio")))


@dataclass(frozen=True)
class FollowerControllerConfig:
    """``[controllers.followers]``: elastic-force regulation around a motion loop.

    Attributes:
        force_loop: Close the force loop (``false`` = motion loop only, on the nominal poses).
        force_kp: Proportional gain of the force loop [-] (>= 0).
        force_ki: Integral gain of the force loop in [1/s] (>= 0).
        natural_frequency: Natural frequency of the inner motion loop in [rad/s].
        damping_ratio: Damping ratio of the inner motion loop [-].
    """

    force_loop: bool = True
    force_kp: float = key(0.5, ge=0, le=1e3, why="a force gain of 1000 turns 1 mN of error into a 1 N correction each period")
    force_ki: float = key(10.0, unit="1/s", ge=0, le=1e6, why="an integral time constant of at least 1 us")
    natural_frequency: float = key(30.0, unit="rad/s", gt=0, le=1e5, why="1e5 rad/s (16 kHz) is beyond any motion loop; the gain wn^2 stays far from overflow (1e300 overflowed)")
    damping_ratio: float = key(1.0, gt=0, le=100.0, why="beyond 100 the loop is a pure damper")

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "force_loop", boolean("force_loop", self.force_loop))
        s(self, "force_kp", number("force_kp", self.force_kp, **limits(self, "force_kp")))
        s(self, "force_ki", number("force_ki", self.force_ki, **limits(self, "force_ki")))
        s(self, "natural_frequency", number("natural_frequency", self.natural_frequency, **limits(self, "natural_frequency")))
        s(self, "damping_ratio", number("damping_ratio", self.damping_ratio, **limits(self, "damping_ratio")))


@dataclass(frozen=True)
class ControllersConfig:
    """``[controllers]``: the leader's and the followers' controllers.

    Attributes:
        enabled: ``false`` runs the plant without control (zero torques, no QP): a passive
            run, whose energy drift is reported when nothing dissipates (no spring damping).
    """

    leader: LeaderControllerConfig = field(default_factory=LeaderControllerConfig)
    followers: FollowerControllerConfig = field(default_factory=FollowerControllerConfig)
    enabled: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.enabled, bool):
            raise ScenarioError("enabled", self.enabled, "true or false")
        instance("leader", self.leader, LeaderControllerConfig)
        instance("followers", self.followers, FollowerControllerConfig)
