"""The one-period map of the actual closed loop, and its Jacobians by central differences.

One control period of :class:`~coopctrl.closed_loop.ClosedLoop` takes the plant state ``x_k``
to ``x_{k+1}``: sensors, the load-distribution QP, the leader and the followers compute the
torques at ``t_k``, which are held (ZOH) while the plant is integrated with the scene's
integrator and substeps. :class:`OnePeriodMap` evaluates exactly that by calling
``ClosedLoop.run(x_k, T)`` (one period) on a loop whose controllers are wrapped by
:mod:`~coopctrl.tuning.loop_probes`, and reads ``x_{k+1}`` and the outputs at ``t_k``.

Its Jacobians are the discrete-time linear model (``dt = T``)

.. math::
    \\delta x_{k+1} = A\\, \\delta x_k + B\\, \\delta u_k, \\qquad
    \\delta y_k = C\\, \\delta x_k + D\\, \\delta u_k

with no approximation of the controllers, the ZOH or the integrator beyond the
linearization itself.
"""

from __future__ import annotations

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.controllers.probes import probe_errors
from coopctrl.tuning import signal_names as names
from coopctrl.tuning.errors import TuningError
from coopctrl.tuning.loop_probes import probed_closed_loop

#: Central-difference steps per kind of signal: poses [m, rad], rates [m/s, rad/s], wrenches [N, N m].
STEP_POSE = 1e-6
STEP_RATE = 1e-6
STEP_WRENCH = 1e-4


class OnePeriodMap:
    """``(x_k, u_k) -> (x_{k+1}, y_k)`` of a scene's closed loop, held at its initial pose.

    Inputs ``u`` (stacked in this order):

    - the leader's target offset ``armL_ref_*`` (p) [m, rad];
    - per follower, its setpoint offset ``armF_setpoint_*`` (p) [N, N m];
    - per follower, its PI output ``armF_pi_*`` (p) [N, N m] (see
      :class:`~coopctrl.tuning.loop_probes.FollowerProbe`).

    The followers' force loops are *opened*: the scene must have ``force_kp = force_ki = 0``
    (:func:`~coopctrl.tuning.operating_point.opened_scenario`), so that the follower's
    correction is ``F* + r + v`` and the PI, a linear block, is closed by the linear model.

    Outputs ``y`` at ``t_k``: the object pose (p), every contact node's pose (m p), every
    arm's interconnection wrench (m p), every follower's force error ``F* + r - F_meas`` (p each).

    Args:
        scenario: A held scene (:func:`~coopctrl.tuning.operating_point.hold_scenario`).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    def __init__(self, scenario):

        f = scenario.controllers.followers
        if f.force_kp != 0 or f.force_ki != 0:
            raise TuningError("scenario.controllers.followers", (f.force_kp, f.force_ki),
                              "an opened scene with force_kp = force_ki = 0 (see opened_scenario)")
        self.scenario = scenario
        self.loop, self.leader, self.followers = probed_closed_loop(scenario)
        plant = self.loop.plant
        self.plant = plant
        self.space = plant.space
        self.p = p = plant.p
        self.m = plant.arm_count
        self.follower_indices = tuple(sorted(self.followers))
        self.T = self.loop.T
        nf = len(self.follower_indices)
        self.nu = p * (1 + nf)
        self.nv = p * nf
        sp = self.space
        self.state_names = plant.state_names()
        self.input_names = names.leader_reference(sp, self.leader.index) + [
            n for i in self.follower_indices for n in names.force_setpoint(sp, i)]
        self.pi_names = [n for i in self.follower_indices for n in names.pi_output(sp, i)]
        self.output_names = (names.object_pose(sp) + [n for i in range(self.m) for n in names.node_pose(sp, i)]
                             + [n for i in range(self.m) for n in names.wrench(sp, i)])
        self.error_names = [n for i in self.follower_indices for n in names.force_error(sp, i)]
        nz = plant.nz
        self.state_steps = np.r_[np.full(nz, STEP_POSE), np.full(nz, STEP_RATE)]
        self.input_steps = np.r_[np.full(p, STEP_POSE), np.full(self.nu - p + self.nv, STEP_WRENCH)]

    # ------------------------------------------------------------------ one period
    def __call__(self, x, u=None, v=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(x_{k+1}, y_k, tau_k)`` from ``x_k`` and the inputs (zeros when None)."""
        p = self.p
        u = np.zeros(self.nu) if u is None else np.asarray(u, dtype=float)
        v = np.zeros(self.nv) if v is None else np.asarray(v, dtype=float)
        self.leader.offset = u[:p]
        for k, i in enumerate(self.follower_indices):
            probe = self.followers[i]
            probe.setpoint_offset = u[p * (k + 1):p * (k + 2)]
            probe.pi_output = v[p * k:p * (k + 1)]
            probe.inner.reset()
            probe.clear()
        rec = self.loop.run(np.asarray(x, dtype=float), self.T)
        if rec["status"] != "ok":
            raise ArithmeticError(f"one control period from the given state failed: {rec['reason']}")
        x0 = rec["x"][0]
        Y = self.plant.node_poses(x0)
        nz = self.plant.nz
        errors = probe_errors(rec, self.loop)
        y = np.concatenate([x0[nz - p:nz], Y[p:], rec["F_measured"][0].reshape(-1)]
                           + [errors[i][0] for i in self.follower_indices])
        return rec["x"][1].copy(), y, rec["tau"][0].copy()

    # ------------------------------------------------------------------ Jacobians
    def jacobians(self, x, u=None, v=None):
        """``(A, B, C, D)`` of the map at ``(x, u, v)`` by central differences.

        ``B`` and ``D`` have the columns of ``u`` then ``v``; ``C`` and ``D`` have the rows
        of the outputs then the force errors. Steps: :data:`STEP_POSE` on poses,
        :data:`STEP_RATE` on rates, :data:`STEP_WRENCH` on wrench inputs.
        """
        x = np.asarray(x, dtype=float)
        u = np.zeros(self.nu) if u is None else np.asarray(u, dtype=float)
        v = np.zeros(self.nv) if v is None else np.asarray(v, dtype=float)
        nx = x.size
        w = np.concatenate([u, v])
        x1, y, _ = self(x, u, v)
        ny = y.size
        A = np.empty((nx, nx))
        C = np.empty((ny, nx))
        B = np.empty((nx, w.size))
        D = np.empty((ny, w.size))
        for k in range(nx):
            h = self.state_steps[k] * max(1.0, abs(x[k]))
            xp, xm = x.copy(), x.copy()
            xp[k] += h
            xm[k] -= h
            (a, c, _), (b, d, _) = self(xp, u, v), self(xm, u, v)
            A[:, k] = (a - b) / (2 * h)
            C[:, k] = (c - d) / (2 * h)
        for k in range(w.size):
            h = self.input_steps[k]
            wp, wm = w.copy(), w.copy()
            wp[k] += h
            wm[k] -= h
            (a, c, _), (b, d, _) = self(x, wp[:self.nu], wp[self.nu:]), self(x, wm[:self.nu], wm[self.nu:])
            B[:, k] = (a - b) / (2 * h)
            D[:, k] = (c - d) / (2 * h)
        return A, B, C, D
