"""A small step on the actual nonlinear closed loop, next to the linear model's prediction.

The step is injected with the probes of :mod:`~coopctrl.tuning.loop_probes` into the loop
that ``coopctrl run`` builds for the held scene (same plant, QP, controllers, ZOH and
integrator), started at the linear model's operating point (state and follower integrals).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.controllers.probes import probe_errors
from coopctrl.tuning import signal_names as names
from coopctrl.tuning.errors import TuningError
from coopctrl.tuning.loop_probes import probed_closed_loop


@dataclass(frozen=True, eq=False)
class StepComparison:
    """Responses to the same step: nonlinear loop and linear model, as deviations from the
    operating point.

    Attributes:
        input: The stepped input's name; amplitude: its step [m, rad, N or N m].
        t: (N,) sample times [s] (the control ticks).
        outputs: Output names (columns).
        nonlinear: (N, n_y) deviations of the nonlinear loop.
        linear: (N, n_y) the linear model's response.
        status: The nonlinear run's status (``"ok"`` or why it stopped).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    input: str
    amplitude: float
    t: np.ndarray
    outputs: list
    nonlinear: np.ndarray
    linear: np.ndarray
    status: str

    def columns(self, outputs) -> list[int]:
        names = [outputs] if isinstance(outputs, str) else list(outputs)
        missing = [n for n in names if n not in self.outputs]
        if missing:
            raise TuningError("outputs", missing, f"names among {', '.join(self.outputs)}")
        return [self.outputs.index(n) for n in names]

    def relative_error(self, outputs) -> float:
        """``max_t,k |y_nl - y_lin| / max_t,k |y_lin|`` over the named outputs ``k`` [-].

        The error of the linear prediction relative to the peak of the predicted response of
        that group of outputs (a group shares one unit, e.g. ``["arm2_Fx", "arm2_Fz"]``).
        """
        c = self.columns(outputs)
        lin, nl = self.linear[:, c], self.nonlinear[:, c]
        return float(np.max(np.abs(nl - lin)) / np.max(np.abs(lin)))


def simulate_step(model, input: str, amplitude: float, duration: float, force_kp=None, force_ki=None) -> StepComparison:
    """Step ``input`` by ``amplitude`` at t = 0 on the nonlinear loop and on ``model.closed()``.

    Args:
        model: A :class:`~coopctrl.tuning.closed_loop_model.ClosedLoopModel`.
        input: ``armL_ref_<axis>`` (leader target offset [m, rad]) or ``armF_setpoint_<component>``
            (follower setpoint offset [N, N m]).
        amplitude: Size of the step; small, for the linear model to hold.
        duration: Simulated time [s].
        force_kp, force_ki: Follower PI gains (scalars) for both runs (default: the scene's).

    Returns:
        :class:`StepComparison` with every output of the model.
    """
    import control

    from coopctrl.scenario.loader import scenario_from_dict

    sys = model.closed(force_kp, force_ki)
    if input not in sys.input_labels:
        raise TuningError("input", input, f"one of {', '.join(sys.input_labels)}")
    scenario = model.scenario
    kp0, ki0 = model.force_gains
    if force_kp is not None or force_ki is not None:
        kp = kp0 if force_kp is None else float(force_kp)
        ki = ki0 if force_ki is None else float(force_ki)
        scenario = scenario_from_dict(scenario.to_dict(), overrides={
            "controllers.followers.force_kp": kp, "controllers.followers.force_ki": ki,
            "controllers.followers.force_loop": True})
    else:
        kp, ki = kp0, ki0
    loop, leader, followers = probed_closed_loop(scenario)
    op = model.operating_point
    p = model.p
    nf_out = len(model.plain_outputs)
    v_eq = op.pi_output
    e_eq = op.outputs[nf_out:]
    integrals = {}
    for k, i in enumerate(model.followers):
        sl = slice(p * k, p * (k + 1))
        # the integral that gives the equilibrium PI output with these gains
        integrals[i] = (v_eq[sl] - kp * e_eq[sl]) / ki if ki > 0 else np.zeros(p)
    prefix, kind, comp = input.split("_", 2)
    c = sys.input_labels.index(input)
    if kind == "ref":
        leader.offset[names.axis_index(model.space, comp)] = amplitude
    else:
        followers[int(prefix[3:]) - 1].setpoint_offset[names.component_index(model.space, comp)] = amplitude
    rec = loop.run(op.x, duration, integrals=integrals)
    errors = probe_errors(rec, loop)
    n = len(rec["t"])
    plant = loop.plant
    nz = plant.nz
    y = np.empty((n, sys.noutputs))
    for k in range(n):
        xk = rec["x"][k]
        y[k, :nf_out] = np.concatenate([xk[nz - p:nz], plant.node_poses(xk)[p:], rec["F_measured"][k].reshape(-1)])
        y[k, nf_out:] = np.concatenate([errors[i][k] for i in model.followers]) if model.followers else []
    y -= op.outputs
    U = np.zeros((sys.ninputs, n))
    U[c] = amplitude
    lin = np.asarray(control.forced_response(sys, rec["t"], U).outputs).T
    return StepComparison(input=input, amplitude=float(amplitude), t=rec["t"], outputs=list(sys.output_labels),
                          nonlinear=y, linear=lin.reshape(n, -1), status=rec["status"])
