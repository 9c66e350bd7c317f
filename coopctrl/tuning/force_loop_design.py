"""Follower force-loop gains ``(force_kp, force_ki)`` for a target bandwidth and phase margin.

Solved numerically on the closed-loop model (:class:`~coopctrl.tuning.ForceLoop` of one
follower component): find ``k_p >= 0``, ``k_i > 0`` with

.. math::
    \\omega_b(k_p, k_i) = \\omega_b^*, \\qquad \\varphi_m(k_p, k_i) = \\varphi_m^*

where ``omega_b`` is the -3 dB bandwidth of the setpoint-to-force transfer function and
``phi_m`` the phase margin of the loop ``L``. The same gains act on every component of every
follower (the scenario holds one pair), so the other loops are closed with them too; the
returned :class:`~coopctrl.tuning.ForceLoop` of each component shows what they get.
A coarse grid seeds ``scipy.optimize.least_squares``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning import signal_names as names
from coopctrl.tuning.elastic_modes import elastic_modes
from coopctrl.tuning.errors import TuningError, UnachievableDesign
from coopctrl.tuning.force_loop import ForceLoop, default_component, force_loop
from coopctrl.tuning.frequency import bandwidth, frequency_grid, frequency_response, phase_margin_from_response
from coopctrl.tuning.gains import Gains

#: A design is accepted within these tolerances of its targets: relative bandwidth [-], phase margin [deg].
BANDWIDTH_TOLERANCE = 0.01
PHASE_MARGIN_TOLERANCE = 0.5

#: Seed grid of the solver.
KP_GRID = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0)
KI_GRID = tuple(np.logspace(0, 3.5, 8))

#: Solver starts (the best grid points) and evaluations per start.
SEEDS = 2
MAX_EVALUATIONS = 40


@dataclass(frozen=True, eq=False)
class ForceLoopDesign:
    """A force-loop design.

    Attributes:
        gains: :class:`Gains` with ``follower_force_kp``, ``follower_force_ki`` and the force loop on.
        force_loop: The designed loop (:class:`ForceLoop`), with its margins and bandwidth.
        target: ``{"bandwidth_rad_s": ..., "phase_margin_deg": ...}``.
        other_components: :class:`ForceLoop` of the follower's other components with the same gains.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    gains: Gains
    force_loop: ForceLoop
    target: dict
    other_components: tuple

    @property
    def achieved(self) -> dict:
        return {"bandwidth_rad_s": self.force_loop.bandwidth, "phase_margin_deg": self.force_loop.margins.phase_margin}


class _Evaluator:
    """Bandwidth and phase margin of one force loop for many gains (fast path, no python-control
    objects per evaluation)."""

    def __init__(self, model, follower: int, component: str):
        self.model = model
        self.T = model.control_period
        arm = names.arm(follower)
        self.open_loop = (follower, component)
        probe = model.closed(0.0, 0.0, open_loop=self.open_loop)
        self.i_e = probe.output_labels.index(f"{arm}_force_error_{component}")
        self.i_v = probe.input_labels.index(f"{arm}_pi_{component}")
        self.i_F = probe.output_labels.index(f"{arm}_{component}")
        self.i_r = probe.input_labels.index(f"{arm}_setpoint_{component}")
        self.omega = frequency_grid(probe)
        self.z = np.exp(1j * self.omega * self.T)
        self.cache: dict = {}

    def __call__(self, kp: float, ki: float) -> tuple[float, float]:
        key = (round(kp, 12), round(ki, 12))
        if key in self.cache:
            return self.cache[key]
        closed = self.model.closed(kp, ki)
        if np.max(np.abs(np.linalg.eigvals(np.asarray(closed.A)))) >= 1.0:
            out = (float("nan"), float("nan"))
        else:
            opened = self.model.closed(kp, ki, open_loop=self.open_loop)
            P = frequency_response(opened[self.i_e, self.i_v], self.omega)
            pi = kp + ki * self.T * self.z / (self.z - 1.0)
            pm, _ = phase_margin_from_response(self.omega, -pi * P)
            out = (bandwidth(closed[self.i_F, self.i_r]), pm)
        self.cache[key] = out
        return out


def follower_force_gains(model, bandwidth_rad_s: float, phase_margin_deg: float, follower: int | None = None,
                         component: str | None = None) -> ForceLoopDesign:
    """``(force_kp, force_ki)`` that give a follower's force loop a bandwidth and a phase margin.

    Args:
        model: The :class:`ClosedLoopModel` of the scene (its followers' motion-loop gains are kept).
        bandwidth_rad_s: Target -3 dB bandwidth ``omega_b`` of setpoint to measured force [rad/s].
        phase_margin_deg: Target phase margin of the loop [deg], in (0, 180).
        follower: Arm index (0-based) of the follower (default: the first).
        component: Wrench component designed for (default: the grip normal, :func:`default_component`).

    Returns:
        :class:`ForceLoopDesign`.

    Raises:
        TuningError: a target out of range.
        UnachievableDesign: the bandwidth is beyond the control rate (``>= pi / T``) or above
            the elastic mode the loop acts through, or no gains reach both targets (the
            closest found is reported, with the likely limit).
    """
    from scipy.optimize import least_squares

    if not (np.isfinite(bandwidth_rad_s) and bandwidth_rad_s > 0):
        raise TuningError("bandwidth_rad_s", bandwidth_rad_s, "a bandwidth > 0 rad/s")
    if not (0 < phase_margin_deg < 180):
        raise TuningError("phase_margin_deg", phase_margin_deg, "a phase margin in (0, 180) deg")
    if not model.followers:
        raise TuningError("model", model.scenario.name, "a scene with a follower")
    follower = model.followers[0] if follower is None else follower
    if follower not in model.followers:
        raise TuningError("follower", follower, f"a follower arm index (0-based): one of {list(model.followers)}")
    component = default_component(model, follower) if component is None else component
    c = names.component_index(model.space, component)
    target = {"bandwidth_rad_s": float(bandwidth_rad_s), "phase_margin_deg": float(phase_margin_deg)}
    T = model.control_period
    nyquist = np.pi / T
    if bandwidth_rad_s >= nyquist:
        raise UnachievableDesign(target, f"beyond the control rate: the sampled loop acts only below the Nyquist "
                                         f"frequency pi / T = {nyquist:.4g} rad/s (T = {T:g} s); shorten "
                                         "simulation.control_period or lower the bandwidth")
    modes = elastic_modes(model.scenario.plant(), model.operating_point.x)
    k = modes.seen_by(follower, c)
    w_e = float(modes.natural_frequencies[k])
    if bandwidth_rad_s >= w_e:
        raise UnachievableDesign(target, f"above the elastic mode the loop acts through ({w_e:.4g} rad/s, "
                                         f"{modes.dominant_coordinate(k)}, damping {modes.damping_ratios[k]:.3g}): the "
                                         "force loop would drive the grasp at its resonance; lower the bandwidth or "
                                         "stiffen the interconnection (springs[*].stiffness)")
    ev = _Evaluator(model, follower, component)

    def residual(theta):
        kp, ki = theta[0], np.exp(theta[1])
        bw, pm = ev(kp, ki)
        if not (np.isfinite(bw) and np.isfinite(pm)):
            return np.array([10.0, 10.0])
        return np.array([np.log(bw / bandwidth_rad_s), (pm - phase_margin_deg) / 30.0])

    seeds = sorted(((float(np.sum(residual((kp, np.log(ki))) ** 2)), kp, ki) for kp in KP_GRID for ki in KI_GRID))
    best = None
    for _, kp0, ki0 in seeds[:SEEDS]:
        sol = least_squares(residual, x0=[kp0, np.log(ki0)], bounds=([0.0, -5.0], [1e3, 12.0]), diff_step=1e-4,
                            xtol=1e-10, ftol=1e-10, max_nfev=MAX_EVALUATIONS)
        if best is None or sol.cost < best.cost:
            best = sol
        kp, ki = best.x[0], float(np.exp(best.x[1]))
        bw, pm = ev(kp, ki)
        if abs(bw / bandwidth_rad_s - 1) <= BANDWIDTH_TOLERANCE and abs(pm - phase_margin_deg) <= PHASE_MARGIN_TOLERANCE:
            break
    else:
        closest = {"bandwidth_rad_s": bw, "phase_margin_deg": pm, "force_kp": kp, "force_ki": ki}
        wm = model.scenario.controllers.followers.natural_frequency
        if bandwidth_rad_s > wm:
            why = (f"the bandwidth is above the followers' motion loop (controllers.followers.natural_frequency = "
                   f"{wm:g} rad/s), whose lag eats the phase margin; raise that natural frequency or lower the target")
        else:
            why = "no force_kp >= 0, force_ki > 0 give both on this loop; relax one of the targets"
        raise UnachievableDesign(target, why, closest)
    fl = force_loop(model, follower, component, kp, ki, modes=modes)
    others = tuple(force_loop(model, follower, other, kp, ki, modes=modes)
                   for other in names.WRENCH[model.space] if other != component)
    gains = Gains(follower_force_loop=True, follower_force_kp=float(kp), follower_force_ki=float(ki))
    return ForceLoopDesign(gains=gains, force_loop=fl, target=target, other_components=others)
