"""The loaded start: the state at rest at t = 0 with the grasps already carrying the planned split.

:func:`loaded_state` places the object on its nominal pose ``Y_0^N(0)``, solves the load-distribution
QP of t = 0 (the wrench ``w_N`` that holds the object, the desired squeeze, and the scenario's
families), deflects each contact node by its compliance so that its interconnection carries its share
``F_i`` (:meth:`GraspCompliance.deformation`), and reaches it by inverse kinematics seeded with the
unloaded configuration. Velocities are zero.

It needs only the loop's parts (plant, trajectory, grasps, QP settings, compliance), never a built loop,
so the scenario layer plans a loaded start without the simulator (``coopctrl.scenario.build.initial_state``)
and :meth:`ClosedLoop.loaded_state <coopctrl.closed_loop.ClosedLoop.loaded_state>` gives the same state.
"""

from __future__ import annotations

import numpy as np

from coopctrl.controllers import GraspCompliance, required_object_wrench
from coopctrl.load_distribution import LoadDistribution
from coopctrl.loop.qp_inputs import contact_normals, qp_torque_limits, torque_model
from plants.cooperative import ContactPoint, nominal_node_motion


def loaded_state(plant, trajectory, grasps, ld_config, compliance, torque_limits: bool, x_unloaded) -> np.ndarray:
    """The loaded state at rest at t = 0, as the controllers plan it (module docstring).

    Args:
        plant: The :class:`~plants.cooperative.CooperativePlant`.
        trajectory: Object trajectory with ``evaluate(t) -> (Y, dY, ddY)``.
        grasps: (m, p) grasp poses in the object frame, as the controllers know them.
        ld_config: The :class:`~coopctrl.load_distribution.LoadDistributionConfig` (split, squeeze, families).
        compliance: :class:`~coopctrl.controllers.GraspCompliance` of the plant.
        torque_limits: Whether the QP carries the torque-limit family.
        x_unloaded: The unloaded state: the inverse kinematics' seeds.

    Computed once per plant for the same parts (:func:`coopctrl.derived.derived`) when the trajectory is a shipped
    one and the compliance a :class:`~coopctrl.controllers.GraspCompliance`; a new array each call.

    Raises:
        InfeasibleLoad: no split of t = 0 exists.
        UnreachablePoseError: an arm cannot reach its loaded node pose.
    """
    from coopctrl.derived import derived, immutable

    grasps = np.array(grasps, dtype=float)
    x_unloaded = np.array(x_unloaded, dtype=float)

    def compute():
        x = _loaded_state(plant, trajectory, grasps, ld_config, compliance, torque_limits, x_unloaded)
        x.flags.writeable = False
        return x

    if not immutable(trajectory) or type(compliance) is not GraspCompliance:
        return compute().copy()
    key = ("loaded_state", trajectory, grasps.shape, grasps.tobytes(), ld_config, compliance.K.tobytes(),
           compliance.C.tobytes(), bool(torque_limits), x_unloaded.tobytes())
    return derived(plant, key, compute).copy()


def _loaded_state(plant, trajectory, grasps, ld_config, compliance, torque_limits: bool, x_unloaded) -> np.ndarray:
    """:func:`loaded_state`, computed."""
    space = plant.space
    p, m = plant.p, plant.arm_count
    npos = 3 if space == "spatial" else 2
    el = plant.elastic
    grasps = np.asarray(grasps, dtype=float)
    Y0N, dY0N, ddY0N = trajectory.evaluate(0.0)
    Yn = nominal_node_motion(Y0N, dY0N, ddY0N, grasps, space)[0]
    w_N = required_object_wrench(space, float(el.node_params[0, 0]), el.node_params[0, 1:].copy(), el.gravity.copy(),
                                 Y0N, dY0N, ddY0N)
    ld = LoadDistribution(ld_config, space, m)
    terms = plant.control_terms(x_unloaded)
    kwargs = {}
    if ld_config.min_grip is not None or ld_config.friction_coefficient is not None:
        kwargs["normals"] = contact_normals(plant, terms)
    if torque_limits:
        kwargs["jacobians"], kwargs["biases"] = torque_model(plant, terms, np.zeros((m + 1, p)))
        kwargs["tau_max"] = qp_torque_limits(plant)
    if ld_config.split == "elastic":
        kwargs["K"] = compliance.stiffness_world(Y0N)
    F = ld.solve(Yn[1:, :npos], Y0N[:npos], w_N, **kwargs).F
    x = np.array(x_unloaded, dtype=float)
    nz = plant.nz
    x[nz:] = 0.0
    x[nz - p:nz] = Y0N
    for i, arm in enumerate(plant.arms):
        Yi = compliance.deformation(i, F[i], Y0N, Yn[i + 1])
        sl = plant.q_slice(i)
        x[sl] = arm.inverse_kinematics(Yi, x_unloaded[sl]) if not isinstance(arm, ContactPoint) else Yi
    return x
