"""Why a run failed: each possible cause checked against the evidence of the run.

:func:`diagnose_record` runs after a run, in :func:`coopctrl.simulator.simulate`: when the run diverged
(outside the Euler-angle singularity, which the loop names itself), it explains the stop the run recorded
(``LoopRecord.stop``, :class:`coopctrl.loop.diagnosis.Stop`) anew with :func:`diagnose_failure` and the
scenario, and writes that reason into the record. It lives here, above the loop, because it linearizes
the closed loop of the scenario (:mod:`~coopctrl.analysis.closed_loop_stability`), which builds loops;
nothing is attached to the loop for it. The causes, in the order they are reported:

- **unstable gain**: a gain the sampled loop model finds unstable at the control period
  (:func:`coopctrl.analysis.instability.gain_cause`), named with its stable limit; the torque
  saturation such a loop drives is then its consequence and not named;
- **static instability**: the object's translational stiffness with the contacts held has a negative
  eigenvalue at the start (:func:`coopctrl.loop.diagnosis.static_instability`; a squeezed
  central-spring grasp buckles);
- **unreachable pose**: an arm cannot reach its nominal node pose at the failure time (inverse
  kinematics within its joint limits);
- **torque saturation**: the commanded torques were clipped at ``tau_max`` on at least
  :data:`SATURATION_SHARE` of the ticks run, or on the last tick before the failure (which joints, how
  many ticks, the first time); when the step is also a cause, only if the saturation precedes the
  blow-up (:func:`saturation_precedes_blow_up`): an unstable step saturates the torques as it blows
  up, and saturation on the last ticks only is then its consequence, not evidence against the step;
- **load distribution**: the QP failed and the loop held its last feasible split (how many ticks, the
  first time);
- **the step**: ``h`` beyond the closed loop's predicted limit
  (:mod:`~coopctrl.analysis.closed_loop_stability`) at the start state or a few ticks before the
  failure. Only then is a smaller step suggested; otherwise the reason says the step is not the cause.
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.io.number_text import numbers_text
from coopctrl.loop.diagnosis import Diagnosis, held_split_cause, static_instability

__all__ = ["SATURATION_SHARE", "Diagnosis", "closed_loop_limit", "diagnose_failure", "diagnose_record", "held_split_cause",
           "saturation_cause", "saturation_precedes_blow_up", "unreachable_cause"]

#: Share of the ticks run [-] with clipped torques from which saturation is named as a cause.
SATURATION_SHARE = 0.1


def saturation_cause(loop, rec: dict, k_done: int) -> str:
    """The torque saturation phrase, or ``""`` when the evidence does not name it (module docstring)."""
    ticks = int(rec.get("saturated_ticks", 0))
    if ticks == 0 or k_done == 0:
        return ""
    last = rec.get("saturated_last_tick", -1)
    if ticks < SATURATION_SHARE * k_done and last < k_done - 1:
        return ""
    per_joint = np.asarray(rec.get("saturated_joint_ticks", np.zeros(0)), dtype=int)
    names = _joint_names(loop)
    order = [j for j in np.argsort(-per_joint, kind="stable") if per_joint[j] > 0][:4]
    joints = ", ".join(f"{names[j]} ({per_joint[j]} ticks)" for j in order)
    first = rec.get("saturation_first_time_s", math.nan)
    more = "" if len(order) == int(np.sum(per_joint > 0)) else f" and {int(np.sum(per_joint > 0)) - len(order)} more"
    return (f"torque saturation: the commanded torques were clipped at tau_max on {ticks} of {k_done} ticks from "
            f"t = {first:.4g} s ({joints}{more}); the task needs more torque than the arms have: lower the payload "
            "(object.mass) or the accelerations, or raise tau_max (`coopctrl check` refuses such a task before it "
            "runs)")


def saturation_precedes_blow_up(rec: dict, t_fail: float, t_back: float) -> bool:
    """True when the torques saturated before a step-driven blow-up could have saturated them.

    The step's limit is judged at the start and at the state of ``t_back`` [s], a few ticks
    (:data:`~coopctrl.loop.diagnosis.DIAGNOSIS_TICKS_BACK`) before the failure at ``t_fail`` [s], where
    the blow-up has not yet taken over. Saturation outweighs the step only if it began by that state,
    ``t_sat <= t_back`` (at the start state itself when the run failed within a few ticks), and in the
    first half of the run, ``t_sat <= t_fail / 2``; saturation
    first met in the last ticks (e.g. 1 of 2 ticks of a run that diverged at its second tick) is what a
    diverging state does to its controller."""
    first = float(rec.get("saturation_first_time_s", math.nan))
    return first <= t_back and first <= 0.5 * t_fail


def unreachable_cause(loop, t: float) -> str:
    """The unreachable-pose phrase when an arm cannot reach its nominal node pose at ``t`` [s], else ``""``."""
    from plants.cooperative import ContactPoint, nominal_node_motion
    from plants.errors import PlantError, UnreachablePoseError

    try:
        Y0N, dY0N, ddY0N = loop.trajectory.evaluate(t)
        Yn = nominal_node_motion(Y0N, dY0N, ddY0N, loop.grasps, loop.space)[0]
    except (PlantError, ValueError):
        return ""
    for i, arm in enumerate(loop.plant.arms):
        if isinstance(arm, ContactPoint):
            continue
        try:
            arm.inverse_kinematics(Yn[i + 1], seeds=5)
        except UnreachablePoseError as exc:
            pose = numbers_text(Yn[i + 1])
            return (f"unreachable pose: at t = {t:.4g} s arm {i + 1} (arms[{i}]) cannot reach its nominal node pose "
                    f"({pose}) within its joint limits (best residual {exc.residual:.3g}); move the waypoint, the "
                    "grasp or the arm base")
    return ""


def closed_loop_limit(loop, states, scenario=None) -> float:
    """The smallest predicted closed-loop step limit [s] of ``loop``'s integrator over ``states``
    (``(x, t)`` pairs; ``nan`` when no linearization succeeded, ``inf`` when none is below ``T``), on the
    closed loop of ``scenario`` (the one ``loop`` was built from). Without a scenario, or for a passive
    loop: ``nan``, and the open-loop prediction decides."""
    from coopctrl.analysis.closed_loop_stability import LoopLinearizer

    if scenario is None or not loop.enabled:
        return math.nan
    try:
        lin = LoopLinearizer(scenario)
    except Exception:  # noqa: BLE001 - a diagnosis must never replace the failure it explains
        return math.nan
    best = math.nan
    for x, t in states:
        if x is None or not np.all(np.isfinite(x)):
            continue
        try:
            h, _ = lin.linearize(x, None, t).max_stable_step(loop.integrator)
        except Exception:  # noqa: BLE001 - a state the controller or the plant refuses: no limit from it
            continue
        best = h if math.isnan(best) else min(best, h)
    return best


def diagnose_failure(loop, rec: dict, k_done: int, t_fail: float, x_back, t_back: float, x0,
                     scenario=None) -> Diagnosis:
    """The causes of a failed run (module docstring), from its evidence ``rec`` up to tick ``k_done``; the
    step is judged against the closed-loop limit of ``scenario``'s loop (:func:`closed_loop_limit`;
    without a scenario, against the open-loop prediction)."""
    causes = []
    why = static_instability(loop, x0)
    if why:
        causes.append(why)
    gain = ""
    if loop.enabled:
        from coopctrl.analysis.instability import gain_cause

        gain = gain_cause(scenario)
        if gain:  # an unstable gain first: what the loop does (saturation, a blow-up) follows from it
            causes.append(gain)
    if loop.enabled:
        reach = unreachable_cause(loop, t_fail)
        if reach:
            causes.append(reach)
    if loop.enabled:
        limit = closed_loop_limit(loop, [(np.asarray(x0, dtype=float), 0.0), (x_back, t_back)], scenario)
    else:  # no controller: the loop is the plant, whose prediction is the open-loop one
        limit = math.nan
    if math.isnan(limit):
        limit_open = loop.predicted_max_step(x0)
        if x_back is not None and np.all(np.isfinite(x_back)):
            try:
                limit_open = min(limit_open, loop.predicted_max_step(x_back))
            except (ArithmeticError, ValueError, np.linalg.LinAlgError):
                pass
        step_is_cause = loop.h > limit_open
    else:
        step_is_cause = loop.h > limit
    if loop.enabled:
        sat = saturation_cause(loop, rec, k_done)
        # an unstable step saturates the torques as it blows up: then saturation is named only if it came first
        if sat and not gain and not (step_is_cause and not saturation_precedes_blow_up(rec, t_fail, t_back)):
            causes.append(sat)
        held = held_split_cause(rec.get("events", ()))
        if held:
            causes.append(held)
    return Diagnosis(tuple(causes), bool(step_is_cause), limit)


def diagnose_record(scenario, loop, rec) -> None:
    """After a run of ``loop``, the :func:`~coopctrl.simulator.closed_loop` of ``scenario``: when its stop
    (``rec["stop"]``) is a divergence whose reason depends on its causes, that reason found anew with
    :func:`diagnose_failure` on ``scenario`` (the closed-loop step limit), written into ``rec["reason"]``
    and the stop's event. Nothing else changes (the loop and the scenario are only read)."""
    from coopctrl.loop.diagnosis import rediagnose

    stop = rec.get("stop")
    if stop is None:
        return

    def causes(loop_, evidence, k_done, t_fail, x_back, t_back, x0):
        return diagnose_failure(loop_, evidence, k_done, t_fail, x_back, t_back, x0, scenario=scenario)

    reason = rediagnose(loop, stop, causes)
    if reason is None:
        return
    events = rec["events"]
    t, kind, _ = events[stop.event]
    events[stop.event] = (t, kind, reason)
    rec["reason"] = reason


def _joint_names(loop) -> list[str]:
    """``"arm 1 joint 2"`` for each input of the plant."""
    out = []
    for i, arm in enumerate(loop.plant.arms):
        out += [f"arm {i + 1} joint {j + 1}" for j in range(arm.dof)]
    return out
