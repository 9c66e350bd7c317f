"""Gains the sampled linear model already shows unstable: refused before the run, naming the field.

Pre-flight (:func:`coopctrl.analysis.preflight.preflight`, so ``coopctrl check`` and ``coopctrl run``)
calls :func:`check_gains`. Each loop of the controller is modelled as the controller assumes it, sampled
at the control period ``T`` with the command held (ZOH):

* **a motion loop** (the leader's, and each follower's inner loop): computed torque makes the node's
  tracking error a double integrator, ``e'' = a``, with ``a_k = -K_p e_k - K_d e'_k``,
  ``K_p = omega_n^2``, ``K_d = 2 zeta omega_n``:

  .. math::
      \\begin{bmatrix} e \\\\ e' \\end{bmatrix}_{k+1} =
      \\begin{bmatrix} 1 - K_p T^2/2 & T - K_d T^2/2 \\\\ -K_p T & 1 - K_d T \\end{bmatrix}
      \\begin{bmatrix} e \\\\ e' \\end{bmatrix}_k

* **a follower's force loop** (:class:`~coopctrl.controllers.FollowerForceController`): the force
  deviation ``f = K (Y - Y_ff)`` [N] follows the PI's output ``r`` through that motion loop
  (``K C = I``: the compliance cancels the stiffness), ``e_k = -f_k``, ``I_{k+1} = I_k + T e_k``,
  ``r_k = k_p e_k + k_i I_{k+1}``, ``a_k = K_p (r_k - f_k) - K_d f'_k``: a 3-state map.

A loop is unstable when its map has an eigenvalue of modulus ``>= 1``. The field named is the first of
``controllers.leader.natural_frequency``, ``controllers.followers.natural_frequency``,
``controllers.followers.force_kp`` (the force loop unstable with ``k_i = 0``) and
``controllers.followers.force_ki``, with the stability limit of that gain, the others as given
(bisection to :data:`RESOLUTION`). The model ignores the elastic modes and the arms' coupling, so a
refusal is confirmed on the closed loop of the scene itself, linearized at its start
(:mod:`~coopctrl.analysis.closed_loop_stability`, at a step far below every integration limit): only
gains that the whole loop's period map also finds growing are refused. A loop the model finds stable
is never refused here; a run that nevertheless grows is judged by :mod:`coopctrl.analysis.instability`.
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.errors import ScenarioError

__all__ = ["RESOLUTION", "check_gains", "force_loop_map", "gain_limit", "loop_grows", "motion_loop_map", "spectral_radius",
           "unstable_gain"]

#: Relative resolution of the bisection on a gain's stability limit [-].
RESOLUTION = 1e-3


def motion_loop_map(natural_frequency: float, damping_ratio: float, T: float) -> np.ndarray:
    """The sampled computed-torque error loop's one-period map (module docstring), (2, 2) [-, s, 1/s]."""
    kp, kd = natural_frequency ** 2, 2.0 * damping_ratio * natural_frequency
    return np.array([[1.0 - kp * T * T / 2.0, T - kd * T * T / 2.0], [-kp * T, 1.0 - kd * T]])


def force_loop_map(force_kp: float, force_ki: float, natural_frequency: float, damping_ratio: float,
                   T: float) -> np.ndarray:
    """The sampled force loop's one-period map on ``(f, f', I)`` (module docstring), (3, 3); on ``(f, f')``,
    (2, 2), for a P loop (``force_ki = 0``: the integral is then no state of the loop)."""
    kp, kd = natural_frequency ** 2, 2.0 * damping_ratio * natural_frequency
    # e = -f; I' = I - T f; r = -force_kp f + force_ki (I - T f); a = kp (r - f) - kd f'
    a_f = kp * (-force_kp - force_ki * T - 1.0)
    a_df = -kd
    a_i = kp * force_ki
    M = np.array([[1.0 + a_f * T * T / 2.0, T + a_df * T * T / 2.0, a_i * T * T / 2.0],
                  [a_f * T, 1.0 + a_df * T, a_i * T],
                  [-T, 0.0, 1.0]])
    return M if force_ki != 0.0 else M[:2, :2]


def spectral_radius(M: np.ndarray) -> float:
    """``max |eig(M)|`` [-] (``inf`` when ``M`` is not finite)."""
    if not np.all(np.isfinite(M)):
        return math.inf
    return float(np.max(np.abs(np.linalg.eigvals(M))))


def gain_limit(radius_at, value: float) -> float:
    """The largest gain ``g <= value`` [its unit] with ``radius_at(g) < 1``, by bisection on a log scale
    from a stable small value (``0`` when even ``g -> 0`` is unstable)."""
    lo = value
    while radius_at(lo) >= 1.0:
        lo *= 0.1
        if lo < 1e-12 * max(value, 1e-300):
            return 0.0
    hi = value
    if lo == hi:
        return value
    while hi / lo - 1.0 > RESOLUTION:
        mid = math.sqrt(lo * hi)
        if radius_at(mid) < 1.0:
            lo = mid
        else:
            hi = mid
    return lo


def unstable_gain(scenario) -> tuple | None:
    """``(field, value, limit, radius[, more])`` of the first gain the model finds unstable (``more``: a
    second gain that must come down too), or ``None``."""
    c = scenario.controllers
    T = scenario.simulation.control_period
    lead, fol = c.leader, c.followers
    rho = spectral_radius(motion_loop_map(lead.natural_frequency, lead.damping_ratio, T))
    if rho >= 1.0:
        limit = gain_limit(lambda w: spectral_radius(motion_loop_map(w, lead.damping_ratio, T)), lead.natural_frequency)
        return "controllers.leader.natural_frequency", lead.natural_frequency, limit, rho
    if not scenario.followers:
        return None
    rho = spectral_radius(motion_loop_map(fol.natural_frequency, fol.damping_ratio, T))
    if rho >= 1.0:
        limit = gain_limit(lambda w: spectral_radius(motion_loop_map(w, fol.damping_ratio, T)), fol.natural_frequency)
        return "controllers.followers.natural_frequency", fol.natural_frequency, limit, rho
    if not fol.force_loop:
        return None
    wn, zeta = fol.natural_frequency, fol.damping_ratio
    rho = spectral_radius(force_loop_map(fol.force_kp, fol.force_ki, wn, zeta, T))
    if rho < 1.0:
        return None
    if spectral_radius(force_loop_map(fol.force_kp, 0.0, wn, zeta, T)) >= 1.0:
        limit = gain_limit(lambda g: spectral_radius(force_loop_map(g, 0.0, wn, zeta, T)), fol.force_kp)
        if fol.force_ki > 0 and spectral_radius(force_loop_map(limit / 4, fol.force_ki, wn, zeta, T)) >= 1.0:
            ki = gain_limit(lambda g: spectral_radius(force_loop_map(limit / 4, g, wn, zeta, T)), fol.force_ki)
            return ("controllers.followers.force_kp", fol.force_kp, limit, rho,
                    f"; with force_kp = {limit / 4:.3g}, controllers.followers.force_ki = {fol.force_ki:g} 1/s must "
                    f"also come below {ki:.3g} 1/s")
        return "controllers.followers.force_kp", fol.force_kp, limit, rho
    limit = gain_limit(lambda g: spectral_radius(force_loop_map(fol.force_kp, g, wn, zeta, T)), fol.force_ki)
    return "controllers.followers.force_ki", fol.force_ki, limit, rho


def loop_grows(scenario, x0) -> bool:
    """True when the scene's whole closed loop, linearized at ``x0`` (t = 0), has a growing mode at a
    step far below every integration limit (``rho_0 > 1``; :meth:`LoopLinearization.max_stable_step`);
    also True when it cannot be linearized (the model's finding then stands)."""
    from coopctrl.analysis.closed_loop_stability import GROWTH_TOLERANCE, LoopLinearizer
    from coopctrl.integrators import get_integrator

    try:
        lin = LoopLinearizer(scenario).linearize(x0, None, 0.0)
        _, rho0 = lin.max_stable_step(get_integrator("rk4"))
    except Exception:  # noqa: BLE001 - a start the linearization refuses: the sampled model decides
        return True
    return rho0 > 1.0 + GROWTH_TOLERANCE


def check_gains(scenario, x0=None) -> None:
    """Raise :class:`~coopctrl.errors.ScenarioError` naming the gain when a loop of ``scenario``'s
    controller is unstable at its control period (module docstring); ``x0``: the start state for the
    confirmation (default ``build.initial_state(scenario)``). A passive scene has no gains to check."""
    if not scenario.controllers.enabled:
        return
    found = unstable_gain(scenario)
    if found is None:
        return
    field, value, limit, rho, *more = found
    if x0 is None:
        from coopctrl.scenario import build

        x0 = build.initial_state(scenario)
    if not loop_grows(scenario, x0):
        return
    T = scenario.simulation.control_period
    unit = "" if field.endswith("force_kp") else " 1/s" if field.endswith("force_ki") else " rad/s"
    raise ScenarioError(field, value,
                        f"a value below {limit:.3g}{unit}: sampled every control_period = {T:g} s this loop is "
                        f"unstable (its one-period map has an eigenvalue of modulus {rho:.3g} > 1, and the scene's "
                        "linearized closed loop grows too; docs/reliability.md, 'Instability'); take a value well "
                        f"below the limit (e.g. {limit / 4:.3g}{unit}) or shorten simulation.control_period"
                        + "".join(more),
                        scenario.source)
