"""The leader arm: computed torque tracking its nominal node trajectory (docs/model.md s.6)."""

from __future__ import annotations

import numpy as np

from coopctrl._core import tracking_acceleration
from coopctrl.controllers.computed_torque import PostureTask, _vector, arm_torque
from coopctrl.errors import ScenarioError


class LeaderController:
    """Computed torque on the full model for the leader ``v``:

    .. math::
        a_{cmd} = \\ddot Y_v^N + K_d (\\dot Y_v^N - \\dot Y_v) + K_p (Y_v^N - Y_v), \\quad
        K_p = \\omega_n^2, \\; K_d = 2 \\zeta \\omega_n

    then :func:`node_computed_torque`: the loop's own law, in the C++ core (``coopctrl._core.tracking_acceleration``
    and ``arm_torque``, coopctrl/core/control_laws.h), which :meth:`acceleration` and :meth:`torque` call.
    ``Y_v^N`` is the nominal leader node trajectory: the
    object's nominal motion carried to the grasp (148) plus the nominal deformation that makes
    the leader's interconnection carry its QP share. With an exact model the node error obeys
    ``e'' + 2 zeta omega_n e' + omega_n^2 e = 0``.

    A redundant leader (7 joints in space) tracks the 6-D node pose with the dynamically
    consistent inverse and adds the damped null-space posture task of :class:`PostureTask`
    through the projector ``P^T = I - J^T J^{#T}``, ``J^# = N^-1 J^T (J N^-1 J^T)^-1``
    (:func:`node_computed_torque`): the posture torque does not accelerate the node.

    Args:
        plant: The cooperative plant (the controller's model).
        index: The leader's arm index.
        natural_frequency: ``omega_n`` [rad/s] > 0.
        damping_ratio: ``zeta`` [-] > 0.
    """

    def __init__(self, plant, index: int, natural_frequency: float, damping_ratio: float):
        if not natural_frequency > 0:
            raise ScenarioError("controllers.leader.natural_frequency", natural_frequency, "a frequency > 0 rad/s")
        if not damping_ratio > 0:
            raise ScenarioError("controllers.leader.damping_ratio", damping_ratio, "a ratio > 0")
        self.plant = plant
        self.index = index
        self.Kp = natural_frequency**2
        self.Kd = 2.0 * damping_ratio * natural_frequency
        self.posture = PostureTask(plant, index)

    def reset(self) -> None:
        self.posture.reset()

    def acceleration(self, terms, Y_ref, dY_ref, ddY_ref) -> np.ndarray:
        """Commanded node acceleration ``a_cmd`` [m/s^2, rad/s^2] toward the node reference ``Y_ref`` [m, rad],
        ``dY_ref`` [m/s, rad/s], ``ddY_ref`` [m/s^2, rad/s^2] at ``terms`` (the plant's control terms):
        ``coopctrl._core.tracking_acceleration`` (coopctrl/core/control_laws.h).
        In the loop ``Y_ref`` is the nominal deformed node pose,
        ``GraspCompliance.deformation(index, F*, Y0^N, Y_v^N)``."""
        k = self.index + 1
        p = self.plant.p
        target = _vector("Y_ref", Y_ref, p)
        a = np.empty(p)
        tracking_acceleration(target, np.ascontiguousarray(terms.Y[k]), _vector("dY_ref", dY_ref, p),
                              np.ascontiguousarray(terms.dY[k]), _vector("ddY_ref", ddY_ref, p), self.Kp, self.Kd,
                              3 if self.plant.space == "spatial" else 2, np.empty(p), a)
        return a

    def torque(self, terms, Y_ref, dY_ref, ddY_ref) -> np.ndarray:
        """Leader torques [N m] for the reference ``(Y_ref, dY_ref, ddY_ref)`` of its node: what the loop
        applies (before saturation) for the same terms and reference."""
        return arm_torque(self.plant, terms, self.index, self.acceleration(terms, Y_ref, dY_ref, ddY_ref),
                          self.posture)
