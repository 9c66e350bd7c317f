"""Probes: wrappers of the leader and follower controllers that inject test signals into the
actual :class:`~coopctrl.closed_loop.ClosedLoop` and record what the followers see.

They let the linear models and the checks against the nonlinear loop use the loop exactly as
``coopctrl run`` runs it (same plant, QP, controllers, ZOH and integrator). The compiled tick reads
a probe's signals (leader ``offset``; follower ``setpoint_offset``, ``pi_output``, ``error_gain``,
``measurement_delay``) as inputs of the run, constant over it; the followers' errors of a run are read
from its record (:func:`probe_errors`), never written back into the probes. :meth:`LeaderProbe.torque`
and :meth:`FollowerProbe.torque` state the same arithmetic for one tick in Python. With every injected
signal at zero, a probe returns the torques of the controller it wraps.
"""

from __future__ import annotations

from collections import deque

import numpy as np


def probe_errors(record, loop) -> dict[int, np.ndarray]:
    """Each follower's force error of a run, ``F* + r - F_meas`` at every recorded tick (true, undelayed):
    arm index -> (N, p) [N, N m].

    ``F*`` and ``F_meas`` are the record's ``F_commanded`` and ``F_measured`` (N, m, p); ``r`` is the
    follower's :attr:`FollowerProbe.setpoint_offset` (zero for a follower without a probe).

    Args:
        record: The :class:`~coopctrl.loop.record.LoopRecord` of a run of ``loop``.
        loop: The :class:`~coopctrl.closed_loop.ClosedLoop` that ran it (its followers, probed or not).
    """
    out = {}
    for i, c in loop.followers.items():
        if isinstance(c, FollowerProbe):
            out[i] = (record["F_commanded"][:, i] + c.setpoint_offset) - record["F_measured"][:, i]
        else:
            out[i] = record["F_commanded"][:, i] - record["F_measured"][:, i]
    return out


class LeaderProbe:
    """The leader's computed torque toward ``Y_v^N + offset``.

    Attributes:
        offset: (p,) offset [m, rad] added to the leader's target pose ``Y_v^N`` (the
            reference input of the leader's tracking loop).
    """

    def __init__(self, leader):
        self.inner = leader
        self.index = leader.index
        self.offset = np.zeros(leader.plant.p)

    def torque(self, terms, Y_ref, dY_ref, ddY_ref):
        return self.inner.torque(terms, Y_ref + self.offset, dY_ref, ddY_ref)


class FollowerProbe:
    """A follower's force controller with its setpoint offset, its loop opened or scaled.

    Each tick the wrapped :class:`~coopctrl.controllers.FollowerForceController` receives

    .. math::
        F' = F^* + r + v, \\qquad
        F_{meas}' = F' - g \\odot (F' - F_{meas}(t - d\\,T))

    so its error is ``e' = g (F' - F_meas(t - d T))``.

    Attributes:
        setpoint_offset: ``r`` (p,) [N, N m], a step in the follower's force setpoint.
        pi_output: ``v`` (p,) [N, N m]. In a loop built with ``force_kp = force_ki = 0``
            the follower's correction is ``F^* + r + v``: ``v`` then stands for the output of
            the PI, which the linear model closes itself (the *opened* loop).
        error_gain: ``g`` (p,) [-], scales the error per component: the gain of that loop
            (both ``k_p`` and ``k_i``) multiplied by ``g`` (1 = unchanged).
        measurement_delay: ``d`` (p,) integers >= 0, extra delay of the measured force
            per component in control periods (0 = none).
        errors: ``F^* + r - F_meas`` of every tick :meth:`torque` ran since :meth:`clear` (true,
            undelayed) [N, N m]; a run of the loop leaves it alone: :func:`probe_errors` reads a run's.
    """

    def __init__(self, follower):
        self.inner = follower
        self.index = follower.index
        p = follower.plant.p
        self.setpoint_offset = np.zeros(p)
        self.pi_output = np.zeros(p)
        self.error_gain = np.ones(p)
        self.measurement_delay = np.zeros(p, dtype=int)
        self.errors: list[np.ndarray] = []
        self._history: deque = deque()

    @property
    def integral(self) -> np.ndarray:
        """The wrapped controller's error integral [N s] (its state)."""
        return self.inner.integral

    def reset(self) -> None:
        """Zero the integral, the delay line and the record."""
        self.inner.reset()
        self.clear()

    def clear(self) -> None:
        self.errors.clear()
        self._history.clear()

    def torque(self, terms, F_set, F_meas, Y_rigid, dY_ref, ddY_ref, Y0, dt):
        F_sp = F_set + self.setpoint_offset
        self.errors.append(F_sp - F_meas)
        seen = F_meas
        d_max = int(self.measurement_delay.max())
        if d_max > 0:
            self._history.append(np.array(F_meas, dtype=float))
            while len(self._history) > d_max + 1:
                self._history.popleft()
            seen = np.array([self._history[max(len(self._history) - 1 - int(d), 0)][c]
                             for c, d in enumerate(self.measurement_delay)])
        F_cmd = F_sp + self.pi_output
        F_seen = F_cmd - self.error_gain * (F_cmd - seen)
        return self.inner.torque(terms, F_cmd, F_seen, Y_rigid, dY_ref, ddY_ref, Y0, dt)
