"""A follower's force loop: loop transfer function, margins, bandwidth and the elastic mode.

One wrench component ``C`` of follower ``F`` is analysed with every other loop closed (the
leader's tracking loop, the other components and the other followers: loop-at-a-time). With
the plant part ``P(z)`` from the PI output ``v_C`` to the force error ``e_C``
(:meth:`ClosedLoopModel.closed` with ``open_loop``), and the discrete PI of
:class:`~coopctrl.controllers.FollowerForceController`

.. math::
    K(z) = k_p + k_i T \\frac{z}{z - 1}, \\qquad L(z) = -K(z)\\, P(z)

(``e = F* - F_meas`` falls when ``v`` rises, so ``-P`` is the plant in negative feedback).
The closed force loop is the transfer function from the setpoint offset ``armF_setpoint_C``
to the measured wrench ``armF_C`` (it includes the feedforward ``C_i F*`` of the follower).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning import signal_names as names
from coopctrl.tuning.elastic_modes import elastic_modes
from coopctrl.tuning.errors import TuningError
from coopctrl.tuning.frequency import Margins, bandwidth, margins


def discrete_pi(force_kp: float, force_ki: float, control_period: float, name: str = "force_pi"):
    """The follower's PI as a ``control.StateSpace`` (``dt = T``): state ``s_k = I_{k-1}`` [N s],
    ``s_{k+1} = s_k + T e_k``, ``v_k = k_i s_k + (k_p + k_i T) e_k`` (no state if ``k_i = 0``)."""
    import control

    T = control_period
    if force_ki == 0:  # P only: no state
        return control.ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[force_kp]], T, name=name)
    return control.ss([[1.0]], [[T]], [[force_ki]], [[force_kp + force_ki * T]], T, name=name)


def default_component(model, follower: int) -> str:
    """The world wrench component most aligned with the follower's approach axis (its node
    frame's x axis, the grip normal) at the operating point: ``"Fx"`` for the shipped scenes."""
    from plants.frames import rotation_zyx

    p = model.p
    plant = model.scenario.plant()
    Y = plant.node_poses(model.operating_point.x).reshape(-1, p)[follower + 1]
    if model.space == "spatial":
        axis = rotation_zyx(Y[3:6])[:, 0]
    else:
        axis = np.array([np.cos(Y[2]), np.sin(Y[2])])
    return names.WRENCH[model.space][int(np.argmax(np.abs(axis)))]


@dataclass(frozen=True, eq=False)
class ForceLoop:
    """One force loop of one follower.

    Attributes:
        follower: The follower's arm index (0-based); component: ``"Fx"`` ...
        force_kp, force_ki: The PI gains analysed [-], [1/s].
        loop: ``L(z)``, SISO ``control.StateSpace`` (``dt = T``).
        closed_loop: SISO ``control.StateSpace`` from ``armF_setpoint_C`` [N] to ``armF_C`` [N].
        margins: :class:`~coopctrl.tuning.frequency.Margins` of ``loop``.
        bandwidth: -3 dB bandwidth of ``closed_loop`` [rad/s].
        elastic_mode: Natural frequency [rad/s] of the elastic mode this loop acts through
            (:meth:`ElasticModes.seen_by`); elastic_damping: its damping ratio [-];
            elastic_coordinate: the object coordinate that mode moves most.
        highest_elastic_mode: The highest elastic mode of the grasp [rad/s].
        nyquist: ``pi / T`` [rad/s], the highest frequency the sampled loop can act at.
        stable: Whether every pole of the closed loop is inside the unit circle.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    follower: int
    component: str
    force_kp: float
    force_ki: float
    loop: object
    closed_loop: object
    margins: Margins
    bandwidth: float
    elastic_mode: float
    elastic_damping: float
    elastic_coordinate: str
    highest_elastic_mode: float
    nyquist: float
    stable: bool

    @property
    def bandwidth_ratio(self) -> float:
        """``bandwidth / elastic_mode`` [-]: below 1 the loop works below the grasp's resonance."""
        return self.bandwidth / self.elastic_mode

    def summary(self) -> dict:
        m = self.margins
        return {"follower": self.follower, "component": self.component, "force_kp": self.force_kp,
                "force_ki_1_s": self.force_ki, "gain_margin": m.gain_margin, "gain_margin_db": m.gain_margin_db,
                "phase_crossover_rad_s": m.phase_crossover, "phase_margin_deg": m.phase_margin,
                "gain_crossover_rad_s": m.gain_crossover, "delay_margin_s": m.delay_margin,
                "bandwidth_rad_s": self.bandwidth, "elastic_mode_rad_s": self.elastic_mode,
                "elastic_mode_damping": self.elastic_damping, "elastic_mode_coordinate": self.elastic_coordinate,
                "bandwidth_over_elastic_mode": self.bandwidth_ratio, "nyquist_rad_s": self.nyquist,
                "stable": self.stable}


def force_loop(model, follower: int | None = None, component: str | None = None, force_kp=None, force_ki=None,
               modes=None) -> ForceLoop:
    """:class:`ForceLoop` of ``model`` (a :class:`ClosedLoopModel`).

    Args:
        follower: Arm index (0-based) of the follower (default: the first).
        component: Wrench component (default: :func:`default_component`).
        force_kp: Proportional gain [-] for every follower component (default: the scene's).
        force_ki: Integral gain [1/s] for every follower component (default: the scene's).
        modes: Precomputed :func:`elastic_modes` at the operating point (computed if None).
    """
    import control

    if not model.followers:
        raise TuningError("follower", follower, "a scene with a follower (this one has none)")
    follower = model.followers[0] if follower is None else follower
    if follower not in model.followers:
        raise TuningError("follower", follower, f"a follower arm index (0-based): one of {list(model.followers)}")
    component = default_component(model, follower) if component is None else component
    c = names.component_index(model.space, component)
    kp0, ki0 = model.force_gains
    kp = kp0 if force_kp is None else float(force_kp)
    ki = ki0 if force_ki is None else float(force_ki)
    T = model.control_period
    arm = names.arm(follower)
    opened = model.closed(kp, ki, open_loop=(follower, component))
    P = opened[opened.output_labels.index(f"{arm}_force_error_{component}"),
               opened.input_labels.index(f"{arm}_pi_{component}")]
    L = -(P * discrete_pi(kp, ki, T))
    L = control.ss(L.A, L.B, L.C, L.D, T, inputs=[f"{arm}_force_error_{component}"],
                   outputs=[f"{arm}_loop_{component}"], name=f"{arm}_{component}_force_loop")
    closed = model.closed(kp, ki)
    Tcl = closed[closed.output_labels.index(f"{arm}_{component}"), closed.input_labels.index(f"{arm}_setpoint_{component}")]
    Tcl = control.ss(Tcl.A, Tcl.B, Tcl.C, Tcl.D, T, states=list(closed.state_labels),
                     inputs=[f"{arm}_setpoint_{component}"], outputs=[f"{arm}_{component}"],
                     name=f"{arm}_{component}_closed_force_loop")
    stable = bool(np.max(np.abs(closed.poles())) < 1.0)
    if modes is None:
        modes = elastic_modes(model.scenario.plant(), model.operating_point.x)
    k = modes.seen_by(follower, c)
    return ForceLoop(follower=follower, component=component, force_kp=kp, force_ki=ki, loop=L, closed_loop=Tcl,
                     margins=margins(L), bandwidth=bandwidth(Tcl) if stable else float("nan"),
                     elastic_mode=float(modes.natural_frequencies[k]), elastic_damping=float(modes.damping_ratios[k]),
                     elastic_coordinate=modes.dominant_coordinate(k),
                     highest_elastic_mode=float(np.max(modes.natural_frequencies)), nyquist=float(np.pi / T),
                     stable=stable)
