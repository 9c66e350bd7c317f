"""``[trajectory]``: the object's nominal motion through via poses, minimum-jerk in between."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import choice, field_scope, instance, number, vector
from coopctrl.scenario.schema import key, limits

#: ``trajectory.orientation``: the book's component-wise ZYX angles, or minimum jerk on the rotation group.
ORIENTATIONS = ("euler", "geodesic")


@dataclass(frozen=True)
class ViaPoint:
    """One via pose of the object MC.

    Attributes:
        time: Time in [s], >= 0.
        pose: Absolute object MC pose (planar ``[x, z, theta]``, spatial
            ``[x, y, z, psi, theta, phi]``) in [m] and [rad].
    """

    time: float = key(unit="s", ge=0, le=1e4, why="as simulation.duration")
    pose: tuple[float, ...] = key(unit="m, rad")

    def __post_init__(self) -> None:
        object.__setattr__(self, "time", number("time", self.time, **limits(self, "time")))
        object.__setattr__(self, "pose", vector("pose", self.pose, lengths=(3, 6), what="a pose, m and rad"))


@dataclass(frozen=True)
class TrajectoryConfig:
    """The nominal object trajectory.

    Attributes:
        via: Via points with strictly increasing times; the first is at time 0 and is the
            initial object pose. Between two vias the motion is minimum-jerk (rest to rest).
        orientation: How the object turns between two vias: ``"geodesic"`` (the shorter rotation about a
            fixed axis, minimum-jerk in its angle: ``coopctrl.trajectory.GeodesicTrajectory``; the via angles
            then only name rotations) or ``"euler"`` (the book's: each ZYX angle minimum-jerk on its own, not
            wrapped). Absent: ``"geodesic"`` when the scene's rotations are in charts, else ``"euler"``. A
            planar rotation is one angle: both move it the same way.
    """

    via: tuple[ViaPoint, ...]
    orientation: str | None = key(None, allowed=ORIENTATIONS)

    def __post_init__(self) -> None:
        if not isinstance(self.via, (list, tuple)) or not self.via:
            raise ScenarioError("via", self.via, "a non-empty list of {time = t, pose = [...]} tables")
        for k, point in enumerate(self.via):
            instance(f"via[{k}]", point, ViaPoint)
        object.__setattr__(self, "via", tuple(self.via))
        if self.orientation is not None:  # None: the scene's (Scenario)
            object.__setattr__(self, "orientation", choice("orientation", self.orientation, ORIENTATIONS))
        if self.via[0].time != 0.0:
            with field_scope("via[0]"):
                raise ScenarioError("time", self.via[0].time, "0 (the first via is the initial pose)")
        for k in range(1, len(self.via)):
            if self.via[k].time <= self.via[k - 1].time:
                with field_scope(f"via[{k}]"):
                    raise ScenarioError("time", self.via[k].time, f"a time > {self.via[k - 1].time} s (strictly increasing)")
        sizes = {len(p.pose) for p in self.via}
        if len(sizes) > 1:
            raise ScenarioError("via", [list(p.pose) for p in self.via], "poses all of the same length")

    @property
    def end_time(self) -> float:
        """Time of the last via [s]."""
        return self.via[-1].time


#: Tolerance [control periods] of :func:`check_segments`: far above the rounding of two via times (1e-16 s
#: relative) and far below any segment a controller could tell from one period.
SEGMENT_TOLERANCE_TICKS = 1e-9


def check_segments(trajectory: TrajectoryConfig, control_period: float) -> None:
    """Refuse a segment shorter than the control period [s] (bad input, naming
    ``trajectory.via[i].time``): a minimum-jerk segment of duration ``T`` between poses ``D`` apart
    peaks at ``(10 / sqrt(3)) |D| / T^2`` (1e18 m/s^2 for 0.3 m in 1 ns); the loop samples it once
    per control period at most, so it cannot be followed, only jumped.

    The comparison is in control periods with a tolerance of :data:`SEGMENT_TOLERANCE_TICKS`: times that
    are whole multiples of the period in decimal (0.008 s and 0.009 s at 1 ms) differ by a binary rounding
    of about 1e-16 s, which must not refuse a segment of exactly one period."""
    for k in range(1, len(trajectory.via)):
        T = trajectory.via[k].time - trajectory.via[k - 1].time
        if T < control_period * (1.0 - SEGMENT_TOLERANCE_TICKS):
            raise ScenarioError(
                f"trajectory.via[{k}].time", trajectory.via[k].time,
                f"a time >= trajectory.via[{k - 1}].time + simulation.control_period = "
                f"{trajectory.via[k - 1].time + control_period:.9g} s (a segment of {T:.3g} s is shorter than the "
                f"control period {control_period:g} s: the controllers cannot follow it)")
