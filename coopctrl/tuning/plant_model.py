"""The plant alone, linearized about a scene's nominal state (continuous time, no controller).

.. math::
    \\delta\\dot x = A\\, \\delta x + B\\, \\delta\\tau, \\qquad \\delta y = C\\, \\delta x

``(A, B)`` are :meth:`CooperativePlant.jacobians` (central differences of the right-hand
side); ``C`` maps the state to the named outputs: the object pose ``object_*`` [m, rad], every
contact node's pose ``armK_node_*`` [m, rad] and every arm's interconnection wrench
``armK_F*``/``armK_M*`` [N, N m] (world frame, as the wrist sensors read it; with damping it
depends on the rates). The input ``tau`` is about the holding torques of the nominal state.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning import signal_names as names

#: Central-difference step of the output map on poses and rates [m, rad, m/s, rad/s].
STEP = 1e-7


@dataclass(frozen=True, eq=False)
class PlantModel:
    """A linearized plant.

    Attributes:
        system: Continuous ``control.StateSpace`` with named states (``arm1_q1`` ...,
            ``object_x`` ..., ``darm1_q1`` ...), inputs (``arm1_tau1`` ... [N m]) and outputs
            (see the module docstring).
        x: The nominal state it is linearized about.
        tau: The holding torques there [N m]: every arm's computed torque for zero node
            acceleration, ``tau_i = h_i + J_i^T (w_free_i + S_i)``.
        residual: ``max |f(x, tau)|`` [m/s^2, rad/s^2]: 0 at an equilibrium; not 0 where the
            object itself is not at rest (e.g. the unloaded state, in which gravity is not yet
            carried by the interconnections). The linear model leaves it out.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    system: object
    x: np.ndarray
    tau: np.ndarray
    residual: float

    def discretize(self, control_period: float):
        """``control.c2d`` with a zero-order hold at ``control_period`` [s], names kept."""
        import control

        sys = control.c2d(self.system, control_period, method="zoh")
        return control.ss(sys.A, sys.B, sys.C, sys.D, control_period, states=list(self.system.state_labels),
                          inputs=list(self.system.input_labels), outputs=list(self.system.output_labels),
                          name=f"{self.system.name}_zoh")


def nominal_state(scenario) -> np.ndarray:
    """The state the linear plant is taken about: the scene's loaded initial state, or the
    unloaded state for an immobile scene (docs/model.md s.3, 4.5) or ``simulation.start = "unloaded"``."""
    from coopctrl.scenario import build

    if scenario.scene.unloaded_state == "immobile":
        return build.unloaded_state(scenario)
    return build.initial_state(scenario)


def holding_torques(plant, x) -> np.ndarray:
    """Torques that give every arm's node zero acceleration at ``x`` [N m]."""
    from coopctrl.controllers import node_computed_torque

    terms = plant.control_terms(x)
    tau = np.zeros(plant.input_size)
    for i in range(plant.arm_count):
        tau[plant.q_slice(i)] = node_computed_torque(plant, terms, i, np.zeros(plant.p))
    return tau


def _outputs(plant, x) -> np.ndarray:
    p, nz = plant.p, plant.nz
    return np.concatenate([x[nz - p:nz], plant.node_poses(x)[p:], plant.control_terms(x).Fw.reshape(-1)])


def output_names(space: str, arms: int) -> list[str]:
    return (names.object_pose(space) + [n for i in range(arms) for n in names.node_pose(space, i)]
            + [n for i in range(arms) for n in names.wrench(space, i)])


def linearize_plant(scenario, x=None) -> PlantModel:
    """:class:`PlantModel` of ``scenario``'s plant about ``x`` (default: :func:`nominal_state`)."""
    import control

    plant = scenario.plant()
    x = nominal_state(scenario) if x is None else np.asarray(x, dtype=float)
    tau = holding_torques(plant, x)
    A, B = plant.jacobians(x, tau)
    y0 = _outputs(plant, x)
    C = np.empty((y0.size, x.size))
    for k in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[k] += STEP
        xm[k] -= STEP
        C[:, k] = (_outputs(plant, xp) - _outputs(plant, xm)) / (2 * STEP)
    system = control.ss(A, B, C, np.zeros((C.shape[0], B.shape[1])), states=plant.state_names(),
                        inputs=plant.input_names(), outputs=output_names(plant.space, plant.arm_count),
                        name=f"{scenario.name}_plant")
    residual = float(np.max(np.abs(plant.rhs(0.0, x, tau))))
    return PlantModel(system=system, x=x, tau=tau, residual=residual)
