"""A run that finished its ticks but was not controlled: judged a failure, with its cause.

A run whose error grows without bound stops at a divergence guard (a non-finite state, a deformation
beyond ``simulation.max_deformation``, an energy beyond ``simulation.max_energy``) and its diagnosis
names the cause (:mod:`coopctrl.analysis.diagnosis`, which names an unstable gain first:
:func:`gain_cause`). A loop can also be unstable and yet stay bounded: clipped torques cap the growth,
and the run reaches its end with the object far off its path. Such a run is not ``ok``:

* **saturated on most ticks**: the commanded torques were clipped at ``tau_max`` on more than
  :data:`SATURATED_SHARE` of the ticks. The run's status is ``diverged`` (exit 1), its reason names
  the cause: an unstable gain of the sampled loop model (:mod:`coopctrl.analysis.gain_stability`) with
  its stable limit, else the torque limit of the joint clipped most often, with pre-flight's plan: the
  joint and torque the task needs beyond its limit, or the plan's largest ``|tau| / tau_max`` when it
  fits (the saturation then comes from correcting a tracking error).

Below that share, saturation stays a warning of an ``ok`` run (a transient the loop recovers from).
"""

from __future__ import annotations

import numpy as np

__all__ = ["SATURATED_SHARE", "gain_cause", "saturation_failure"]

#: Share of the ticks [-] with clipped torques above which a finished run is a failure: most of the run
#: was spent outside the torques the controller asked for, so none of its tracking is the controller's.
SATURATED_SHARE = 0.5


def gain_cause(scenario) -> str:
    """The phrase naming a gain the sampled loop model finds unstable (with its limit), or ``""``."""
    from coopctrl.analysis.gain_stability import unstable_gain

    if scenario is None or not scenario.controllers.enabled:
        return ""
    found = unstable_gain(scenario)
    if found is None:
        return ""
    field, value, limit, rho, *more = found
    return (f"unstable gain: {field} = {value:g} is beyond the stable limit {limit:.3g} of its loop sampled every "
            f"{scenario.simulation.control_period:g} s (one-period map |eig| = {rho:.3g} > 1); take a value well below "
            f"it (e.g. {limit / 4:.3g})" + "".join(more))


def saturation_failure(scenario, loop, rec: dict) -> str:
    """The reason of a finished run saturated on more than :data:`SATURATED_SHARE` of its ticks, or ``""``."""
    n = len(rec["t"])
    ticks = int(rec.get("saturated_ticks", 0))
    if n == 0 or not ticks > SATURATED_SHARE * n:
        return ""
    head = (f"not controlled: the commanded torques were clipped at tau_max on {ticks} of {n} ticks (more than "
            f"{SATURATED_SHARE:.0%}; docs/reliability.md, 'Instability')")
    gain = gain_cause(scenario)
    if gain:
        return f"{head}; cause: {gain}"
    per_joint = np.asarray(rec.get("saturated_joint_ticks", np.zeros(0)), dtype=int)
    if not per_joint.size:
        return f"{head}; raise tau_max or lower the payload (object.mass) or the accelerations"
    j = int(np.argmax(per_joint))
    arm, joint = _arm_joint(loop, j)
    tau_max = float(np.asarray(loop.tau_max, dtype=float)[j]) if loop.tau_max is not None else float("nan")
    return (f"{head}; cause: the torque limit arms[{arm}].tau_max[{joint}] = {tau_max:.4g} N m (joint {joint + 1} of "
            f"arm {arm + 1}, clipped on {per_joint[j]} ticks){_planned(scenario, loop)}")


def _planned(scenario, loop) -> str:
    """What pre-flight's plan says of the torques: the joint and torque the task needs beyond its limit (the
    value that would hold it), or that the plan fits (the saturation then comes from the tracking error)."""
    try:
        from coopctrl.analysis.preflight import preflight

        report = preflight(scenario, loop)
    except Exception:  # noqa: BLE001 - the failure's reason stands without the plan
        return ": the task needs more torque than the arm has; raise it, or lower the payload or the accelerations"
    torque = [issue for issue in report.issues if issue.kind == "torque"]
    if torque:
        return f"; pre-flight: {torque[0].message}"
    if report.torque_ratio_max == report.torque_ratio_max:
        return (f"; the nominal plan needs at most {report.torque_ratio_max:.3g} x tau_max (at t = "
                f"{report.torque_ratio_time_s:.4g} s), so the torques saturate correcting a tracking error the "
                "limits cannot follow: lower the gains or the accelerations, or raise tau_max")
    return ": the task needs more torque than the arm has; raise it, or lower the payload or the accelerations"


def _arm_joint(loop, j: int) -> tuple[int, int]:
    """``(arm, joint)`` (0-based) of the plant input ``j``."""
    for i, arm in enumerate(loop.plant.arms):
        if j < arm.dof:
            return i, j
        j -= arm.dof
    return 0, j
