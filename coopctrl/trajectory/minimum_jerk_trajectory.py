"""Piecewise minimum-jerk (quintic, rest-to-rest) trajectory through via poses."""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np

from coopctrl.errors import ScenarioError

#: Pose size per space: spatial ``[x, y, z, psi, theta, phi]``, planar ``[x, z, theta]``.
POSE_SIZE = {"spatial": 6, "planar": 3}

#: Peak of ``ds/dtau`` of the minimum-jerk profile, reached at ``tau = 1/2`` [-].
PEAK_VELOCITY_FACTOR = 1.875
#: Peak of ``|d^2 s/dtau^2|`` of the minimum-jerk profile, ``10 / sqrt(3)`` [-], reached at the
#: instants :data:`PEAK_ACCELERATION_TAUS` (where ``d^3 s/dtau^3 = 60 - 360 tau + 360 tau^2 = 0``).
PEAK_ACCELERATION_FACTOR = 10.0 / math.sqrt(3.0)
#: ``tau = (3 -+ sqrt(3)) / 6`` of a segment: its acceleration and deceleration peaks [-].
PEAK_ACCELERATION_TAUS = ((3.0 - math.sqrt(3.0)) / 6.0, (3.0 + math.sqrt(3.0)) / 6.0)


def checked_times(value) -> np.ndarray:
    """The via-point times [s] of a trajectory, validated: a non-empty 1-D array of finite, strictly
    increasing times starting at 0 (a copy).

    Raises:
        ScenarioError: naming the field (``times``, ``times[2]``), the value and what is allowed.
    """
    try:
        times = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ScenarioError("times", value, "a 1-D sequence of numbers [s]") from None
    if times.ndim != 1 or times.shape[0] < 1:
        raise ScenarioError("times", f"<array of shape {times.shape}>", "a non-empty 1-D array [s]")
    bad = np.flatnonzero(~np.isfinite(times))
    if bad.size:
        raise ScenarioError(f"times[{bad[0]}]", float(times[bad[0]]), "a finite time [s]")
    if times[0] != 0.0:
        raise ScenarioError("times[0]", float(times[0]), "0.0 (the trajectory starts at t = 0 s)")
    bad = np.flatnonzero(np.diff(times) <= 0.0)
    if bad.size:
        i = int(bad[0]) + 1
        raise ScenarioError(f"times[{i}]", float(times[i]),
                            f"strictly increasing times: > times[{i - 1}] = {times[i - 1]!r}")
    return times


@dataclass(frozen=True, eq=False)
class MinimumJerkTrajectory:
    """Rest-to-rest quintic segments through via poses, component-wise on the pose coordinates.

    On segment ``i`` (``t_i <= t <= t_{i+1}``, ``T_i = t_{i+1} - t_i``, ``tau = (t - t_i) / T_i``):

    .. math::

        Y(t) = Y_i + (Y_{i+1} - Y_i)\\, s(\\tau), \\qquad
        s(\\tau) = 10 \\tau^3 - 15 \\tau^4 + 6 \\tau^5

    so velocity and acceleration are zero at every via point. The peaks of a segment are closed
    form (:meth:`peaks`): velocity ``1.875 |Y_{i+1} - Y_i| / T_i`` at its middle, acceleration
    ``(10 / sqrt(3)) |Y_{i+1} - Y_i| / T_i^2`` at ``tau = (3 -+ sqrt(3)) / 6``. Each coordinate (positions in
    [m], Euler angles ZYX ``(psi, theta, phi)`` in [rad], docs/model.md s.2) is interpolated
    separately; the angles are not wrapped (the path follows the numerical difference of the
    given angles). Before ``t = 0`` the first pose is held, after :attr:`duration` the last one,
    both with zero velocity and acceleration. :class:`~coopctrl.trajectory.GeodesicTrajectory` turns
    the object on the rotation group instead (the shorter rotation about a fixed axis, through pitch
    +-90 deg too), with the same interface as an Euler view.

    Args:
        times: Via-point times [s], shape ``(k,)``, strictly increasing, ``times[0] = 0``.
        poses: Via poses, shape ``(k, 6)`` (``space="spatial"``: ``[x, y, z, psi, theta, phi]``)
            or ``(k, 3)`` (``space="planar"``: ``[x, z, theta]``); finite.
        space: ``"spatial"`` or ``"planar"``.

    Raises:
        ScenarioError: (a ``ValueError``) naming the field (``times``, ``poses[2, 4]``, ``space``).
    """

    times: np.ndarray
    poses: np.ndarray
    space: str
    _times_list: list = field(init=False, repr=False)
    _base: np.ndarray = field(init=False, repr=False)
    _delta: np.ndarray = field(init=False, repr=False)
    _inv_T: tuple = field(init=False, repr=False)
    _end: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        if self.space not in POSE_SIZE:
            raise ScenarioError("space", self.space, "'spatial' or 'planar'")
        size = POSE_SIZE[self.space]
        times = checked_times(self.times)
        try:
            poses = np.array(self.poses, dtype=float)
        except (TypeError, ValueError):
            raise ScenarioError("poses", self.poses, f"a ({times.shape[0]}, {size}) array") from None
        if poses.shape != (times.shape[0], size):
            raise ScenarioError(
                "poses", f"<array of shape {poses.shape}>",
                f"shape ({times.shape[0]}, {size}) for space '{self.space}' and {times.shape[0]} times",
            )
        bad = np.argwhere(~np.isfinite(poses))
        if bad.size:
            i, j = (int(v) for v in bad[0])
            raise ScenarioError(f"poses[{i}, {j}]", float(poses[i, j]), "a finite coordinate")
        times.flags.writeable = False
        poses.flags.writeable = False
        set_ = object.__setattr__
        set_(self, "times", times)
        set_(self, "poses", poses)
        set_(self, "_times_list", times.tolist())
        k = times.shape[0]
        # Rows [Y, dY, ddY] of each segment = base + delta * [s, s'/T, s''/T^2].
        base = np.zeros((max(k - 1, 1), 3, size))
        delta = np.zeros((max(k - 1, 1), 1, size))
        if k > 1:
            base[:, 0, :] = poses[:-1]
            delta[:, 0, :] = poses[1:] - poses[:-1]
        else:
            base[0, 0, :] = poses[0]
        set_(self, "_base", base)
        set_(self, "_delta", delta)
        set_(self, "_inv_T", tuple((1.0 / np.diff(times)).tolist()) if k > 1 else (0.0,))
        end = np.zeros((3, size))
        end[0] = poses[-1]
        set_(self, "_end", end)

    @property
    def duration(self) -> float:
        """Time of the last via pose [s]."""
        return self._times_list[-1]

    @property
    def pose_size(self) -> int:
        """6 (spatial) or 3 (planar)."""
        return self.poses.shape[1]

    def peaks(self) -> tuple[np.ndarray, np.ndarray]:
        """Closed-form peak speed and acceleration of every segment, per pose coordinate.

        Returns:
            ``(v_peak, a_peak)``, each of shape ``(segments, pose_size)``:
            ``v_peak = 1.875 |Y_{i+1} - Y_i| / T_i`` [m/s, rad/s] and
            ``a_peak = (10 / sqrt(3)) |Y_{i+1} - Y_i| / T_i^2`` [m/s^2, rad/s^2] (no segment: empty).
        """
        if self.times.shape[0] < 2:
            empty = np.zeros((0, self.pose_size))
            return empty, empty.copy()
        delta = np.abs(np.diff(self.poses, axis=0))
        T = np.diff(self.times)[:, None]
        return PEAK_VELOCITY_FACTOR * delta / T, PEAK_ACCELERATION_FACTOR * delta / T**2

    def peak_times(self) -> np.ndarray:
        """The instants [s] of every segment's closed-form acceleration peaks (``tau = (3 -+ sqrt(3)) / 6``)
        and speed peak (``tau = 1/2``), sorted: where a check sampled on a grid could miss the extremes
        of a short segment."""
        if self.times.shape[0] < 2:
            return np.zeros(0)
        t0, T = self.times[:-1], np.diff(self.times)
        taus = np.array([PEAK_ACCELERATION_TAUS[0], 0.5, PEAK_ACCELERATION_TAUS[1]])
        return np.sort((t0[:, None] + T[:, None] * taus[None, :]).reshape(-1))

    def evaluate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose, velocity and acceleration at time ``t`` [s].

        Returns:
            ``(Y, dY, ddY)``: new arrays of the pose size, in [m, rad], [m/s, rad/s],
            [m/s^2, rad/s^2].
        """
        times = self._times_list
        if t >= times[-1]:
            out = self._end.copy()
        elif t > 0.0:
            i = bisect.bisect_right(times, t) - 1
            inv_T = self._inv_T[i]
            tau = (t - times[i]) * inv_T
            tau2 = tau * tau
            out = self._delta[i] * np.array((
                tau2 * tau * (10.0 + tau * (-15.0 + 6.0 * tau)),
                tau2 * (30.0 + tau * (-60.0 + 30.0 * tau)) * inv_T,
                tau * (60.0 + tau * (-180.0 + 120.0 * tau)) * inv_T * inv_T,
            ))[:, None]
            out += self._base[i]
        elif t <= 0.0:
            out = self._base[0].copy()
        else:
            raise ValueError(f"t = {t!r} is invalid: expected a finite time [s]")
        return out[0], out[1], out[2]

    def sample(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Vectorised :meth:`evaluate` on an array of times ``t`` [s] of shape ``(N,)``.

        Returns:
            ``(Y, dY, ddY)``, each of shape ``(N, pose_size)``.
        """
        t = np.asarray(t, dtype=float)
        if t.ndim != 1:
            raise ValueError(f"t has shape {t.shape}: expected a 1-D array of times [s]")
        if not np.isfinite(t).all():
            raise ValueError("t contains non-finite times: expected finite times [s]")
        times = self.times
        size = self.pose_size
        if times.shape[0] == 1:
            Y = np.broadcast_to(self.poses[0], (t.shape[0], size)).copy()
            return Y, np.zeros_like(Y), np.zeros_like(Y)
        i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.shape[0] - 2)
        inv_T = np.asarray(self._inv_T)[i]
        tau = np.clip((t - times[i]) * inv_T, 0.0, 1.0)
        s = tau**3 * (10.0 + tau * (-15.0 + 6.0 * tau))
        ds = tau**2 * (30.0 + tau * (-60.0 + 30.0 * tau)) * inv_T
        dds = tau * (60.0 + tau * (-180.0 + 120.0 * tau)) * inv_T**2
        delta = self._delta[i, 0]
        return self.poses[i] + delta * s[:, None], delta * ds[:, None], delta * dds[:, None]
