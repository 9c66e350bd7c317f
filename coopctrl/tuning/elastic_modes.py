"""The elastic modes of the grasp: the object vibrating on its interconnections.

The leader's and the followers' computed-torque loops move the contact nodes as commanded,
cancelling the arms' dynamics and the interconnection forces at the nodes, so the elastic
dynamics that remain are those of the object on its interconnections with the contact nodes
held (docs/model.md s.3, linearized about ``Y``):

.. math::
    W_0\\, \\ddot y_0 + D_{00}\\, \\dot y_0 + K_{00}\\, y_0 = 0

with ``K_00 = dF_e,0/dY_0`` (:meth:`ElasticSystem.node_stiffness`), ``D_00 = dF_d,0/d(dY_0)``
and ``W_0`` the object's inertia block. The closed-loop model has poles within a few percent
of these (``tests/test_tuning.py`` checks it); they are the ceiling of the force loops.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from coopctrl.compact_repr import compact_repr
from coopctrl.tuning import signal_names as names

#: Central-difference step on the object's pose and rate [m, rad, m/s, rad/s].
STEP = 1e-7


@dataclass(frozen=True, eq=False)
class ElasticModes:
    """Modes of the object on its interconnections, contact nodes held; sorted by frequency.

    Attributes:
        natural_frequencies: ``omega_n`` [rad/s] per mode.
        damping_ratios: ``zeta`` [-] per mode.
        shapes: (p, n_modes) mode shapes in the object's pose coordinates, largest entry 1.
        coordinates: Names of the pose coordinates (rows of ``shapes``).
        modal_masses: ``shape^T W_0 shape`` per mode [kg or kg m^2].
        wrench_per_mode: (m, p, n_modes) change of each arm's measured wrench [N, N m] per unit
            of the mode's shape: which loop sees which mode.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    natural_frequencies: np.ndarray
    damping_ratios: np.ndarray
    shapes: np.ndarray
    coordinates: list
    modal_masses: np.ndarray
    wrench_per_mode: np.ndarray

    def dominant_coordinate(self, mode: int) -> str:
        """The pose coordinate that moves most in ``mode`` (``"object_x"``)."""
        return self.coordinates[int(np.argmax(np.abs(self.shapes[:, mode])))]

    def seen_by(self, arm: int, component: int) -> int:
        """The mode that changes wrench ``component`` of ``arms[arm]`` most per unit of modal
        amplitude with mass-normalized shapes (``|dF| / sqrt(modal mass)``): the elastic mode
        that this force loop acts through."""
        return int(np.argmax(np.abs(self.wrench_per_mode[arm, component]) / np.sqrt(self.modal_masses)))


def elastic_modes(plant, x) -> ElasticModes:
    """The :class:`ElasticModes` of ``plant`` at state ``x`` (its node poses)."""
    p, nz = plant.p, plant.nz
    x = np.asarray(x, dtype=float)
    Y = plant.node_poses(x).reshape(-1, p)
    el = plant.elastic
    K = el.node_stiffness(Y, 0)
    W = el.inertia(Y)[:p, :p]
    Dm = np.empty((p, p))
    dY = np.zeros_like(Y)
    for a in range(p):
        dp, dm = dY.copy(), dY.copy()
        dp[0, a], dm[0, a] = STEP, -STEP
        Dm[:, a] = (el.damping_force(Y, dp)[:p] - el.damping_force(Y, dm)[:p]) / (2 * STEP)
    Winv = np.linalg.inv(W)
    A = np.block([[np.zeros((p, p)), np.eye(p)], [-Winv @ K, -Winv @ Dm]])
    lam, V = np.linalg.eig(A)
    keep = [k for k in range(2 * p) if lam[k].imag > 0 or (lam[k].imag == 0)]  # one of each pair
    keep = sorted(keep, key=lambda k: abs(lam[k]))
    freqs = np.array([abs(lam[k]) for k in keep])
    damp = np.array([-lam[k].real / abs(lam[k]) if abs(lam[k]) > 0 else 1.0 for k in keep])
    shapes = np.empty((p, len(keep)))
    for c, k in enumerate(keep):
        v = V[:p, k]
        j = int(np.argmax(np.abs(v)))
        v = (v * np.conj(v[j]) / abs(v[j])).real
        shapes[:, c] = v / np.max(np.abs(v))
    modal = np.einsum("im,ij,jm->m", shapes, W, shapes)
    # wrench per unit of each shape: d F_meas / d Y_0 (object pose perturbed, nodes held)
    m = plant.arm_count
    G = np.empty((m, p, p))
    for a in range(p):
        xp, xm = x.copy(), x.copy()
        xp[nz - p + a] += STEP
        xm[nz - p + a] -= STEP
        G[:, :, a] = (plant.control_terms(xp).Fw - plant.control_terms(xm).Fw) / (2 * STEP)
    return ElasticModes(natural_frequencies=freqs, damping_ratios=damp, shapes=shapes,
                        coordinates=names.object_pose(plant.space), modal_masses=modal, wrench_per_mode=G @ shapes)
