"""The ZYX Euler-angle band: where the closed loop stops before the singularity (docs/model.md s.2).

A node pose carries ZYX angles ``A = (psi, theta, phi)``; the body-rate map ``L(A)`` is singular
at ``cos(theta) = 0`` (pitch +-90 deg). Near it the Euler coordinates are a bad chart: ``L^-1``
grows like ``1 / cos(theta)``, the rotational inertia seen in Euler coordinates ``L^T I L``
loses rank like ``cos^2(theta)``, so the fastest rotational mode stiffens like ``1 / cos(theta)``
(11.5 times at 85 deg) and a fixed-step integrator eventually diverges there. The plant only
refuses at ``|cos(theta)| < 1e-6`` (:data:`plants.frames.EULER_SINGULARITY_COS`); the loop
draws the line much earlier, at :data:`EULER_PITCH_MARGIN_DEG` from +-90 deg:

- **Before a run** (:func:`check_nominal_path`): the object's nominal trajectory and every
  contact node carried rigidly by it (148) are sampled; a path that enters the band is bad input
  (:class:`~coopctrl.errors.ScenarioError`, exit 2), named by the via point ending the segment.
- **During a run** (:func:`closest_to_singularity`): the closed loop stops when any node of the
  actual state enters the band (:class:`NearSingularity`), and a divergence whose last state was
  in the band is reported as the singularity, not as a step problem.

The fix is never a smaller step: keep the pitch away from +-90 deg, or re-orient the object frame
(``object.pose`` and the grasps) so that the large rotation is a yaw (``psi``) or a roll (``phi``).

This module belongs to the loop (its tick checks the band); :mod:`coopctrl.analysis.euler_singularity`
keeps the same public names for the analysis layer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from coopctrl.errors import ScenarioError

#: Distance [deg] from pitch +-90 deg that a nominal path must keep, and at which a run stops.
#: At 85 deg the rotational modes are ~11.5 times faster than at 0 deg (``1 / cos``).
EULER_PITCH_MARGIN_DEG = 5.0

#: Samples per path segment at least, and at most this pitch travel between samples [deg]; far
#: below the band's width, so that a path cannot step over it.
_MIN_SAMPLES = 200
_MAX_SAMPLE_TRAVEL_DEG = 0.25


@dataclass(frozen=True)
class SingularityHit:
    """Where a pose came closest to the Euler singularity.

    Attributes:
        node: 0 for the object, ``i`` for contact node ``i`` (arm ``i - 1``).
        theta: Its pitch [rad] (in [-pi/2, pi/2] for a node frame extracted from a rotation).
        cos_theta: ``|cos(theta)|`` [-].
        time: Time [s] (nominal path or run), or ``nan``.
    """

    node: int
    theta: float
    cos_theta: float
    time: float = math.nan

    @property
    def pitch_deg(self) -> float:
        """``theta`` in [deg]."""
        return math.degrees(self.theta)

    @property
    def what(self) -> str:
        """``"the object"`` or ``"contact node i (arms[i-1])"``."""
        return "the object" if self.node == 0 else f"contact node {self.node} (arms[{self.node - 1}])"

    def describe(self, with_time: bool = True) -> str:
        """One sentence: where, when (unless ``with_time`` is false), the angle and ``cos(theta)``."""
        when = f" at t = {self.time:.4g} s" if with_time and math.isfinite(self.time) else ""
        away = math.degrees(math.asin(min(self.cos_theta, 1.0)))
        return (f"{self.what} reaches pitch theta = {self.pitch_deg:.2f} deg{when} (cos(theta) = {self.cos_theta:.3g}), "
                f"{away:.2f} deg from the ZYX Euler-angle singularity at +-90 deg where the body-rate map L(A) is "
                "not invertible (docs/model.md s.2)")


def margin_cos(margin_deg: float = EULER_PITCH_MARGIN_DEG) -> float:
    """``|cos(theta)|`` [-] at ``margin_deg`` from +-90 deg: ``sin(margin)``."""
    return math.sin(math.radians(margin_deg))


def fix_hint(margin_deg: float = EULER_PITCH_MARGIN_DEG) -> str:
    """How to avoid the singularity: ``"keep |pitch| below ... or re-orient ..."``."""
    return (f"keep |pitch| below {90.0 - margin_deg:g} deg on the object and every contact node, or re-orient the "
            "object frame (object.pose and the grasps) so that the large rotation is a yaw (psi) or a roll (phi)")


def node_pitches(Y: np.ndarray) -> np.ndarray:
    """Pitch angles [rad] of the node poses ``Y`` (rows ``(x, y, z, psi, theta, phi)``)."""
    return np.asarray(Y, dtype=float)[..., 4]


def closest_to_singularity(Y, time: float = math.nan) -> SingularityHit:
    """The node of spatial node poses ``Y`` ((m+1, 6)) with the smallest ``|cos(theta)|``."""
    theta = node_pitches(Y)
    c = np.abs(np.cos(theta))
    k = int(np.argmin(c))
    return SingularityHit(k, float(theta[k]), float(c[k]), time)


def nominal_path_pitches(trajectory, grasps, times) -> tuple[np.ndarray, np.ndarray]:
    """``(theta, cos)`` of the object and each contact node on the nominal path, shape (N, m+1).

    A node's frame is ``R_j = R(A_0) R(A_0j)`` (148); its pitch is ``asin(-R_j[2, 0])`` with
    ``R_j[2, 0] = R(A_0)[2, :] . R(A_0j)[:, 0]``, so ``|cos(theta_j)| = sqrt(1 - R_j[2, 0]^2)``.
    """
    from plants.frames import rotation_zyx

    Y0 = trajectory.sample(np.asarray(times, dtype=float))[0]
    psi, th, ph = Y0[:, 3], Y0[:, 4], Y0[:, 5]
    del psi  # the yaw does not enter row 2 of R(A_0)
    row2 = np.stack((-np.sin(th), np.cos(th) * np.sin(ph), np.cos(th) * np.cos(ph)), axis=1)
    grasps = np.atleast_2d(np.asarray(grasps, dtype=float))
    theta = np.empty((Y0.shape[0], grasps.shape[0] + 1))
    cos = np.empty_like(theta)
    theta[:, 0] = th
    cos[:, 0] = np.abs(np.cos(th))
    for j, g in enumerate(grasps):
        col0 = rotation_zyx(np.ascontiguousarray(g[3:6]))[:, 0]
        s = np.clip(-(row2 @ col0), -1.0, 1.0)
        theta[:, j + 1] = np.arcsin(s)
        cos[:, j + 1] = np.sqrt(np.maximum(1.0 - s * s, 0.0))
    return theta, cos


def first_path_hit(trajectory, grasps, margin_deg: float = EULER_PITCH_MARGIN_DEG) -> tuple[SingularityHit, int] | None:
    """The first sample of the nominal path that enters the band, and its segment index, or ``None``.

    Each segment ``[t_i, t_(i+1)]`` is sampled with at least 200 points and at most 0.25 deg of
    pitch travel between samples (the object's pitch is monotone on a minimum-jerk segment; a
    node's pitch changes no faster than the object's rotation angle, bounded by the sum of the
    Euler-angle changes); the returned hit is the closest sample of the first segment that enters.
    """
    times = np.asarray(trajectory.times, dtype=float)
    poses = np.asarray(trajectory.poses, dtype=float)
    limit = margin_cos(margin_deg)
    if times.size == 1:
        t_all = [times[:1]]
    else:
        t_all = []
        for i in range(times.size - 1):
            travel = math.degrees(float(np.sum(np.abs(poses[i + 1, 3:6] - poses[i, 3:6]))))
            n = max(_MIN_SAMPLES, int(math.ceil(travel / _MAX_SAMPLE_TRAVEL_DEG)) + 1)
            t_all.append(np.linspace(times[i], times[i + 1], n))
    for seg, t in enumerate(t_all):
        theta, cos = nominal_path_pitches(trajectory, grasps, t)
        inside = cos < limit
        if np.any(inside):
            k, j = np.unravel_index(int(np.argmin(np.where(inside, cos, np.inf))), cos.shape)
            return SingularityHit(int(j), float(theta[k, j]), float(cos[k, j]), float(t[k])), seg
    return None


def check_nominal_path(trajectory, grasps, margin_deg: float = EULER_PITCH_MARGIN_DEG) -> None:
    """Raise :class:`ScenarioError` if the nominal path enters the band around pitch +-90 deg.

    The error names ``trajectory.via[k].pose``, the via point that ends the offending segment
    (``trajectory.via[0].pose`` for a path of one pose), the pose, and what is allowed. A shipped trajectory's
    path passed with these grasps and margin is not checked again (:func:`coopctrl.derived.derived`).
    """
    from coopctrl.derived import derived

    grasps = np.array(grasps, dtype=float)
    found = derived(trajectory, ("book_path_hit", grasps.shape, grasps.tobytes(), float(margin_deg)),
                    lambda: first_path_hit(trajectory, grasps, margin_deg))
    if found is None:
        return
    hit, seg = found
    k = seg + 1 if len(trajectory.times) > 1 else 0
    raise ScenarioError(
        f"trajectory.via[{k}].pose", [float(v) for v in np.asarray(trajectory.poses)[k]],
        f"a path that keeps every node's ZYX pitch at least {margin_deg:g} deg away from +-90 deg: on the nominal "
        f"path {hit.describe()}; a smaller step does not help: {fix_hint(margin_deg)}")


#: Pitch [deg] beyond which the Euler-angle chart is blamed for a stiff mode living on that node's
#: angles: at 45 deg the chart's stiffening ``1 / cos^2(theta)`` of a damped rotational mode is 2.
CHART_PITCH_DEG = 45.0


def chart_mode_share(plant, x, mode: np.ndarray, pitch_deg: float = CHART_PITCH_DEG) -> tuple[float, SingularityHit]:
    """How much of a mode lives on the Euler angles of nodes pitched beyond ``pitch_deg``.

    The mode's position part ``dz`` (joint angles and the object pose) is mapped to node
    displacements ``dY_0 = dz_0``, ``dY_i = J_i dz_i`` (a contact point's ``dz_i`` is its pose);
    the share is ``sum |dA_i|^2`` over the Euler angles of the pitched nodes divided by
    ``sum |dY_i|^2`` over every node coordinate (metres and radians, compared as numbers: a rotation
    of the Euler chart moves no node by more than millimetres, a translational mode moves the angles
    by a fraction of its metres). Returns ``(share [-], the most pitched node)``.
    """
    p, nz = plant.p, plant.nz
    dz = np.asarray(mode)[:nz]
    Y, _, _, _, J, _ = plant.arm_terms(x)
    Y = np.asarray(Y).reshape(-1, p)
    dY = np.zeros((plant.node_count, p), dtype=complex)
    dY[0] = dz[nz - p:]
    for i, arm in enumerate(plant.arms):
        sl = plant.q_slice(i)
        n = sl.stop - sl.start
        Ji = np.asarray(J[i])[:, :n]
        dY[i + 1] = dz[sl] if not np.any(Ji) else Ji @ dz[sl]
    hit = closest_to_singularity(Y)
    pitched = np.abs(np.cos(Y[:, 4])) < math.cos(math.radians(pitch_deg))
    total = float(np.sum(np.abs(dY) ** 2))
    if total == 0.0:
        return 0.0, hit
    return float(np.sum(np.abs(dY[pitched, 3:6]) ** 2)) / total, hit


class NearSingularity(Exception):
    """A node of the running state entered the band around pitch +-90 deg (the tick stops the run).

    Attributes:
        hit: The :class:`SingularityHit` of the node closest to the singularity.
    """

    def __init__(self, hit: SingularityHit):
        super().__init__(hit.describe())
        self.hit = hit


def hit_from_plant_error(exc, t: float) -> SingularityHit:
    """A :class:`SingularityHit` at time ``t`` [s] from the plant's
    :class:`~plants.errors.EulerSingularityError` ``exc`` (node 0 and pitch 90 deg when it names no place)."""
    theta = float(getattr(exc, "theta", math.nan))
    node = 0
    where = str(getattr(exc, "where", ""))
    if where.startswith("contact node "):
        digits = where[len("contact node "):].split()[0]
        node = int(digits) if digits.isdigit() else 0
    c = abs(math.cos(theta)) if math.isfinite(theta) else 0.0
    return SingularityHit(node, theta if math.isfinite(theta) else 0.5 * math.pi, c, t)
