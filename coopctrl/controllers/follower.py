"""A follower arm: elastic-force regulation around a computed-torque motion loop (docs/model.md s.6)."""

from __future__ import annotations

import numpy as np

from coopctrl._core import follower_correction, pose_increment, tracking_acceleration
from coopctrl.controllers.computed_torque import PostureTask, _vector, arm_torque
from coopctrl.errors import ScenarioError


class FollowerForceController:
    """Drive the wrench of follower ``i``'s interconnection to its QP setpoint ``F_i^*``.

    Outer force loop (PI on the wrench error, in displacement units through the grasp
    compliance ``C_i = K_i^+`` of :class:`GraspCompliance`):

    .. math::
        e = F_i^* - F_i^{meas}, \\quad
        \\delta = C_i \\big(k_p e + k_i \\textstyle\\int e\\, dt\\big), \\quad
        Y_i^{cmd} = \\underbrace{Y_i^{rigid} + C_i F_i^*}_{\\text{feedforward}} + \\delta

    Inner motion loop: computed torque tracking ``Y_i^cmd`` with ``omega_m``, ``zeta_m``
    (as :class:`LeaderController`).

    Bandwidth. The interconnection turns a node displacement into a wrench through
    ``K_i``: ``F = K_i (Y_i - Y_i^{rigid})``. With the motion loop ``M(s) = omega_m^2 /
    (s^2 + 2 zeta_m omega_m s + omega_m^2)`` the force loop is

    .. math:: L(s) = \\Big(k_p + \\frac{k_i}{s}\\Big) M(s)

    so for ``omega_m >> k_i`` the force error decays at ``omega_F ~ k_i / (1 + k_p)`` [rad/s]
    and the static error of a pure P loop is ``1 / (1 + k_p)``. The elastic mode of the
    grasp, ``omega_e = sqrt(k / m_eff)`` (node against object), sets the ceiling: the motion loop must
    stay below it (``omega_m < omega_e``) so that the computed torque does not excite the
    interconnection, and the force loop below the motion loop (``omega_F < omega_m / 3``).

    With ``force_loop=False`` the follower only tracks the feedforward pose (position control).

    The law is the loop's own, in the C++ core (``coopctrl._core.follower_correction``, ``pose_increment``,
    ``tracking_acceleration``, ``arm_torque``, coopctrl/core/control_laws.h): :meth:`torque` calls it.

    A redundant follower (7 joints in space) runs the same inner loop with the dynamically
    consistent inverse and the damped null-space posture task of :class:`PostureTask`, through
    the projector ``P^T = I - J^T J^{#T}``, ``J^# = N^-1 J^T (J N^-1 J^T)^-1``
    (:func:`node_computed_torque`): the posture torque moves neither the node nor, through it,
    the interconnection's force.
    """

    def __init__(self, plant, index: int, compliance, kp: float, ki: float, natural_frequency: float,
                 damping_ratio: float, force_loop: bool = True, integral_limit: float = 1e3):
        for name, value in (("force_kp", kp), ("force_ki", ki)):
            if not value >= 0:
                raise ScenarioError(f"controllers.followers.{name}", value, "a gain >= 0")
        if not natural_frequency > 0:
            raise ScenarioError("controllers.followers.natural_frequency", natural_frequency, "a frequency > 0 rad/s")
        if not damping_ratio > 0:
            raise ScenarioError("controllers.followers.damping_ratio", damping_ratio, "a ratio > 0")
        self.plant = plant
        self.index = index
        self.compliance = compliance
        self.kp = float(kp)
        self.ki = float(ki)
        self.force_loop = bool(force_loop)
        self.Kp = natural_frequency**2
        self.Kd = 2.0 * damping_ratio * natural_frequency
        self.integral_limit = integral_limit  # [N s] anti-windup bound on each component
        self.integral = np.zeros(plant.p)
        self.posture = PostureTask(plant, index)

    def reset(self) -> None:
        self.integral[:] = 0.0
        self.posture.reset()

    def torque(self, terms, F_set, F_meas, Y_rigid, dY_ref, ddY_ref, Y0, dt: float) -> np.ndarray:
        """Follower torques [N m]; updates the integral of the force error over ``dt`` [s]."""
        k = self.index + 1
        p = self.plant.p
        correction = np.empty(p)
        follower_correction(_vector("F_set", F_set, p), _vector("F_meas", F_meas, p), self.integral, float(dt),
                            self.kp, self.ki, float(self.integral_limit), self.force_loop, correction)
        Y_rigid = _vector("Y_rigid", Y_rigid, p)
        Y0 = _vector("Y0", Y0, p)
        C = np.ascontiguousarray(self.compliance.C[self.index])
        spatial = self.plant.space == "spatial"
        # follower_acceleration_into: target = pose_increment(corr) + Y_rigid, then the tracking law toward it
        target = np.empty(p)
        if not pose_increment(spatial, C, correction, Y0, Y_rigid, target):
            self.compliance.pose_increment(self.index, correction, Y0, Y_rigid)  # raises EulerSingularityError
        target += Y_rigid
        a = np.empty(p)
        tracking_acceleration(target, np.ascontiguousarray(terms.Y[k]), _vector("dY_ref", dY_ref, p),
                              np.ascontiguousarray(terms.dY[k]), _vector("ddY_ref", ddY_ref, p), self.Kp, self.Kd,
                              3 if spatial else 2, np.empty(p), a)
        return arm_torque(self.plant, terms, self.index, a, self.posture)
