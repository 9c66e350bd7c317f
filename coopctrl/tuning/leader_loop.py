"""The leader's tracking loop: poles, damping and step response on the closed-loop model."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning import signal_names as names
from coopctrl.tuning.leader_error_model import error_poles


def second_order_step(natural_frequency: float, damping_ratio: float) -> dict:
    """Step figures of ``omega_n^2 / (s^2 + 2 zeta omega_n s + omega_n^2)``: overshoot [-] (fraction
    of the final value), peak time [s] and 2 % settling time ``4 / (zeta omega_n)`` [s]."""
    wn, z = float(natural_frequency), float(damping_ratio)
    if z < 1:
        wd = wn * np.sqrt(1 - z * z)
        overshoot, peak = float(np.exp(-np.pi * z / np.sqrt(1 - z * z))), float(np.pi / wd)
    else:
        overshoot, peak = 0.0, float("inf")
    return {"overshoot": overshoot, "peak_time_s": peak, "settling_time_s": 4.0 / (z * wn)}


@dataclass(frozen=True, eq=False)
class LeaderLoop:
    """The leader's tracking loop along one pose coordinate.

    Attributes:
        axis: The pose coordinate (``"x"``, ``"theta"`` ...).
        natural_frequency, damping_ratio: The scene's leader gains ``omega_n`` [rad/s], ``zeta`` [-].
        closed_loop: SISO ``control.StateSpace`` (``dt = T``) from the target offset
            ``armL_ref_<axis>`` [m or rad] to the node pose ``armL_node_<axis>``, the whole
            closed loop (object, followers) included.
        poles: Every pole of the closed loop (``z``).
        design_poles: The two poles of the sampled error model
            (:mod:`~coopctrl.tuning.leader_error_model`) with these gains (``z``).
        dominant_poles: The two closed-loop poles nearest to ``design_poles`` (``z``).
        dominant_frequency, dominant_damping: ``omega_n`` [rad/s] and ``zeta`` [-] of the
            dominant poles (:func:`equivalent_second_order`).
        step: ``control.step_response`` of ``closed_loop``.
        step_info: ``control.step_info`` of ``step`` (overshoot in percent, times in s).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    axis: str
    natural_frequency: float
    damping_ratio: float
    closed_loop: object
    poles: np.ndarray
    design_poles: np.ndarray
    dominant_poles: np.ndarray
    dominant_frequency: float
    dominant_damping: float
    step: object
    step_info: dict

    @property
    def predicted_step(self) -> dict:
        """:func:`second_order_step` of the dominant poles."""
        return second_order_step(self.dominant_frequency, self.dominant_damping)

    def damping_table(self):
        """``control.damp`` of every closed-loop pole: ``(omega_n [rad/s], zeta, poles)``."""
        import control

        return control.damp(self.closed_loop, doprint=False)

    def summary(self) -> dict:
        return {"axis": self.axis, "natural_frequency_rad_s": self.natural_frequency,
                "damping_ratio": self.damping_ratio, "dominant_frequency_rad_s": self.dominant_frequency,
                "dominant_damping": self.dominant_damping,
                "overshoot_percent": float(self.step_info["Overshoot"]),
                "settling_time_s": float(self.step_info["SettlingTime"])}


def leader_loop(model, axis: str | None = None, duration: float | None = None) -> LeaderLoop:
    """:class:`LeaderLoop` of ``model`` (a :class:`ClosedLoopModel`) along ``axis`` (default: the
    first coordinate, ``"x"``); the step response covers ``duration`` [s] (default 8 / (zeta
    omega_n), twice the 2 % settling time of the design)."""
    import control

    space = model.space
    axis = names.POSE[space][0] if axis is None else axis
    names.axis_index(space, axis)
    lead = model.scenario.controllers.leader
    wn, zeta = lead.natural_frequency, lead.damping_ratio
    T = model.control_period
    sys = model.closed()
    inp = f"{names.arm(model.leader)}_ref_{axis}"
    out = f"{names.arm(model.leader)}_node_{axis}"
    siso = sys[sys.output_labels.index(out), sys.input_labels.index(inp)]
    siso = control.ss(siso.A, siso.B, siso.C, siso.D, T, states=list(sys.state_labels), inputs=[inp], outputs=[out],
                      name=f"leader_{axis}_tracking")
    poles = siso.poles()
    design = error_poles(wn, zeta, T)
    dominant = []
    pool = list(range(len(poles)))
    for zd in design:
        k = min(pool, key=lambda j: abs(poles[j] - zd))
        dominant.append(poles[k])
        pool.remove(k)
    dominant = np.array(dominant)
    wn_dom, zeta_dom = equivalent_second_order(dominant, T)
    if duration is None:
        duration = 8.0 / (zeta * wn)
    t = np.arange(int(round(duration / T)) + 1) * T
    step = control.step_response(siso, t)
    return LeaderLoop(axis=axis, natural_frequency=wn, damping_ratio=zeta, closed_loop=siso, poles=poles,
                      design_poles=design, dominant_poles=dominant, dominant_frequency=wn_dom,
                      dominant_damping=zeta_dom, step=step,
                      step_info=control.step_info(np.asarray(step.outputs).reshape(-1), step.time))


def equivalent_second_order(pair, control_period: float) -> tuple[float, float]:
    """``(omega_n, zeta)`` of the continuous pair ``s = log(z) / T`` of two discrete poles ``z``:
    ``omega_n = sqrt(s_1 s_2)``, ``zeta = -(s_1 + s_2) / (2 omega_n)`` (the ``s^2 + 2 zeta omega_n s
    + omega_n^2`` they are the roots of; ``zeta >= 1`` for two real poles)."""
    s = np.log(np.asarray(pair, dtype=complex)) / control_period
    wn = float(np.sqrt(abs((s[0] * s[1]).real)))
    return wn, float(-(s[0] + s[1]).real / (2 * wn))
