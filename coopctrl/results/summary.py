"""Key figures of a :class:`~coopctrl.results.SimulationResult` and their text table."""

from __future__ import annotations

import math
from collections import Counter
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult

#: QP statuses counted as a successful solve (compared case-insensitively).
QP_SUCCESS = ("solved", "ok", "optimal", "proxqp_solved", "solved_inaccurate")

_TINY = 1e-12


def json_safe(value: Any) -> Any:
    """A copy of ``value`` made of dicts, lists, str, int, float, bool and None only, with every
    NaN or infinity replaced by ``None`` (so ``json.dumps(..., allow_nan=False)`` succeeds)."""
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, np.generic):
        return json_safe(value.item())
    if isinstance(value, bool) or value is None or isinstance(value, (str, int)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return str(value)


def _rms(values: np.ndarray) -> float | None:
    values = np.asarray(values, dtype=float).reshape(-1)
    if values.size == 0:
        return None
    return float(np.sqrt(np.mean(values**2)))


def _max(values: np.ndarray) -> float | None:
    values = np.asarray(values, dtype=float).reshape(-1)
    return float(np.max(values)) if values.size else None


def _internal_force_error(squeeze: np.ndarray, desired: np.ndarray, t: np.ndarray) -> tuple[float | None, str | None]:
    """RMS [N] over samples and pairs of ``squeeze - desired`` (the pair tensions of the internal-force
    error, :func:`coopctrl.loop.squeeze.squeeze_series`), or ``(None, why)``: never computed from a
    sample whose decomposition was ill-conditioned or not finite (its squeeze is NaN there)."""
    if squeeze.shape[1] == 0:
        return None, "a single contact has no internal force"
    bad = ~np.all(np.isfinite(squeeze), axis=1)
    if np.any(bad):
        k = int(np.argmax(bad))
        return None, (f"pair tensions undefined at {int(np.sum(bad))} of {len(bad)} samples (first at t = "
                      f"{float(t[k]):.6g} s): the contacts' pair decomposition is ill-conditioned (contacts "
                      "nearly coincident or collinear) or the contact wrenches are not finite")
    return _rms(squeeze - desired[None, :]), None


def _rotation(A: np.ndarray) -> np.ndarray:
    """R = Rz(psi) Ry(theta) Rx(phi) for rows A = (psi, theta, phi) (docs/model.md §2): (N, 3, 3)."""
    cps, sps = np.cos(A[:, 0]), np.sin(A[:, 0])
    cth, sth = np.cos(A[:, 1]), np.sin(A[:, 1])
    cph, sph = np.cos(A[:, 2]), np.sin(A[:, 2])
    R = np.empty((A.shape[0], 3, 3))
    R[:, 0, 0] = cps * cth
    R[:, 0, 1] = cps * sth * sph - sps * cph
    R[:, 0, 2] = cps * sth * cph + sps * sph
    R[:, 1, 0] = sps * cth
    R[:, 1, 1] = sps * sth * sph + cps * cph
    R[:, 1, 2] = sps * sth * cph - cps * sph
    R[:, 2, 0] = -sth
    R[:, 2, 1] = cth * sph
    R[:, 2, 2] = cth * cph
    return R


def orientation_error(Y0: np.ndarray, Y0_nominal: np.ndarray) -> np.ndarray:
    """Angle [rad] of the rotation between the actual and nominal object orientations, (N,)."""
    if Y0.shape[1] == 3:
        d = Y0[:, 2] - Y0_nominal[:, 2]
        return np.abs((d + np.pi) % (2 * np.pi) - np.pi)
    Ra, Rn = _rotation(Y0[:, 3:6]), _rotation(Y0_nominal[:, 3:6])
    trace = np.einsum("nji,nji->n", Ra, Rn)  # trace(Ra^T Rn)
    return np.arccos(np.clip((trace - 1.0) / 2.0, -1.0, 1.0))


def position_error(Y0: np.ndarray, Y0_nominal: np.ndarray) -> np.ndarray:
    """Distance [m] between the actual and nominal object MC positions, (N,)."""
    k = 2 if Y0.shape[1] == 3 else 3
    return np.linalg.norm(Y0[:, :k] - Y0_nominal[:, :k], axis=1)


def qp_failed(status: str) -> bool:
    """True when a QP status is not one of :data:`QP_SUCCESS`."""
    return status.strip().lower() not in QP_SUCCESS


def summarize(result: "SimulationResult") -> dict[str, Any]:
    """The summary dict of ``result`` (see :meth:`SimulationResult.summary`)."""
    r = result
    n = r.t.shape[0]
    p = r.pose_size
    nf = 2 if p == 3 else 3  # force components of a wrench
    simulated = float(r.t[-1] - r.t[0]) if n > 1 else 0.0
    wall = r.wall_time_s  # from the first tick: the run's set-up (its model and data built) is startup_s
    realtime = simulated / wall if wall and math.isfinite(wall) and wall > 0 and n > 1 else None

    pos = position_error(r.Y0, r.Y0_nominal)
    ori = orientation_error(r.Y0, r.Y0_nominal)
    followers = [k for k in r.followers if 0 <= k < r.arms]
    if followers:
        df = r.F_measured[:, followers, :nf] - r.F_commanded[:, followers, :nf]
        follower_rms = _rms(np.linalg.norm(df, axis=2))
    else:
        follower_rms = None
    internal_rms, internal_unavailable = _internal_force_error(r.squeeze, r.squeeze_desired, r.t)
    if r.tau_max is not None and r.tau.size:
        with np.errstate(divide="ignore", invalid="ignore"):
            torque_ratio = _max(np.abs(r.tau) / r.tau_max[None, :])
    else:
        torque_ratio = None
    times = r.qp_solve_time_s[np.isfinite(r.qp_solve_time_s)]
    drift = None
    if r.energy_conserving and r.energy is not None and r.energy.size:
        E = r.energy
        scale = max(abs(float(E[0])), _TINY)
        if r.kinetic_energy is not None and r.kinetic_energy.size:
            scale = max(scale, float(np.nanmax(np.abs(r.kinetic_energy))))
        drift = float(np.max(np.abs(E - E[0]))) / scale
    return json_safe(
        {
            "scenario": r.scenario,
            "status": r.status,
            "reason": r.reason,
            "model": dict(r.model),
            "integrator": r.integrator,
            "step_s": r.step_s,
            "control_period_s": r.control_period_s,
            "duration_s": r.duration_s,
            "simulated_time_s": simulated,
            "samples": n,
            "wall_time_s": wall,
            "realtime_factor": realtime,
            "startup_s": r.startup_s,
            "object_position_error_rms_m": _rms(pos),
            "object_position_error_max_m": _max(pos),
            "object_orientation_error_max_rad": _max(ori),
            "follower_force_error_rms_N": follower_rms,
            "internal_force_error_rms_N": internal_rms,
            "internal_force_error_unavailable": internal_unavailable,
            "max_torque_ratio": torque_ratio,
            "qp_solves": len(r.qp_status),
            "qp_failures": sum(count for s, count in Counter(r.qp_status).items() if qp_failed(s)),  # per distinct status
            "qp_solve_time_median_us": float(np.median(times)) * 1e6 if times.size else None,
            "qp_active_constraints": dict(r.qp_active_constraints),
            "qp_time_share": (r.qp_time_s / wall) if wall and math.isfinite(r.qp_time_s) else None,
            "torque_saturated_ticks": int(r.torque_saturated_ticks),
            "energy_drift_rel": drift,
            "events": len(r.events),
            "leader": r.leader,
            "followers": list(r.followers),
            **_integration(r.integration_statistics),
        }
    )


def _integration(stats) -> dict[str, Any]:
    """The error-controlled integrator's step counts (no keys for a fixed step)."""
    if not stats:
        return {}
    return {"steps_accepted": stats["steps_accepted"], "steps_rejected": stats["steps_rejected"],
            "steps_rejected_share": stats["rejected_share"], "smallest_step_s": stats["smallest_step_s"],
            "rhs_evaluations": stats["rhs_evaluations"]}


#: Rows of :func:`summary_table`: (key, label, scale, unit).
_ROWS = (
    ("scenario", "scenario", None, ""),
    ("status", "status", None, ""),
    ("reason", "reason", None, ""),
    ("integrator", "integrator", None, ""),
    ("step_s", "integration step", 1e3, "ms"),
    ("smallest_step_s", "smallest step", 1e3, "ms"),
    ("steps_accepted", "steps accepted", None, ""),
    ("steps_rejected", "steps rejected", None, ""),
    ("control_period_s", "control period", 1e3, "ms"),
    ("simulated_time_s", "simulated time", 1.0, "s"),
    ("wall_time_s", "wall time", 1.0, "s"),
    ("realtime_factor", "real-time factor", 1.0, "x"),
    ("startup_s", "startup", 1.0, "s"),
    ("object_position_error_rms_m", "object position error RMS", 1e3, "mm"),
    ("object_position_error_max_m", "object position error max", 1e3, "mm"),
    ("object_orientation_error_max_rad", "object orientation error max", 1e3, "mrad"),
    ("follower_force_error_rms_N", "follower force error RMS", 1.0, "N"),
    ("internal_force_error_rms_N", "internal force error RMS", 1.0, "N"),
    ("max_torque_ratio", "max |tau| / tau_max", 1.0, ""),
    ("qp_solves", "QP solves", None, ""),
    ("qp_failures", "QP failures", None, ""),
    ("qp_solve_time_median_us", "QP solve time median", 1.0, "us"),
    ("energy_drift_rel", "relative energy drift", 1.0, ""),
)


def summary_table(summary: dict[str, Any]) -> str:
    """A short aligned text table of the key figures of a summary dict (``None`` shows as ``-``)."""
    rows = []
    for key, label, scale, unit in _ROWS:
        if key not in summary or (key == "reason" and not summary.get(key)):
            continue
        value = summary[key]
        if value is None:
            text = "-"
        elif scale is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
            text = f"{value * scale:.4g}" + (f" {unit}" if unit else "")
        else:
            text = str(value)
        rows.append((label, text))
    width = max(len(label) for label, _ in rows)
    return "\n".join(f"{label.ljust(width)}  {text}" for label, text in rows)
