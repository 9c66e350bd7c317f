"""The stiffness of each grasp, seen from the object: wrench on the object per node displacement."""

from __future__ import annotations

import numpy as np

from coopctrl._core import pose_increment
from plants.frames import body_rate_map_inv, euler_zyx_from_rotation, rotation_zyx


def _rotvec_matrix(v) -> np.ndarray:
    """Rodrigues: ``exp(S(v))`` for a rotation vector ``v`` [rad]."""
    th = float(np.linalg.norm(v))
    S = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    if th < 1e-12:
        return np.eye(3) + S
    return np.eye(3) + np.sin(th) / th * S + (1 - np.cos(th)) / th**2 * S @ S


class GraspCompliance:
    """Per contact i, the 6x6 (3x3 planar) stiffness ``K_i`` in the object frame:

    .. math:: F_i^{obj} = K_i \\, \\delta_i^{obj}

    where ``delta_i`` is node i's displacement ``(dr, dtheta)`` relative to its rigid nominal
    pose (translation and small rotation vector, object frame) and ``F_i`` the wrench the
    interconnections apply to the object (:meth:`CooperativePlant.contact_wrenches`). It is
    computed once, by central differences of the plant's own contact wrenches about the
    unloaded reference state, so it holds for any element (for the book's central spring it is
    rank-deficient: no lateral stiffness without pre-tension, and :meth:`deformation` uses the
    pseudo-inverse).

    :meth:`deformation` maps a desired wrench to the node pose that produces it (the nominal
    deformation of docs/model.md s.6, feedforward for the leader and the followers). ``K`` and ``C`` are computed
    once per plant and step (:func:`coopctrl.derived.derived`: a scene's plant is built once), each compliance
    holding its own copies.
    """

    def __init__(self, plant, step: float = 1e-6):
        from coopctrl.derived import derived

        self.plant = plant
        self.space = plant.space
        K, C = derived(plant, ("grasp_compliance", type(self), float(step)), lambda: self._stiffness(float(step)))
        self.K, self.C = K.copy(), C.copy()

    def _stiffness(self, step: float) -> tuple[np.ndarray, np.ndarray]:
        """``(K, C)``, read-only: the stiffness by central differences of ``step`` and its pseudo-inverse."""
        plant = self.plant
        p = plant.p
        m = plant.arm_count
        Y_ref = plant.elastic.Y_ref.copy()
        self.K = np.zeros((m, p, p))
        R0 = rotation_zyx(Y_ref[0, 3:6]) if p == 6 else None
        th0 = Y_ref[0, 2] if p == 3 else 0.0
        # every displaced pose (contact i, axis a, +step then -step), their wrenches in one call of the core
        Ys = np.repeat(Y_ref[None], 2 * m * p, axis=0)
        for i in range(m):
            for a in range(p):
                for s, sgn in enumerate((1.0, -1.0)):
                    Ys[(i * p + a) * 2 + s, i + 1] = self._displace(Y_ref[0], Y_ref[i + 1], a, sgn * step)
        Fws = self.plant.interconnection_wrenches(Ys)[1]
        for i in range(m):
            for a in range(p):
                b = (i * p + a) * 2
                cols = [self._to_object(Fws[b + s, i], R0, th0) for s in (0, 1)]
                with np.errstate(over="ignore", invalid="ignore"):  # checked below
                    self.K[i, :, a] = (cols[0] - cols[1]) / (2 * step)
        self._check_finite()
        K, C = self.K, np.array([np.linalg.pinv(Ki, rcond=1e-9) for Ki in self.K])
        K.flags.writeable = C.flags.writeable = False
        return K, C

    #: Largest grasp stiffness entry [N/m, N m/rad, N/rad] the pseudo-inverse is trusted with: beyond it the
    #: singular value decomposition's scaling overflows (LAPACK may then iterate without end).
    LARGEST_STIFFNESS = 1e150

    def _check_finite(self) -> None:
        """Refuse grasp stiffnesses that are not finite or too large to invert (an SVD of an ``inf`` or
        near-overflow matrix can loop for ever inside LAPACK, beyond the reach of Ctrl-C)."""
        from coopctrl.errors import ScenarioError

        for i, Ki in enumerate(self.K):
            largest = float(np.max(np.abs(Ki))) if np.all(np.isfinite(Ki)) else float("inf")
            if not largest <= self.LARGEST_STIFFNESS:
                raise ScenarioError(
                    "springs", f"grasp stiffness of contact {i + 1} up to {largest:.3g}",
                    f"finite grasp stiffnesses <= {self.LARGEST_STIFFNESS:.0e} (from the springs' stiffness and "
                    "the grasp geometry); lower the stiffness of the springs to a physical value")

    def _displace(self, Y0, Yi, axis, amount):
        """Node pose after a displacement along object-frame axis ``axis`` (translation or rotation)."""
        p = self.space == "spatial" and 6 or 3
        out = Yi.copy()
        if p == 3:
            c, s = np.cos(Y0[2]), np.sin(Y0[2])
            if axis < 2:
                e = np.zeros(2)
                e[axis] = amount
                out[:2] += np.array([c * e[0] - s * e[1], s * e[0] + c * e[1]])
            else:
                out[2] += amount
            return out
        R0 = rotation_zyx(Y0[3:6])
        if axis < 3:
            out[:3] += R0[:, axis] * amount
        else:
            v = R0[:, axis - 3] * amount
            out[3:] = euler_zyx_from_rotation(_rotvec_matrix(v) @ rotation_zyx(Yi[3:6]))
        return out

    @staticmethod
    def _to_object(F, R0, th0):
        if R0 is not None:
            return np.concatenate([R0.T @ F[:3], R0.T @ F[3:]])
        c, s = np.cos(th0), np.sin(th0)
        return np.array([c * F[0] + s * F[1], -s * F[0] + c * F[1], F[2]])

    def deformation(self, i: int, F_world, Y0, Y_rigid) -> np.ndarray:
        """Node pose ``Y_i`` that makes contact i apply ``F_world`` to the object at pose ``Y0``.

        ``Y_rigid`` is the rigid nominal pose of node i (148); the result is
        ``Y_rigid + delta`` with ``delta = R_0 C_i R_0^T F`` mapped to pose coordinates
        (rotation vector to Euler increments via ``L(A_i)^-1 R_i^T``).
        """
        return Y_rigid + self.pose_increment(i, F_world, Y0, Y_rigid)

    def pose_increment(self, i: int, F_world, Y0, Yi) -> np.ndarray:
        """Pose-coordinate increment of node i that changes its wrench on the object by ``F_world`` (linear).

        The loop's own law, in the C++ core: ``coopctrl._core.pose_increment`` (coopctrl/core/control_laws.h)."""
        F = np.ascontiguousarray(F_world, dtype=float)
        Y0 = np.ascontiguousarray(Y0, dtype=float)
        Yi = np.ascontiguousarray(Yi, dtype=float)
        p = self.C.shape[1]
        for name, a in (("F_world", F), ("Y0", Y0), ("Yi", Yi)):
            if a.shape != (p,):
                raise ValueError(f"{name}: shape {a.shape}; expected ({p},) [N, N m] or [m, rad]")
        out = np.empty(p)
        ok = pose_increment(self.space == "spatial", np.ascontiguousarray(self.C[i]), F, Y0, Yi, out)
        if not ok:
            body_rate_map_inv(Yi[3:6], f"contact node {i + 1}")  # raises EulerSingularityError
        return out

    def stiffness_world(self, Y0) -> np.ndarray:
        """Block-diagonal grasp stiffness (m p x m p) in the world frame, for the elastic split ``A_K``."""
        m, p = self.K.shape[0], self.K.shape[1]
        if self.space == "planar":
            c, s = np.cos(Y0[2]), np.sin(Y0[2])
            Rb = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        else:
            R0 = rotation_zyx(Y0[3:6])
            Rb = np.zeros((6, 6))
            Rb[:3, :3] = R0
            Rb[3:, 3:] = R0
        out = np.zeros((m * p, m * p))
        for i in range(m):
            Ki = Rb @ self.K[i] @ Rb.T
            out[i * p:(i + 1) * p, i * p:(i + 1) * p] = 0.5 * (Ki + Ki.T)
        return out
