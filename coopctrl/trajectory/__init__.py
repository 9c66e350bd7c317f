"""Reference trajectories of the object node ``Y_0``: :class:`MinimumJerkTrajectory` (the book's,
coordinate by coordinate) and :class:`GeodesicTrajectory` (the rotation on the rotation group, with an
Euler view for the Euler-based loop)."""

from __future__ import annotations

from coopctrl.trajectory.geodesic_trajectory import (
    EULER_VIEW_MARGIN_DEG,
    QUATERNION_NORM_TOLERANCE,
    EulerViewError,
    GeodesicTrajectory,
    RotationSample,
)
from coopctrl.trajectory.minimum_jerk_trajectory import (
    PEAK_ACCELERATION_FACTOR,
    PEAK_ACCELERATION_TAUS,
    PEAK_VELOCITY_FACTOR,
    POSE_SIZE,
    MinimumJerkTrajectory,
)

__all__ = ["EULER_VIEW_MARGIN_DEG", "EulerViewError", "GeodesicTrajectory", "MinimumJerkTrajectory",
           "PEAK_ACCELERATION_FACTOR", "PEAK_ACCELERATION_TAUS", "PEAK_VELOCITY_FACTOR", "POSE_SIZE",
           "QUATERNION_NORM_TOLERANCE", "RotationSample"]
