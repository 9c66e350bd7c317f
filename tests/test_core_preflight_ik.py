"""coopctrl/core/preflight_ik (coopctrl._core): pre-flight's inverse kinematics on the arms of the shipped scenes (DH
and chain arms, 6 and 7 joints, planar arms) toward seeded targets, checked against the arms' own forward kinematics:
a reachable target from a nearby seed is reached within the tolerance, inside the joint limits; a far one is not
(``False``); the posture refinement of a redundant arm keeps the node on its target and does not move the joints
away from the rest posture along the self-motion manifold; the square joint rates solve ``J_i dq_i = dY_i``
(numpy's solve), and a singular or non-square arm is refused. (The kernels were checked bit for bit against the
numba kernels they replaced when they were ported; pre-flight's results are checked in tests/test_preflight.py.)"""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

from coopctrl import _core, load_scenario
from coopctrl.analysis.preflight_ik import KIND_CHAIN, KIND_DH
from coopctrl.scenario import build
from plants.arms.chain_arm import ChainArm
from plants.arms.planar_arm import PlanarArm
from plants.arms.serial_arm import SerialArm
from plants.arms.spatial_ik import IK_TOLERANCE, POSTURE_ITERATIONS, POSTURE_STEP
from plants.frames import rotation_zyx

SCENES = sorted(p.stem for p in (pathlib.Path(__file__).parents[1] / "scenarios").glob("*.toml"))
DRAWS = 6


def _shipped_arms():
    """One arm of each kind and size of the shipped scenes, by (class, dof, scene)."""
    seen, arms = set(), []
    for name in SCENES:
        plant = build.build_plant(load_scenario(name))
        for arm in plant.arms:
            if not isinstance(arm, (SerialArm, ChainArm, PlanarArm)):
                continue
            key = (type(arm).__name__, arm.dof, getattr(arm, "name", ""))
            if key not in seen:
                seen.add(key)
                arms.append(pytest.param(arm, id=f"{name}-{type(arm).__name__}-{arm.dof}"))
    return arms


ARMS = _shipped_arms()


def _f64(a):
    return np.array(a, dtype=np.float64, order="C")


def _cases(arm, rng):
    """(target, seed) pairs: the node pose at a random q inside the limits from a seed near q, and a pose 5 m away."""
    lo, hi = arm.q_limits[:, 0], arm.q_limits[:, 1]
    lo, hi = np.maximum(lo, -3.0), np.minimum(hi, 3.0)
    for k in range(DRAWS):
        q = rng.uniform(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo))
        target = _f64(arm.terms(q, np.zeros(arm.dof)).Y)
        seed = q + rng.normal(0.0, 0.05 if k % 2 else 0.3, arm.dof)
        if k == DRAWS - 1:
            target[0] += 5.0  # beyond reach
        yield target, seed


def _rotation_residual(A_target, A):
    """The angle [rad] of ``R(A_target) R(A)^T``: ``|R_t R^T - I|_F / sqrt(2)`` (exact to second order)."""
    return np.linalg.norm(rotation_zyx(A_target) @ rotation_zyx(A).T - np.eye(3)) / np.sqrt(2.0)


def _null_residual(arm, q, posture):
    """``|(I - J^+ J)(posture - q)|``: how far ``q`` is from the rest posture along the self-motion manifold (the
    node's analytic Jacobian has the geometric one's null space away from the Euler singularity)."""
    J = arm.terms(q, np.zeros(arm.dof)).J
    return np.linalg.norm((np.eye(arm.dof) - np.linalg.pinv(J) @ J) @ (posture - q))


#: Margin on the solver's own tolerance for the residuals evaluated here (a different rounding of the same pose).
MARGIN = 1e-12


@pytest.mark.parametrize("arm", [a for a in ARMS if not isinstance(a.values[0], PlanarArm)])
def test_spatial_ik_reaches_the_target_and_the_posture_stays_on_it(arm):
    kind = KIND_DH if isinstance(arm, SerialArm) else KIND_CHAIN
    table = _f64(arm.dh_array() if kind == KIND_DH else arm.kernel_table())
    base, tool, posture = _f64(arm.base), _f64(arm.tool), _f64(arm.rest_posture())
    lower, upper = _f64(arm.q_limits[:, 0]), _f64(arm.q_limits[:, 1])
    rng = np.random.default_rng(arm.dof)
    outcomes = set()
    for target, seed in _cases(arm, rng):
        q = _f64(seed)
        ok = _core.spatial_ik(kind, table, base, tool, lower, upper, target, q, IK_TOLERANCE)
        outcomes.add(bool(ok))
        if not ok:
            assert target[0] - arm.terms(q, np.zeros(arm.dof)).Y[0] > 1.0  # only the target beyond reach
            continue
        assert np.all((q >= lower) & (q <= upper))
        Y = arm.terms(q, np.zeros(arm.dof)).Y
        assert np.linalg.norm(Y[:3] - target[:3]) <= IK_TOLERANCE + MARGIN
        assert _rotation_residual(target[3:], Y[3:]) <= IK_TOLERANCE + MARGIN
        if arm.dof > 6:
            before = _null_residual(arm, q, posture)
            _core.refine_posture(kind, table, base, tool, lower, upper, posture, target, q, IK_TOLERANCE,
                                 POSTURE_ITERATIONS, POSTURE_STEP)
            Y = arm.terms(q, np.zeros(arm.dof)).Y
            assert np.linalg.norm(Y[:3] - target[:3]) <= IK_TOLERANCE + MARGIN
            assert _rotation_residual(target[3:], Y[3:]) <= IK_TOLERANCE + MARGIN
            assert np.all((q >= lower) & (q <= upper))
            assert _null_residual(arm, q, posture) <= before
            outcomes.add("refined")
    assert {True, False} <= outcomes  # both a converged and a failed solve were met
    if arm.dof > 6:
        assert "refined" in outcomes


@pytest.mark.parametrize("arm", [a for a in ARMS if isinstance(a.values[0], PlanarArm)])
def test_planar_ik_reaches_the_target_with_its_angle_wrapped(arm):
    links, base, tool, gravity = _f64(arm.link_array()), _f64(arm.base), _f64(arm.tool), _f64(arm.gravity)
    lower, upper = _f64(arm.q_limits[:, 0]), _f64(arm.q_limits[:, 1])
    rng = np.random.default_rng(3 + arm.dof)
    outcomes = set()
    for target, seed in _cases(arm, rng):
        target[2] += 2.0 * np.pi * (rng.integers(-1, 2))  # an angle off by a turn: wrapped
        q = _f64(seed)
        ok = _core.planar_ik(links, base, tool, gravity, lower, upper, target, q, IK_TOLERANCE)
        outcomes.add(bool(ok))
        if not ok:
            continue
        assert np.all((q >= lower) & (q <= upper))
        Y = arm.terms(q, np.zeros(arm.dof)).Y
        assert np.linalg.norm(Y[:2] - target[:2]) <= IK_TOLERANCE + MARGIN
        assert abs(np.angle(np.exp(1j * (target[2] - Y[2])))) <= IK_TOLERANCE + MARGIN
    assert outcomes == {True, False}


@pytest.mark.parametrize("p", [6, 3])
def test_square_joint_rates_solve_each_arm(p):
    rng = np.random.default_rng(p)
    m, nmax = 3, p + 1
    for trial in range(20):
        J = rng.normal(size=(m, p, nmax))
        dY = rng.normal(size=(m + 1, p))
        dofs = np.full(m, p, dtype=np.int64)
        if trial == 1:
            J[1, :, 0] = 0.0  # a zero pivot column: singular
        if trial == 2:
            dofs[2] = p + 1  # a redundant arm: not square
        got = np.zeros((m, nmax))
        ok = _core.square_joint_rates_into(J, dY, dofs, got)
        assert ok == (trial not in (1, 2))
        if ok:
            for i in range(m):
                want = np.linalg.solve(J[i, :, :p], dY[i + 1])
                scale = np.linalg.cond(J[i, :, :p]) * max(1.0, np.max(np.abs(want)))
                assert np.max(np.abs(got[i, :p] - want)) <= 1e-13 * scale


def test_the_bindings_check_their_arguments():
    q = np.zeros(6)
    with pytest.raises(ValueError, match="kind"):
        _core.spatial_ik(2, np.zeros((6, 16)), np.eye(4), np.eye(4), q, q, q, q, IK_TOLERANCE)
    with pytest.raises(ValueError, match="q"):
        _core.spatial_ik(0, np.zeros((6, 16)), np.eye(4), np.eye(4), q, q, q, np.zeros(5), IK_TOLERANCE)
    with pytest.raises(ValueError, match="links"):
        _core.planar_ik(np.zeros((3, 6)), np.zeros(3), np.zeros(3), np.zeros(2), q[:3], q[:3], q[:3], q[:3],
                        IK_TOLERANCE)
