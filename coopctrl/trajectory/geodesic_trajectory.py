"""Piecewise minimum-jerk trajectory whose orientation moves on the rotation group (no Euler singularity)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from coopctrl.errors import ScenarioError
from coopctrl.trajectory import quaternion as quat
from coopctrl.trajectory.minimum_jerk_trajectory import (
    PEAK_ACCELERATION_FACTOR,
    PEAK_ACCELERATION_TAUS,
    PEAK_VELOCITY_FACTOR,
    checked_times,
)

#: Distance [deg] from pitch +-90 deg inside which the Euler view is refused (the loop's band,
#: ``coopctrl.loop.euler_band.EULER_PITCH_MARGIN_DEG``).
EULER_VIEW_MARGIN_DEG = 5.0
#: A quaternion via pose whose norm differs from 1 by more than this [-] is refused; within it, it is
#: normalized (rounding of printed quaternions is ~1e-9 at 9 digits; a larger error is a wrong pose).
QUATERNION_NORM_TOLERANCE = 1e-6
#: Via-pose row lengths: ``[x, y, z, psi, theta, phi]`` (ZYX Euler) or ``[x, y, z, w, qx, qy, qz]``.
EULER_ROW, QUATERNION_ROW = 6, 7
#: Table points per segment tracking the continuous branch of the Euler view: the rotation between
#: two is at most ``1.875 pi / 1024`` rad (0.33 deg), and the pitch moves no more than the rotation.
_TABLE = 1024


class EulerViewError(ValueError):
    """The Euler view of a :class:`GeodesicTrajectory` was asked for inside the band around pitch +-90 deg.

    Attributes:
        time: The first such time [s].
        pitch_deg: The ZYX pitch there [deg] (principal, in [-90, 90]).
    """

    def __init__(self, time: float, pitch_deg: float):
        self.time, self.pitch_deg = time, pitch_deg
        super().__init__(
            f"the Euler view of the geodesic trajectory is undefined at t = {time:.6g} s: its ZYX pitch "
            f"{pitch_deg:.3f} deg is within {EULER_VIEW_MARGIN_DEG:g} deg of +-90 deg, where L(A) is singular; read "
            "the rotation with sample_rotation(t) (quaternion and angular velocity), or keep the path's pitch "
            f"below {90.0 - EULER_VIEW_MARGIN_DEG:g} deg to run it in Euler coordinates")


class RotationSample(NamedTuple):
    """The motion of :meth:`GeodesicTrajectory.sample_rotation`, each row one time (shape ``(N, 3)`` or ``(N, 4)``).

    Attributes:
        r, dr, ddr: Position [m], velocity [m/s], acceleration [m/s^2], world axes.
        q: Unit quaternion ``(w, x, y, z)`` of the body frame in the world (sign continuous in time).
        omega, alpha: Angular velocity [rad/s] and acceleration [rad/s^2], world axes.
        omega_body, alpha_body: The same in the body axes of ``R(t)`` (``omega = R(t) omega_body``).
    """

    r: np.ndarray
    dr: np.ndarray
    ddr: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    omega_body: np.ndarray
    alpha_body: np.ndarray


def _profile(tau, inv_T):
    """``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5`` and its time derivatives ``s' = ds/dtau / T``,
    ``s'' = d^2s/dtau^2 / T^2`` [1/s, 1/s^2] (``inv_T = 1 / T``)."""
    s = tau**3 * (10.0 + tau * (-15.0 + 6.0 * tau))
    ds = tau**2 * (30.0 + tau * (-60.0 + 30.0 * tau)) * inv_T
    dds = tau * (60.0 + tau * (-180.0 + 120.0 * tau)) * inv_T**2
    return s, ds, dds


def _nearest(a, ref):
    """:func:`quaternion.nearest_zyx` for one triple (plain floats: the table is tracked point by point):
    of ``a`` and ``(a_0 + pi, pi - a_1, a_2 + pi)``, each shifted by the whole turns nearest ``ref``, the
    closer to ``ref``."""
    two_pi = 2.0 * math.pi
    r0, r1, r2 = ref
    best, best_d = None, math.inf
    for x0, x1, x2 in ((a[0], a[1], a[2]), (a[0] + math.pi, math.pi - a[1], a[2] + math.pi)):
        x0 += two_pi * round((r0 - x0) / two_pi)
        x1 += two_pi * round((r1 - x1) / two_pi)
        x2 += two_pi * round((r2 - x2) / two_pi)
        d = (x0 - r0) ** 2 + (x1 - r1) ** 2 + (x2 - r2) ** 2
        if d < best_d:
            best, best_d = (x0, x1, x2), d
    return best


@dataclass(frozen=True, eq=False)
class GeodesicTrajectory:
    """Rest-to-rest minimum-jerk segments through via poses: positions component-wise, rotations on
    the geodesic of the rotation group.

    On segment ``i`` (``t_i <= t <= t_{i+1}``, ``T_i = t_{i+1} - t_i``, ``tau = (t - t_i) / T_i``,
    ``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5`` as :class:`MinimumJerkTrajectory`):

    .. math::

        r(t) = r_i + (r_{i+1} - r_i)\\, s, \\qquad
        R(t) = R_i \\exp(s\\, [\\phi_i]_\\times), \\qquad \\phi_i = \\log(R_i^T R_{i+1}),\\ |\\phi_i| \\le \\pi

    ``phi_i`` [rad] is the rotation vector of the relative rotation in ``R_i``'s axes
    (:attr:`rotation_vectors`). Because ``exp(s [phi]) phi = phi``, the axis is fixed both in the body
    and in the world, and with ``s' = ds/dt``, ``s'' = d^2s/dt^2``:

    .. math::

        \\omega_b = R^T \\dot R^\\vee = \\dot s\\, \\phi_i, \\quad \\alpha_b = \\ddot s\\, \\phi_i, \\qquad
        \\omega = R(t)\\, \\omega_b = \\dot s\\, R_i \\phi_i, \\quad \\alpha = \\ddot s\\, R_i \\phi_i

    (body components in the axes of ``R(t)``, the same numbers as in ``R_i``'s axes; world ones fixed
    in direction; ``d/dt`` of the body components is the body component of ``d omega / dt`` since
    ``omega x omega = 0``). Rates and accelerations vanish at every via (rest to rest), before
    ``t = 0`` (first pose held) and after :attr:`duration` (last pose held). A relative rotation of
    ``pi`` (within ``2e-12`` rad) has two geodesics: the one whose axis has its largest component
    positive is taken (:func:`quaternion.shortest`); a zero rotation stays still (``log`` and ``exp``
    are exact there).

    **Euler view** (:meth:`sample`, :meth:`evaluate`, the interface of :class:`MinimumJerkTrajectory`):
    ``Y = (r, A)`` with the book's ZYX angles ``A = (psi, theta, phi)`` of ``R(t)``,
    ``dA = L(A)^-1 omega_b`` and ``ddA = L(A)^-1 (alpha_b - dL(A, dA) dA)`` (plants.frames). ``A`` is the
    continuous branch starting at the first via's angles (as written, when written as angles), so a
    later via's angles may differ from the written ones by whole turns, or be the other family
    ``(psi + pi, pi - theta, phi + pi)``. The branch is tracked at construction on 1025 points of each
    segment (each the representative nearest the previous one); at a time ``t`` the angles of ``R(t)``
    are the representative nearest the tracked ones interpolated to ``t``, so they are exact and
    continuous wherever the view exists (past the band, the family the tracking reached). Inside
    :data:`EULER_VIEW_MARGIN_DEG` of pitch +-90 deg the view does not exist and raises
    :class:`EulerViewError` (:meth:`euler_band_entry` finds where a path enters).

    Args:
        times: Via times [s], shape ``(k,)``, strictly increasing, ``times[0] = 0``.
        poses: ``k`` via poses, each ``[x, y, z, psi, theta, phi]`` (m, ZYX Euler angles in rad) or
            ``[x, y, z, w, qx, qy, qz]`` (m, unit quaternion); the two forms may be mixed. A quaternion
            is normalized if its norm is within :data:`QUATERNION_NORM_TOLERANCE` of 1, else refused.
            Stored as the Euler form ``(k, 6)`` (a quaternion's principal angles).
        space: ``"spatial"`` (a planar rotation is one angle: :class:`MinimumJerkTrajectory` moves it
            on its geodesic already).

    Attributes:
        positions: ``(k, 3)`` via positions [m].
        quaternions: ``(k, 4)`` unit via quaternions ``(w, x, y, z)``, each signed as the previous
            segment ends (``q_i exp(phi_i)``), so that :meth:`sample_rotation` is continuous in sign.
        rotation_vectors: ``(segments, 3)`` the ``phi_i`` [rad], in ``R_i``'s axes.

    Raises:
        ScenarioError: (a ``ValueError``) naming the field (``times[2]``, ``poses[1]``, ``space``).
    """

    times: np.ndarray
    poses: np.ndarray
    space: str = "spatial"
    positions: np.ndarray = field(init=False, repr=False)
    quaternions: np.ndarray = field(init=False, repr=False)
    rotation_vectors: np.ndarray = field(init=False, repr=False)
    _times_list: list = field(init=False, repr=False)
    _inv_T: np.ndarray = field(init=False, repr=False)
    _dr: np.ndarray = field(init=False, repr=False)
    _phi: np.ndarray = field(init=False, repr=False)
    _phi_world: np.ndarray = field(init=False, repr=False)
    _table: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        if self.space != "spatial":
            raise ScenarioError("space", self.space, "'spatial' (a planar rotation is one angle: "
                                "MinimumJerkTrajectory interpolates it on its geodesic already)")
        times = checked_times(self.times)
        rows = _rows(self.poses, times.shape[0])
        k = times.shape[0]
        positions = np.array([row[:3] for row in rows])
        q = np.array([quat.from_zyx(row[3:]) if row.size == EULER_ROW else row[3:] for row in rows])
        phi = np.zeros((max(k - 1, 1), 3))
        for j in range(k - 1):  # the shorter way; then q[j + 1] signed as q[j] exp(phi_j) ends (q, -q: one rotation)
            phi[j] = quat.log(quat.shortest(quat.multiply(quat.conjugate(q[j]), q[j + 1])))
            if np.dot(quat.multiply(q[j], quat.exp(phi[j])), q[j + 1]) < 0.0:
                q[j + 1] = -q[j + 1]
        euler = np.array([row[3:] if row.size == EULER_ROW else quat.to_zyx(row[3:])[0] for row in rows])
        set_ = object.__setattr__
        for name, value in (("times", times), ("poses", np.hstack((positions, euler))), ("positions", positions),
                            ("quaternions", q), ("rotation_vectors", phi[: k - 1])):
            value.flags.writeable = False
            set_(self, name, value)
        set_(self, "_times_list", times.tolist())
        set_(self, "_inv_T", 1.0 / np.diff(times) if k > 1 else np.zeros(1))
        set_(self, "_dr", np.diff(positions, axis=0) if k > 1 else np.zeros((1, 3)))
        set_(self, "_phi", phi)
        set_(self, "_phi_world", quat.rotate(q[: phi.shape[0]], phi))
        set_(self, "_table", self._euler_table(q, phi, euler[0]))

    def _euler_table(self, q, phi, start) -> np.ndarray:
        """``(segments, _TABLE + 1, 3)`` ZYX angles on ``tau = j / _TABLE``, each the representative
        (:func:`quaternion.nearest_zyx`) closest to the previous one, from the first via's ``start``."""
        tau = np.linspace(0.0, 1.0, _TABLE + 1)
        s = _profile(tau, 0.0)[0]
        table = np.empty((phi.shape[0], tau.size, 3))
        ref = tuple(start)
        for i in range(phi.shape[0]):
            principal = quat.to_zyx(quat.multiply(q[i], quat.exp(s[:, None] * phi[i])))[0].tolist()
            for j, a in enumerate(principal):
                ref = table[i, j] = _nearest(a, ref)
        return table

    @property
    def duration(self) -> float:
        """Time of the last via pose [s]."""
        return self._times_list[-1]

    @property
    def pose_size(self) -> int:
        """6: the Euler view ``[x, y, z, psi, theta, phi]``."""
        return 6

    def peaks(self) -> tuple[np.ndarray, np.ndarray]:
        """Closed-form peak speed and acceleration of every segment, shape ``(segments, 6)`` each.

        Columns 0-2: ``1.875 |r_{i+1} - r_i| / T_i`` [m/s] and ``(10 / sqrt(3)) |r_{i+1} - r_i| / T_i^2`` [m/s^2],
        per axis. Columns 3-5: the body angular velocity ``1.875 |phi_i| / T_i`` [rad/s] and acceleration
        ``(10 / sqrt(3)) |phi_i| / T_i^2`` [rad/s^2] per body axis (their norms are those of ``phi_i``); at the
        instants of :meth:`peak_times`. Not the Euler rates: those have no closed form (``L^-1`` grows like
        ``1 / cos(theta)``).
        """
        if self.times.shape[0] < 2:
            empty = np.zeros((0, 6))
            return empty, empty.copy()
        delta = np.abs(np.hstack((self._dr, self.rotation_vectors)))
        T = np.diff(self.times)[:, None]
        return PEAK_VELOCITY_FACTOR * delta / T, PEAK_ACCELERATION_FACTOR * delta / T**2

    def peak_times(self) -> np.ndarray:
        """The instants [s] of every segment's speed peak (``tau = 1/2``) and acceleration peaks
        (``tau = (3 -+ sqrt(3)) / 6``), sorted: the same for position and rotation (both scale ``s``)."""
        if self.times.shape[0] < 2:
            return np.zeros(0)
        t0, T = self.times[:-1], np.diff(self.times)
        taus = np.array([PEAK_ACCELERATION_TAUS[0], 0.5, PEAK_ACCELERATION_TAUS[1]])
        return np.sort((t0[:, None] + T[:, None] * taus[None, :]).reshape(-1))

    def _motion(self, t):
        """Segment index and ``tau`` of the times ``t`` [s] (held before 0 and after the end), and the
        :class:`RotationSample` there (the class formulas)."""
        t = np.asarray(t, dtype=float)
        if t.ndim != 1:
            raise ValueError(f"t has shape {t.shape}: expected a 1-D array of times [s]")
        if not np.isfinite(t).all():
            raise ValueError("t contains non-finite times: expected finite times [s]")
        i = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, self._inv_T.shape[0] - 1)
        inv_T = self._inv_T[i]
        tau = np.clip((t - self.times[i]) * inv_T, 0.0, 1.0)
        s, ds, dds = (v[:, None] for v in _profile(tau, inv_T))
        phi, phi_w, dr = self._phi[i], self._phi_world[i], self._dr[i]
        q = quat.multiply(self.quaternions[i], quat.exp(s * phi))
        return i, tau, RotationSample(self.positions[i] + s * dr, ds * dr, dds * dr, q,
                                      ds * phi_w, dds * phi_w, ds * phi, dds * phi)

    def sample_rotation(self, t) -> RotationSample:
        """Position, quaternion and their rates at the times ``t`` [s] (shape ``(N,)``): the class
        formulas; defined everywhere, through pitch +-90 deg too."""
        return self._motion(t)[2]

    def sample(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The Euler view ``(Y, dY, ddY)`` at the times ``t`` [s], each of shape ``(N, 6)``
        ([m, rad], [m/s, rad/s], [m/s^2, rad/s^2]), as :meth:`MinimumJerkTrajectory.sample`.

        Raises:
            EulerViewError: at the earliest of the times inside the band (class docstring).
        """
        i, tau, m = self._motion(t)
        principal, cos_theta = quat.to_zyx(m.q)
        inside = np.flatnonzero(cos_theta < math.sin(math.radians(EULER_VIEW_MARGIN_DEG)))
        if inside.size:
            times = np.asarray(t, dtype=float)
            k = int(inside[np.argmin(times[inside])])
            raise EulerViewError(float(times[k]), math.degrees(principal[k, 1]))
        x = tau * _TABLE  # the branch: the representative nearest the tracked table, interpolated
        j = np.minimum(x.astype(int), _TABLE - 1)
        ref = self._table[i, j] + (x - j)[:, None] * (self._table[i, j + 1] - self._table[i, j])
        A = quat.nearest_zyx(principal, ref)
        dA = _euler_rates(A, m.omega_body)
        ddA = _euler_rates(A, m.alpha_body - _dL_dA(A, dA))
        return np.hstack((m.r, A)), np.hstack((m.dr, dA)), np.hstack((m.ddr, ddA))

    def evaluate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The Euler view ``(Y, dY, ddY)`` at one time ``t`` [s]: new arrays of size 6 (:meth:`sample`)."""
        if not math.isfinite(t):
            raise ValueError(f"t = {t!r} is invalid: expected a finite time [s]")
        Y, dY, ddY = self.sample(np.array([float(t)]))
        return Y[0], dY[0], ddY[0]

    def euler_band_entry(self, margin_deg: float = EULER_VIEW_MARGIN_DEG) -> tuple[int, float, float] | None:
        """Where the path first comes within ``margin_deg`` [deg] of pitch +-90 deg: ``(segment, time [s],
        pitch [deg])`` of the first table point inside (the pitch moves at most 0.33 deg between two), or
        ``None`` if the Euler view exists along the whole path."""
        limit = math.sin(math.radians(margin_deg))
        inside = np.abs(np.cos(self._table[..., 1])) < limit
        if not inside.any():
            return None
        i, j = (int(v) for v in np.argwhere(inside)[0])
        T = self._times_list[i + 1] - self._times_list[i] if len(self._times_list) > 1 else 0.0
        pitch = math.degrees(math.asin(math.sin(self._table[i, j, 1])))
        return i, self._times_list[i] + T * j / _TABLE, pitch


def _euler_rates(A, w) -> np.ndarray:
    """``L(A)^-1 w`` for stacks of ZYX angles ``A`` and body vectors ``w`` (plants.frames.body_rate_map_inverse)."""
    cth, tth = np.cos(A[:, 1]), np.tan(A[:, 1])
    cph, sph = np.cos(A[:, 2]), np.sin(A[:, 2])
    yz = sph * w[:, 1] + cph * w[:, 2]
    return np.stack((yz / cth, cph * w[:, 1] - sph * w[:, 2], w[:, 0] + yz * tth), axis=1)


def _dL_dA(A, dA) -> np.ndarray:
    """``dL(A, dA)/dt dA`` for stacks (plants.frames.body_rate_map_dot times ``dA``)."""
    cth, sth = np.cos(A[:, 1]), np.sin(A[:, 1])
    cph, sph = np.cos(A[:, 2]), np.sin(A[:, 2])
    dps, dth, dph = dA[:, 0], dA[:, 1], dA[:, 2]
    return np.stack((-cth * dth * dps,
                     (cph * cth * dph - sph * sth * dth) * dps - sph * dph * dth,
                     (-sph * cth * dph - cph * sth * dth) * dps - cph * dph * dth), axis=1)


def _rows(value, k: int) -> list[np.ndarray]:
    """The ``k`` validated via poses: finite rows of 6 (Euler) or 7 (unit quaternion, normalized)."""
    allowed = f"{k} via poses, each [x, y, z, psi, theta, phi] (m, rad) or [x, y, z, w, qx, qy, qz] (m, unit quaternion)"
    try:
        rows = [np.array(row, dtype=float) for row in value]
    except (TypeError, ValueError):
        raise ScenarioError("poses", value, allowed) from None
    if len(rows) != k:
        raise ScenarioError("poses", f"<{len(rows)} poses>", allowed)
    for i, row in enumerate(rows):
        if row.ndim != 1 or row.size not in (EULER_ROW, QUATERNION_ROW):
            raise ScenarioError(f"poses[{i}]", row.tolist(), allowed)
        bad = np.flatnonzero(~np.isfinite(row))
        if bad.size:
            raise ScenarioError(f"poses[{i}, {bad[0]}]", float(row[bad[0]]), "a finite coordinate")
        if row.size == QUATERNION_ROW:
            norm = float(np.linalg.norm(row[3:]))
            if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
                raise ScenarioError(f"poses[{i}, 3:7]", row[3:].tolist(),
                                    f"a unit quaternion (w, x, y, z): norm 1 within {QUATERNION_NORM_TOLERANCE:g} "
                                    f"(this one has norm {norm:.9g}; divide it by its norm if it is the rotation meant)")
            row[3:] /= norm
    return rows
