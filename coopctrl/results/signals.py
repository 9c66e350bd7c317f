"""The named signals of a result, with units: one table behind ``result.csv``,
:meth:`SimulationResult.to_pandas` and :meth:`SimulationResult.to_time_response`.

Numbering is the scenario's: arms (contacts) are 1..m in the order of ``[[arms]]`` (as in
``springs.pair``, where node k is arm k), joints are 1..n_i within their arm, contact pairs are
``i_j`` with arms i < j. Wrenches are on the object, in the world frame, at the contact node
(``plants.cooperative.CooperativePlant.contact_wrenches``); planar scenes use ``(x, z, theta)``
poses and ``(fx, fz, my)`` wrenches in the x-z plane.

Signals, per sample (N at the control rate):

- ``Y0_<c>`` / ``Y0_nominal_<c>``: object pose and its nominal trajectory [m] or [rad];
- ``Y0_qw``, ``Y0_qx``, ``Y0_qy``, ``Y0_qz`` (spatial): the object's rotation as a unit quaternion [-]
  (``SimulationResult.object_quaternion``, sign-continuous);
- ``Y0d_<c>``: object velocity, the rate of its pose coordinates [m/s] or [rad/s];
- ``node_arm<i>_<c>``: the node (end-effector) pose of arm i [m] or [rad];
- ``q_arm<i>_j<k>`` [rad], ``qd_arm<i>_j<k>`` [rad/s]: joint angles and rates;
- ``tau_arm<i>_j<k>`` [N m]: joint torques;
- ``F_measured_arm<i>_<c>``, ``F_commanded_...``, ``F_external_...``, ``F_internal_...``
  [N] or [N m]: contact wrenches (measured, commanded by the QP, its external and internal parts);
- ``squeeze_<i>_<j>`` [N] measured squeeze of the pair, ``squeeze_desired_<i>_<j>`` [N];
- ``qp_iterations`` [-], ``qp_solve_time_s`` [s], ``energy`` [J] (passive runs).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult


def pose_names(p: int) -> list[str]:
    """Coordinate names of a pose (docs/model.md §2)."""
    return ["x", "z", "theta"] if p == 3 else ["x", "y", "z", "psi", "theta", "phi"]


def wrench_names(p: int) -> list[str]:
    """Component names of a wrench."""
    return ["fx", "fz", "my"] if p == 3 else ["fx", "fy", "fz", "mx", "my", "mz"]


def pose_unit(name: str) -> str:
    """``m`` for a position coordinate, ``rad`` for an angle."""
    return "m" if name in ("x", "y", "z") else "rad"


def wrench_unit(name: str) -> str:
    """``N`` for a force component, ``N m`` for a moment."""
    return "N" if name.startswith("f") else "N m"


def dof_per_arm(result: "SimulationResult") -> list[int]:
    """Joints per arm (from ``result.model``; one block if it is unknown)."""
    dofs = list(result.model.get("dof_per_arm", [])) if result.model else []
    return [int(n) for n in dofs] if dofs and sum(dofs) == result.tau.shape[1] else [int(result.tau.shape[1])]


def joint_labels(result: "SimulationResult") -> list[str]:
    """``arm<i>_j<k>`` for every joint, in the order of ``tau`` (arms 1..m, joints 1..n_i)."""
    return [f"arm{a + 1}_j{j + 1}" for a, n in enumerate(dof_per_arm(result)) for j in range(n)]


def pair_labels(m: int) -> list[str]:
    """``<i>_<j>`` for the contact pairs i < j (arms numbered 1..m), lexicographic."""
    return [f"{i + 1}_{j + 1}" for i in range(m) for j in range(i + 1, m)]


def signals(result: "SimulationResult") -> list[tuple[str, str, np.ndarray]]:
    """``(name, unit, values (N,))`` for every signal, in a fixed order (module docstring)."""
    r = result
    n, p, m = r.t.shape[0], r.pose_size, r.arms
    out: list[tuple[str, str, np.ndarray]] = []
    for prefix, Y in (("Y0", r.Y0), ("Y0_nominal", r.Y0_nominal)):
        out += [(f"{prefix}_{c}", pose_unit(c), Y[:, k]) for k, c in enumerate(pose_names(p))]
    quaternion = r.object_quaternion
    if quaternion is not None:
        out += [(f"Y0_q{c}", "-", quaternion[:, k]) for k, c in enumerate("wxyz")]
    joints = joint_labels(r)
    nq = len(joints)
    if r.x.shape[1] == 2 * nq + 2 * p:  # x = col(q, Y0, q', Y0')
        half = r.x.shape[1] // 2
        out += [(f"Y0d_{c}", pose_unit(c) + "/s", r.x[:, half + nq + k]) for k, c in enumerate(pose_names(p))]
    if r.Y_nodes is not None:
        out += [(f"node_arm{i + 1}_{c}", pose_unit(c), r.Y_nodes[:, i, k])
                for i in range(m) for k, c in enumerate(pose_names(p))]
    if r.x.shape[1] >= 2 * nq + 2 * p:
        half = r.x.shape[1] // 2
        out += [(f"q_{lab}", "rad", r.x[:, j]) for j, lab in enumerate(joints)]
        out += [(f"qd_{lab}", "rad/s", r.x[:, half + j]) for j, lab in enumerate(joints)]
    out += [(f"tau_{lab}", "N m", r.tau[:, j]) for j, lab in enumerate(joints)]
    for field in ("F_measured", "F_commanded", "F_external", "F_internal"):
        W = getattr(r, field)
        out += [(f"{field}_arm{k + 1}_{c}", wrench_unit(c), W[:, k, i])
                for k in range(m) for i, c in enumerate(wrench_names(p))]
    pairs = pair_labels(m) if r.squeeze.shape[1] == m * (m - 1) // 2 else [str(k + 1) for k in range(r.squeeze.shape[1])]
    out += [(f"squeeze_{lab}", "N", r.squeeze[:, k]) for k, lab in enumerate(pairs)]
    out += [(f"squeeze_desired_{lab}", "N", np.full(n, r.squeeze_desired[k])) for k, lab in enumerate(pairs)]
    for field, unit in (("qp_iterations", "-"), ("qp_solve_time_s", "s"), ("energy", "J")):
        value = getattr(r, field)
        if value is not None and value.shape[0] == n:
            out.append((field, unit, value))
    return out
