"""Inverse kinematics of a spatial arm (square or redundant) within its joint limits."""

from __future__ import annotations

import itertools

import numpy as np

from plants.arms._dls_ik import damped_least_squares
from plants.arms._validation import check_vector
from plants.errors import UnreachablePoseError
from plants.frames import rotation_vector, rotation_zyx

#: IK convergence: position [m] and rotation [rad] residuals.
IK_TOLERANCE = 1e-9
#: Posture refinement of a redundant arm: iterations and step fraction [-].
POSTURE_ITERATIONS = 100
POSTURE_STEP = 1.0


def finite_limits(q_limits) -> tuple:
    """``(lower, upper)`` [rad or m] with unbounded (continuous) joints given ``[-pi, pi]``
    for seeding only; clipping still uses the true limits."""
    lower = np.where(np.isfinite(q_limits[:, 0]), q_limits[:, 0], -np.pi)
    upper = np.where(np.isfinite(q_limits[:, 1]), q_limits[:, 1], np.pi)
    return lower, upper


class SpatialInverseKinematics:
    """Mixin: :meth:`inverse_kinematics` for a class with ``tip_transform``, ``q_limits``,
    ``dof``, ``name`` and ``_joint_vector``."""

    def rest_posture(self) -> np.ndarray:
        """Rest posture [rad or m]: the middle of the joint limits (0 for a continuous joint)."""
        lower, upper = finite_limits(self.q_limits)
        return 0.5 * (lower + upper)

    def inverse_kinematics(self, Y_target, q0=None, seeds: int = 20, seed: int = 0, posture=None) -> np.ndarray:
        """Joint positions within ``q_limits`` reaching the node pose ``Y_target``.

        Damped least squares on the pose error (position [m], and the rotation vector of
        ``R_target R(q)^T`` [rad], not the Euler-angle difference), clipped to the joint limits,
        from ``q0`` (default: :meth:`rest_posture`) and then ``seeds`` random seeds drawn with
        ``seed``. For a redundant arm (``n > 6``) the solution is then moved inside the
        self-motion manifold toward ``posture`` (default: :meth:`rest_posture`, the posture the
        controllers' null-space task holds, so that a start found here leaves it at rest):

        .. math:: q \\leftarrow q + s\\, (I - J_g^+ J_g)(q_{post} - q)

        with ``s`` starting at :data:`POSTURE_STEP` (halved after a rejected step), each step
        followed by a damped least-squares correction back onto the target and kept only if it
        converged within the limits and reduced the null-space residual
        ``|(I - J_g^+ J_g)(q_post - q)|``. The result is the configuration of the self-motion
        manifold nearest to ``q_post`` (within the joint limits; locally).

        Raises:
            UnreachablePoseError: No seed reached a residual of 1e-9 m and 1e-9 rad.
        """
        Y_target = check_vector("Y_target", Y_target, 6)
        p_target = Y_target[:3]
        R_target = rotation_zyx(Y_target[3:])
        lower, upper = self.q_limits[:, 0], self.q_limits[:, 1]
        seed_lower, seed_upper = finite_limits(self.q_limits)

        def error_and_jacobian(q):
            T, Jg = self.tip_transform(q)
            e = np.empty(6)
            e[:3] = p_target - T[:3, 3]
            e[3:] = rotation_vector(R_target @ T[:3, :3].T)
            return e, Jg

        def converged(e):
            return np.linalg.norm(e[:3]) <= IK_TOLERANCE and np.linalg.norm(e[3:]) <= IK_TOLERANCE

        rng = np.random.default_rng(seed)
        start0 = self.rest_posture() if q0 is None else self._joint_vector("q0", q0)
        target_posture = self.rest_posture() if posture is None else self._joint_vector("posture", posture)
        # the random seeds drawn only when the ones before did not converge (the same draws, in the same order)
        starts = itertools.chain([start0], (rng.uniform(seed_lower, seed_upper) for _ in range(seeds)))
        best_q, best_res = None, np.inf
        for start in starts:
            q, e = damped_least_squares(error_and_jacobian, start, lower, upper, converged)
            if converged(e):
                if self.dof > 6:
                    q = self._posture_refine(q, target_posture, error_and_jacobian, converged, lower, upper)
                return q
            res = float(np.linalg.norm(e))
            if res < best_res:
                best_q, best_res = q, res
        raise UnreachablePoseError(
            self.name,
            Y_target,
            best_res,
            "move the target or the arm base so that the pose is inside the workspace and joint limits",
        )

    def _posture_refine(self, q, posture, error_and_jacobian, converged, lower, upper) -> np.ndarray:
        """Move ``q`` along the self-motion manifold until the null-space part of
        ``posture - q``, ``r = |(I - J^+ J)(posture - q)|``, is below 1e-10 or stops falling."""

        def residual(q):
            _, Jg = error_and_jacobian(q)
            P = np.eye(self.dof) - np.linalg.pinv(Jg) @ Jg
            return P @ (posture - q)

        d = residual(q)
        r = float(np.linalg.norm(d))
        step = POSTURE_STEP
        for _ in range(POSTURE_ITERATIONS):
            if r <= 1e-10:
                break
            trial = np.clip(q + step * d, lower, upper)
            trial, e = damped_least_squares(error_and_jacobian, trial, lower, upper, converged)
            if converged(e):
                d_new = residual(trial)
                r_new = float(np.linalg.norm(d_new))
                if r_new < r:
                    q, d, r = trial, d_new, r_new
                    step = min(1.0, 2.0 * step)
                    continue
            step *= 0.5
            if step < 1e-3:
                break
        return q
