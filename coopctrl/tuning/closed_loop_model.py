"""The linear model of a scene's closed loop: discrete time, ``dt`` = the control period.

Built in two steps (:func:`linearize_closed_loop`):

1. The *opened* loop: the held scene (:func:`~coopctrl.tuning.operating_point.hold_scenario`)
   with the followers' PI removed, linearized over one control period of the actual
   :class:`~coopctrl.closed_loop.ClosedLoop` about its equilibrium
   (:mod:`~coopctrl.tuning.one_period_map`, :mod:`~coopctrl.tuning.operating_point`). The
   leader's computed torque, the followers' motion loops and feedforward, the QP, the ZOH and
   the integrator are inside it as the code implements them.
2. The followers' PI, which is linear and exactly as :class:`FollowerForceController`
   implements it (the integral is updated before it is used):

   .. math::
       I_k = I_{k-1} + T e_k, \\qquad v_k = k_p e_k + k_i I_k

   i.e. with the state ``s_k = I_{k-1}`` (``armF_force_integral_*``):
   ``s_{k+1} = s_k + T e_k``, ``v_k = k_i s_k + (k_p + k_i T) e_k``. It is closed in
   :meth:`ClosedLoopModel.closed` for any gains, per component, so that force-loop gains can
   be designed without re-linearizing. The inner-loop gains (leader and follower natural
   frequency and damping) are those of the scene: change them and linearize again.

All signals are deviations from the operating point. Names: :mod:`~coopctrl.tuning.signal_names`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning import signal_names as names
from coopctrl.tuning.errors import TuningError
from coopctrl.tuning.one_period_map import OnePeriodMap
from coopctrl.tuning.operating_point import OperatingPoint, find_operating_point, hold_scenario, opened_scenario


def _gain_vector(value, n: int, name: str) -> np.ndarray:
    g = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy() if np.ndim(value) == 0 else np.asarray(value, float)
    if g.shape != (n,) or not np.all(np.isfinite(g)) or np.any(g < 0):
        raise TuningError(name, value, f"a gain >= 0 or {n} gains >= 0 (one per follower component)")
    return g


@dataclass(frozen=True, eq=False)
class ClosedLoopModel:
    """The linearized closed loop of a scene, with the followers' PI as a separate block.

    Attributes:
        scenario: The held scene the model is about (:func:`hold_scenario`), with its gains.
        opened: ``control.StateSpace`` (``dt = T``) of the loop without the followers' PI.
            Inputs: the leader's target offset ``armL_ref_*`` [m, rad], each follower's
            setpoint offset ``armF_setpoint_*`` [N, N m] and PI output ``armF_pi_*`` [N, N m].
            Outputs: ``object_*``, ``armK_node_*`` [m, rad], ``armK_F*``/``armK_M*``
            [N, N m] and each follower's ``armF_force_error_*`` [N, N m].
        operating_point: The equilibrium it is linearized about.
        control_period: ``T`` [s].
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    scenario: object
    opened: object
    operating_point: OperatingPoint
    control_period: float

    # ------------------------------------------------------------------ views
    @property
    def space(self) -> str:
        return self.scenario.space

    @property
    def p(self) -> int:
        return self.scenario.pose_size

    @property
    def leader(self) -> int:
        return self.scenario.leader

    @property
    def followers(self) -> tuple[int, ...]:
        return tuple(self.scenario.followers)

    @property
    def force_gains(self) -> tuple[float, float]:
        """``(k_p, k_i)`` of the scene (zeros if its force loop is off)."""
        f = self.scenario.controllers.followers
        return (f.force_kp, f.force_ki) if f.force_loop else (0.0, 0.0)

    # ------------------------------------------------------------------ closing the PI
    def closed(self, force_kp=None, force_ki=None, open_loop: tuple[int, str] | None = None):
        """The closed loop with the followers' PI gains (default: the scene's).

        Args:
            force_kp, force_ki: Scalars (every follower component) or one gain per follower
                component (stacked by follower, then component) [-], [1/s].
            open_loop: ``(follower arm index, component)``, e.g. ``(1, "Fx")``, to leave that
                one loop open: its ``armF_pi_C`` stays an input and ``armF_force_error_C``
                an output (the loop-at-a-time break point of the force-loop margins).

        The operating point is the equilibrium of the scene's gains. With ``k_i > 0`` it is the
        equilibrium for any gains (``e = 0`` and the same PI output ``v`` there); a P-only
        component (``k_i = 0``) would rest at ``e = v / k_p`` instead, a shift of the
        operating point that the model leaves out (``v`` at rest is below 1e-9 N in the
        two-arm scenes, 0.3 N in the three-arm one).

        Returns:
            ``control.StateSpace`` with ``dt = T``; states: the plant's and
            ``armF_force_integral_*`` [N s] of the closed components with ``k_i > 0``;
            inputs: ``armL_ref_*``, ``armF_setpoint_*``
            (and the opened ``armF_pi_C``); outputs: the opened model's.
        """
        import control

        sys = self.opened
        T = self.control_period
        kp0, ki0 = self.force_gains
        nu = len(self.reference_inputs)
        nv = sys.ninputs - nu
        kp = _gain_vector(kp0 if force_kp is None else force_kp, nv, "force_kp")
        ki = _gain_vector(ki0 if force_ki is None else force_ki, nv, "force_ki")
        n_out = len(self.plain_outputs)
        A, B, C, D = (np.asarray(M) for M in (sys.A, sys.B, sys.C, sys.D))
        Bu, Bv = B[:, :nu], B[:, nu:]
        Ce, Deu = C[n_out:], D[n_out:, :nu]  # the force errors e = Ce x + Deu u (v does not enter e_k)
        keep = np.ones(nv, dtype=bool)
        if open_loop is not None:
            keep[self._pi_index(*open_loop)] = False
        cl = np.flatnonzero(keep)  # the closed components
        it = cl[ki[cl] > 0]  # those with an integral state (a P-only component has none)
        Ke = np.diag(kp[cl] + ki[cl] * T)
        Ks = np.diag(ki[it])
        Bvc, Bvi = Bv[:, cl], Bv[:, it]
        Dv = D[:, nu:]
        ns = it.size
        Acl = np.block([[A + Bvc @ Ke @ Ce[cl], Bvi @ Ks], [T * Ce[it], np.eye(ns)]])
        Bcl = np.vstack([Bu + Bvc @ Ke @ Deu[cl], T * Deu[it]])
        Ccl = np.hstack([C + Dv[:, cl] @ Ke @ Ce[cl], Dv[:, it] @ Ks])
        Dcl = D[:, :nu] + Dv[:, cl] @ Ke @ Deu[cl]
        integ = [n for i in self.followers for n in names.force_integral(self.space, i)]
        states = list(sys.state_labels) + [integ[k] for k in it]
        inputs = list(self.reference_inputs)
        if open_loop is not None:
            k = self._pi_index(*open_loop)
            Bcl = np.hstack([Bcl, np.vstack([Bv[:, [k]], np.zeros((ns, 1))])])
            Dcl = np.hstack([Dcl, D[:, [nu + k]]])
            inputs.append(sys.input_labels[nu + k])
        return control.ss(Acl, Bcl, Ccl, Dcl, T, states=states, inputs=inputs, outputs=list(sys.output_labels),
                          name=f"{self.scenario.name}_closed_loop")

    def _pi_index(self, follower: int, component: str) -> int:
        if follower not in self.followers:
            raise TuningError("follower", follower, f"a follower arm index (0-based): one of {list(self.followers)}")
        c = names.component_index(self.space, component)
        return self.followers.index(follower) * self.p + c

    # ------------------------------------------------------------------ signal lists
    @property
    def reference_inputs(self) -> list[str]:
        """The inputs of :meth:`closed`: leader target offset, then follower setpoint offsets."""
        return [n for n in self.opened.input_labels if "_pi_" not in n]

    @property
    def plain_outputs(self) -> list[str]:
        """Outputs other than the force errors."""
        return [n for n in self.opened.output_labels if "_force_error_" not in n]


def linearize_closed_loop(scenario, overrides: dict | None = None) -> ClosedLoopModel:
    """Linearize a scene's closed loop about its equilibrium holding the initial pose.

    Args:
        scenario: A :class:`~coopctrl.scenario.Scenario` (its trajectory and sensor noise are
            replaced: see :func:`hold_scenario`).
        overrides: Optional dotted overrides applied first, e.g. the output of
            :meth:`Gains.as_overrides` (``{"controllers.leader.natural_frequency": 60.0}``).

    Returns:
        The :class:`ClosedLoopModel`. Its cost is about ``2 (n_x + n_u)`` control periods
        of the loop per Newton iteration (tens of milliseconds for the shipped scenes).
    """
    import control

    if overrides:
        scenario = apply_overrides(scenario, overrides)
    held = hold_scenario(scenario)
    f = held.controllers.followers
    period_map = OnePeriodMap(opened_scenario(held))
    op, (A, B, C, D) = find_operating_point(period_map, f.force_kp, f.force_ki, f.force_loop)
    opened = control.ss(A, B, C, D, period_map.T, states=period_map.state_names,
                        inputs=period_map.input_names + period_map.pi_names,
                        outputs=period_map.output_names + period_map.error_names,
                        name=f"{scenario.name}_opened_loop")
    return ClosedLoopModel(scenario=held, opened=opened, operating_point=op, control_period=period_map.T)


def apply_overrides(scenario, overrides: dict):
    """``scenario`` with dotted overrides applied (``load_scenario`` semantics), validated."""
    from coopctrl.scenario.loader import scenario_from_dict

    return scenario_from_dict(scenario.to_dict(), source=scenario.source, overrides=overrides)
