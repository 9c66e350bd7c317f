"""Reference trajectories of the object node ``Y_0``."""

from __future__ import annotations

from coopctrl.trajectory.minimum_jerk_trajectory import (
    PEAK_ACCELERATION_FACTOR,
    PEAK_ACCELERATION_TAUS,
    PEAK_VELOCITY_FACTOR,
    POSE_SIZE,
    MinimumJerkTrajectory,
)

__all__ = ["MinimumJerkTrajectory", "PEAK_ACCELERATION_FACTOR", "PEAK_ACCELERATION_TAUS", "PEAK_VELOCITY_FACTOR", "POSE_SIZE"]
