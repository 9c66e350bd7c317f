"""The load-distribution QP's contact inputs for the loaded start and the pre-flight (before or outside the tick).

- :func:`contact_normals`: each contact node's inward normal (its frame's approach axis), for the
  ``min_grip`` and ``friction`` families;
- :func:`torque_model`: the ``torque_limits`` family's rows ``tau_i = Jg_i^T F_i + bias_i`` at the
  nominal node accelerations, planned within :data:`TORQUE_HEADROOM` of each joint's limit
  (:class:`TorqueModel`: the same into one reused workspace).

Both are defined once, in the compiled core (coopctrl/core/qp_contact_model.h, which the compiled tick calls on its
measured terms): the functions here only give them the arrays of a
:class:`~plants.cooperative.control_terms.ControlTerms` and return the Python structures
:class:`~coopctrl.load_distribution.LoadDistribution` takes.
"""

from __future__ import annotations

import numpy as np

from coopctrl.controllers._kernels import control_work
from coopctrl._core import contact_normals_into, torque_model_into  # coopctrl/core/qp_contact_model.h

#: Fraction of each joint torque limit the load-distribution QP may plan with [-].
TORQUE_HEADROOM = 0.9


def qp_torque_limits(plant) -> list[np.ndarray]:
    """Each arm's torque limits [N m] the QP plans with: ``TORQUE_HEADROOM * tau_max``; the applied
    torques are saturated at ``tau_max`` itself (actuators), leaving the rest for the feedback terms."""
    return [TORQUE_HEADROOM * np.asarray(a.tau_max, dtype=float) for a in plant.arms]


def _f64(a) -> np.ndarray:
    """``a`` as a C-contiguous float64 array (the compiled tick's argument type; no copy if it is one)."""
    return np.ascontiguousarray(a, dtype=np.float64)


def contact_normals(plant, terms) -> np.ndarray:
    """Inward unit contact normals (m, npos): each node's approach axis (its frame's x axis), from the
    node poses ``terms.Y`` [m, rad] (the core's ``contact_normals_into``)."""
    spatial = plant.space == "spatial"
    out = np.empty((plant.arm_count, 3 if spatial else 2))
    contact_normals_into(_f64(terms.Y), spatial, out, np.empty((3, 3)))
    return out


def torque_model(plant, terms, ddYn) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """QP torque-limit rows ``(jacobians, biases)``: ``tau_i = Jg_i^T F_i + bias_i`` [N m] with the nominal
    node accelerations ``ddYn`` ((m+1, p) [m/s^2, rad/s^2]); ``Jg_i`` (p, n_i) maps the joint rates to the
    node's world twist, ``bias_i = H_i qdd_i + h_i + J_i^T (W_i ddYn_i + w_free_i)`` (n_i,) with ``qdd_i``
    the joint acceleration that tracks ``ddYn_i`` (zero where the arm is singular)
    (the core's ``torque_model_into``). New arrays; :class:`TorqueModel`
    reuses one workspace from call to call."""
    jacobians, biases = TorqueModel(plant)(terms, ddYn)
    return [J.copy() for J in jacobians], [b.copy() for b in biases]


class TorqueModel:
    """:func:`torque_model` of one plant into one workspace, allocated once: a call returns
    ``(jacobians, biases)`` as views of that workspace, overwritten by the next call (pre-flight calls it
    at every sample)."""

    def __init__(self, plant):
        self.spatial = plant.space == "spatial"
        self.arm_kind, self.arm_dof = plant.plant_args.arm_kind, plant.plant_args.arm_dof
        p = plant.p
        dofs = [int(n) for n in self.arm_dof]
        nmax = max(p, *dofs)
        self.Jg = np.zeros((plant.arm_count, p, nmax))
        self.bias = np.zeros(sum(dofs))
        offsets = np.concatenate(([0], np.cumsum(dofs)))
        self.jacobians = [self.Jg[i, :, :n] for i, n in enumerate(dofs)]
        self.biases = [self.bias[offsets[i]:offsets[i + 1]] for i in range(len(dofs))]
        wv, wm = control_work(nmax)
        self.scratch = (np.empty(p), np.empty(p), np.empty(nmax), np.empty(nmax, np.int64), wv, wm, np.empty((3, 3, 3)))

    def __call__(self, terms, ddYn) -> tuple[list[np.ndarray], list[np.ndarray]]:
        torque_model_into(self.spatial, _f64(terms.Y), _f64(ddYn), _f64(terms.W), _f64(terms.w_free),
                          _f64(terms.H), _f64(terms.h), _f64(terms.J), _f64(terms.Jdq), self.arm_kind, self.arm_dof,
                          self.Jg, self.bias, *self.scratch)
        return self.jacobians, self.biases
