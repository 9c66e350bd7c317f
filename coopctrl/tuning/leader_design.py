"""Leader gains: from a natural frequency and a damping ratio, or by LQR on the error dynamics.

The scenario holds one pair ``(omega_n, zeta)`` for every pose coordinate of the leader
(``K_p = omega_n^2 I``, ``K_d = 2 zeta omega_n I``). Both designs use the sampled error
model of :mod:`~coopctrl.tuning.leader_error_model`, on which those gains are exactly the
controller's state feedback, and return :class:`~coopctrl.tuning.gains.Gains`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning.errors import TuningError, UnachievableDesign
from coopctrl.tuning.gains import Gains
from coopctrl.tuning.leader_error_model import error_dynamics, error_poles


def _check_sampled(natural_frequency: float, damping_ratio: float, control_period: float | None) -> None:
    if control_period is None:
        return
    z = error_poles(natural_frequency, damping_ratio, control_period)
    if np.max(np.abs(z)) >= 1.0:
        raise UnachievableDesign(
            {"natural_frequency_rad_s": natural_frequency, "damping_ratio": damping_ratio},
            f"beyond the control rate: sampled every T = {control_period:g} s the leader's error loop is unstable "
            f"(pole |z| = {np.max(np.abs(z)):.4g}); lower the natural frequency well below pi / T = "
            f"{np.pi / control_period:.4g} rad/s or shorten simulation.control_period")


def leader_gains(natural_frequency: float, damping_ratio: float, control_period: float | None = None) -> Gains:
    """Leader gains ``K_p = omega_n^2``, ``K_d = 2 zeta omega_n`` as :class:`Gains`.

    Args:
        natural_frequency: ``omega_n`` [rad/s] > 0.
        damping_ratio: ``zeta`` [-] > 0.
        control_period: If given [s], check that the sampled loop is stable.

    Raises:
        ScenarioError: a value out of range; UnachievableDesign: unstable when sampled.
    """
    gains = Gains(leader_natural_frequency=natural_frequency, leader_damping_ratio=damping_ratio)
    _check_sampled(gains.leader_natural_frequency, gains.leader_damping_ratio, control_period)
    return gains


def bryson_weights(max_error: float, max_rate: float, max_acceleration: float) -> tuple[np.ndarray, np.ndarray]:
    """Bryson's rule: ``Q = diag(1 / e_max^2, 1 / de_max^2)``, ``R = [[1 / a_max^2]]`` for the per-axis
    error model (errors [m or rad], rates [m/s or rad/s], feedback accelerations [m/s^2 or rad/s^2])."""
    for name, v in (("max_error", max_error), ("max_rate", max_rate), ("max_acceleration", max_acceleration)):
        if not (isinstance(v, (int, float)) and v > 0 and np.isfinite(v)):
            raise TuningError(name, v, "a finite number > 0")
    return np.diag([1.0 / max_error**2, 1.0 / max_rate**2]), np.array([[1.0 / max_acceleration**2]])


@dataclass(frozen=True, eq=False)
class LeaderLQRDesign:
    """An LQR design of the leader gains.

    Attributes:
        gains: :class:`Gains` with the leader's ``(omega_n, zeta)`` (what the scenario can hold).
        K: The LQR state feedback ``a = -K (e, de)`` (p x 2p with ``(e_1..e_p, de_1..de_p)``, or 1 x 2).
        natural_frequencies, damping_ratios: Per-axis ``omega_n = sqrt(K_p)``, ``zeta = K_d / (2 omega_n)``
            read from the diagonal of ``K``.
        structure_error: ``||K - [K_p I, K_d I]||_F / ||K||_F`` [-] of the nearest gains of the
            scenario's form (0 when every axis has the same weights and no cross weights).
        lqr_poles: Closed-loop poles of the LQR on the error model (``z`` if sampled, else ``s``).
        poles: Closed-loop poles with the returned ``(omega_n, zeta)``.
        note: What was approximated, if anything.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    gains: Gains
    K: np.ndarray
    natural_frequencies: np.ndarray
    damping_ratios: np.ndarray
    structure_error: float
    lqr_poles: np.ndarray
    poles: np.ndarray
    note: str


def leader_gains_lqr(Q, R, control_period: float | None = None) -> LeaderLQRDesign:
    """LQR on the leader's error dynamics, mapped to the scenario's ``(omega_n, zeta)``.

    Per axis the error is ``e'' = a`` (:func:`~coopctrl.tuning.leader_error_model.error_dynamics`);
    ``control.dlqr`` on its ZOH sampling (``control_period`` [s]; the controller samples the
    error and holds ``a``) or ``control.lqr`` on the continuous model (``control_period=None``)
    minimizes ``sum e^T Q e + a^T R a``.

    Args:
        Q: (2, 2) weight on ``(e, de)`` of every axis, or (2p, 2p) on ``(e_1..e_p, de_1..de_p)``.
        R: Scalar or (1, 1) weight on ``a``, or (p, p) with a (2p, 2p) ``Q``.
        control_period: ``T`` [s] of the loop, or None for the continuous design.

    The scenario holds one ``K_p = omega_n^2`` and one ``K_d = 2 zeta omega_n`` for every
    axis. With a (2, 2) ``Q`` that is exactly the LQR gain. With a full ``Q``/``R`` the LQR gain
    may differ per axis or couple axes: it is then mapped to the nearest gains of that form
    (least squares: the mean of the diagonals of its ``K_p`` and ``K_d`` blocks), and
    ``structure_error`` and ``note`` say how far that is.

    Raises:
        TuningError: wrong shapes; UnachievableDesign: the mapped gains are unstable when sampled.
    """
    import control

    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    R = np.atleast_2d(np.asarray(R, dtype=float))
    if Q.shape[0] != Q.shape[1] or Q.shape[0] % 2 or Q.shape[0] == 0:
        raise TuningError("Q", Q.tolist(), "a (2, 2) weight on (e, de) or a (2p, 2p) weight on (e_1..e_p, de_1..de_p)")
    p = Q.shape[0] // 2
    if R.shape != (p, p):
        raise TuningError("R", R.tolist(), f"a ({p}, {p}) weight on the feedback accelerations")
    base = error_dynamics(control_period)
    A1, B1 = np.asarray(base.A), np.asarray(base.B)
    # (e_1..e_p, de_1..de_p) ordering: kron of the per-axis model with I_p
    A = np.block([[A1[0, 0] * np.eye(p), A1[0, 1] * np.eye(p)], [A1[1, 0] * np.eye(p), A1[1, 1] * np.eye(p)]])
    B = np.vstack([B1[0, 0] * np.eye(p), B1[1, 0] * np.eye(p)])
    try:
        if control_period is None:
            K, _, E = control.lqr(A, B, Q, R)
        else:
            K, _, E = control.dlqr(A, B, Q, R)
    except (ValueError, np.linalg.LinAlgError, control.ControlArgument) as exc:
        raise TuningError("Q, R", (Q.tolist(), R.tolist()), f"weights with Q >= 0 and R > 0 ({exc})") from None
    K = np.asarray(K)
    kp_axes, kd_axes = np.diag(K[:, :p]).copy(), np.diag(K[:, p:]).copy()
    if np.any(kp_axes <= 0) or np.any(kd_axes <= 0):
        raise TuningError("Q", Q.tolist(), "a positive weight on every error and rate (the LQR gain has a zero K_p or K_d)")
    Kp, Kd = float(np.mean(kp_axes)), float(np.mean(kd_axes))
    nearest = np.hstack([Kp * np.eye(p), Kd * np.eye(p)])
    structure_error = float(np.linalg.norm(K - nearest) / np.linalg.norm(K))
    wn, zeta = np.sqrt(Kp), Kd / (2.0 * np.sqrt(Kp))
    note = ""
    if structure_error > 1e-9:
        note = (f"the LQR gain differs per axis or couples axes, which [controllers.leader] cannot hold; it was "
                f"mapped to the nearest common K_p = {Kp:.4g}, K_d = {Kd:.4g} (relative distance {structure_error:.3g})")
    _check_sampled(wn, zeta, control_period)
    gains = Gains(leader_natural_frequency=float(wn), leader_damping_ratio=float(zeta))
    return LeaderLQRDesign(gains=gains, K=K, natural_frequencies=np.sqrt(kp_axes),
                           damping_ratios=kd_axes / (2 * np.sqrt(kp_axes)), structure_error=structure_error,
                           lqr_poles=np.asarray(E), poles=error_poles(wn, zeta, control_period), note=note)
