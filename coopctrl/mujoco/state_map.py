"""The exact map between the loop's plant state and MuJoCo's ``qpos``, ``qvel`` (docs/mujoco.md).

The loop's state is ``x = (q, Y_0, dq, dY_0)`` (:class:`~plants.cooperative.CooperativePlant`): the joint
angles of every arm in arm order, the object's pose ``Y_0`` and their rates. The contact nodes are not
in it: they are the arms' node frames, ``Y_i = Phi_i(q_i)`` (169), computed by the loop from ``q``.
The model of :func:`coopctrl.mujoco.mjcf.scene_mjcf` puts the arms' joints first, in the same order,
then the object's joint, so:

- ``qpos[:n_q] = q``, ``qvel[:n_q] = dq`` (every arm joint is a MuJoCo hinge or slide with the same
  sign and zero);
- spatial object (free joint): ``qpos[n_q:n_q+3] = r_0`` [m], ``qpos[n_q+3:n_q+7]`` the unit quaternion of
  ``R(A_0) = Rz(psi) Ry(theta) Rx(phi)``; ``qvel[n_q:n_q+3] = dr_0`` [m/s] (world),
  ``qvel[n_q+3:n_q+6] = omega_0 = L(A_0) dA_0`` [rad/s], the body angular velocity (105), which is what
  MuJoCo's free joint holds. Back: ``A_0`` from the rotation matrix (theta in [-pi/2, pi/2]; psi and phi
  taken on the branch nearest a reference, so that a turn past pi stays continuous) and
  ``dA_0 = L(A_0)^-1 omega_0``;
- planar object (slide x, slide z, hinge about -y): ``qpos[n_q:n_q+3] = (x_0, z_0, theta_0)`` and
  ``qvel`` their rates, as they are.
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.mujoco.mjcf import quaternion
from plants.frames import body_rate_map, rotation_zyx


def rotation_of_quaternion(quat) -> np.ndarray:
    """The rotation matrix (3x3) of the unit quaternion ``(w, x, y, z)``."""
    w, x, y, z = (float(v) for v in quat)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def euler_rates(A, omega) -> np.ndarray:
    """``dA = L(A)^-1 omega`` [rad/s] of the body angular velocity ``omega`` [rad/s] at the ZYX angles ``A`` (105),
    in closed form (``cos theta != 0``: the loop's guards keep the object out of the Euler-angle band)."""
    cth, sth = math.cos(A[1]), math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    w0, w1, w2 = float(omega[0]), float(omega[1]), float(omega[2])
    a = (sph * w1 + cph * w2) / cth
    return np.array([a, cph * w1 - sph * w2, w0 + sth * a])


def euler_zyx(R) -> np.ndarray:
    """ZYX Euler angles ``(psi, theta, phi)`` [rad] of the rotation matrix ``R``, theta in [-pi/2, pi/2] (as
    :func:`plants.frames.euler_zyx_from_rotation`)."""
    return np.array([math.atan2(R[1, 0], R[0, 0]), math.atan2(-R[2, 0], math.hypot(R[2, 1], R[2, 2])),
                     math.atan2(R[2, 1], R[2, 2])])


def _nearest_branch(a: float, reference: float) -> float:
    """``a + 2 pi k`` nearest ``reference`` [rad]."""
    return a + 2.0 * math.pi * round((reference - a) / (2.0 * math.pi))


class StateMap:
    """The map of one scene's plant state to and from MuJoCo's ``qpos``, ``qvel``.

    Args:
        n_q: Number of arm joints (all arms) [-].
        spatial: Spatial scene (free-joint object) or planar.
    """

    def __init__(self, n_q: int, spatial: bool):
        self.n_q = int(n_q)
        self.spatial = bool(spatial)
        self.p = 6 if spatial else 3
        self.nz = self.n_q + self.p
        self.nq_mujoco = self.n_q + (7 if spatial else 3)  # MuJoCo's qpos size
        self.nv_mujoco = self.n_q + (6 if spatial else 3)  # MuJoCo's qvel size

    @classmethod
    def from_plant(cls, plant) -> "StateMap":
        """The map of a :class:`~plants.cooperative.CooperativePlant`'s state."""
        return cls(int(sum(plant.arm_dofs)), plant.space == "spatial")

    def qpos_qvel(self, x) -> tuple[np.ndarray, np.ndarray]:
        """``(qpos, qvel)`` of the plant state ``x`` (``2 nz``)."""
        x = np.asarray(x, dtype=float)
        n, nz = self.n_q, self.nz
        qpos = np.empty(self.nq_mujoco)
        qvel = np.empty(self.nv_mujoco)
        qpos[:n] = x[:n]
        qvel[:n] = x[nz:nz + n]
        Y0, dY0 = x[n:nz], x[nz + n:]
        if self.spatial:
            qpos[n:n + 3] = Y0[:3]
            qpos[n + 3:n + 7] = quaternion(rotation_zyx(Y0[3:6]))
            qvel[n:n + 3] = dY0[:3]
            qvel[n + 3:n + 6] = body_rate_map(Y0[3:6]) @ dY0[3:6]
        else:
            qpos[n:] = Y0
            qvel[n:] = dY0
        return qpos, qvel

    def state(self, qpos, qvel, reference=None) -> np.ndarray:
        """The plant state ``x`` of MuJoCo's ``(qpos, qvel)``; ``reference``: a plant state whose object angles
        pick the branch of ``psi`` and ``phi`` (the previous state; ``None``: the principal branch)."""
        n, nz = self.n_q, self.nz
        x = np.empty(2 * nz)
        x[:n] = qpos[:n]
        x[nz:nz + n] = qvel[:n]
        if self.spatial:
            A = euler_zyx(rotation_of_quaternion(qpos[n + 3:n + 7]))
            if reference is not None:
                A[0] = _nearest_branch(A[0], float(reference[n + 3]))
                A[2] = _nearest_branch(A[2], float(reference[n + 5]))
            x[n:n + 3] = qpos[n:n + 3]
            x[n + 3:nz] = A
            x[nz + n:nz + n + 3] = qvel[n:n + 3]
            x[nz + n + 3:] = euler_rates(A, qvel[n + 3:n + 6])
        else:
            x[n:nz] = qpos[n:n + 3]
            x[nz + n:] = qvel[n:n + 3]
        return x
