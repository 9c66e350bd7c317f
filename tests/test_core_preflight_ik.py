"""coopctrl/core/preflight_ik (coopctrl._core): pre-flight's inverse kinematics, the same numbers as the numba kernels
of coopctrl.analysis.preflight_ik, bit for bit, on the arms of the shipped scenes (DH and chain arms, 6 and 7 joints,
planar arms) toward seeded targets: reachable ones from a nearby seed (converged), far ones (not converged), the
posture refinement of a redundant arm (the pseudo-inverse from the same LAPACK and BLAS calls as numba's
np.linalg.pinv); and the square joint rates, regular and singular."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

from coopctrl import _core, load_scenario
from coopctrl.analysis import preflight_ik as numba_ik
from coopctrl.scenario import build
from plants.arms.chain_arm import ChainArm
from plants.arms.planar_arm import PlanarArm
from plants.arms.serial_arm import SerialArm
from plants.arms.spatial_ik import IK_TOLERANCE, POSTURE_ITERATIONS, POSTURE_STEP

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


@pytest.mark.parametrize("arm", [a for a in ARMS if not isinstance(a.values[0], PlanarArm)])
def test_spatial_ik_and_posture_match_the_numba_kernels_bit_for_bit(arm):
    kind = numba_ik.KIND_DH if isinstance(arm, SerialArm) else numba_ik.KIND_CHAIN
    table = _f64(arm.dh_array() if kind == numba_ik.KIND_DH else arm.kernel_table())
    base, tool, posture = _f64(arm.base), _f64(arm.tool), _f64(arm.rest_posture())
    lower, upper = _f64(arm.q_limits[:, 0]), _f64(arm.q_limits[:, 1])
    rng = np.random.default_rng(arm.dof)
    outcomes = set()
    for target, seed in _cases(arm, rng):
        q_numba, q_core = _f64(seed), _f64(seed)
        ok_numba = numba_ik.spatial_ik(kind, table, base, tool, lower, upper, target, q_numba)
        ok_core = _core.spatial_ik(kind, table, base, tool, lower, upper, target, q_core, IK_TOLERANCE)
        assert ok_core == ok_numba
        np.testing.assert_array_equal(q_core, q_numba)
        outcomes.add(bool(ok_core))
        if ok_core and arm.dof > 6:
            numba_ik.refine_posture(kind, table, base, tool, lower, upper, posture, target, q_numba)
            _core.refine_posture(kind, table, base, tool, lower, upper, posture, target, q_core, IK_TOLERANCE,
                                 POSTURE_ITERATIONS, POSTURE_STEP)
            np.testing.assert_array_equal(q_core, q_numba)
            outcomes.add("refined")
    assert {True, False} <= outcomes  # both a converged and a failed solve were compared
    if arm.dof > 6:
        assert "refined" in outcomes


@pytest.mark.parametrize("arm", [a for a in ARMS if isinstance(a.values[0], PlanarArm)])
def test_planar_ik_matches_the_numba_kernel_bit_for_bit(arm):
    links, base, tool, gravity = _f64(arm.link_array()), _f64(arm.base), _f64(arm.tool), _f64(arm.gravity)
    lower, upper = _f64(arm.q_limits[:, 0]), _f64(arm.q_limits[:, 1])
    rng = np.random.default_rng(3 + arm.dof)
    outcomes = set()
    for target, seed in _cases(arm, rng):
        target[2] += 2.0 * np.pi * (rng.integers(-1, 2))  # an angle off by a turn: wrapped
        q_numba, q_core = _f64(seed), _f64(seed)
        ok_numba = numba_ik.planar_ik(links, base, tool, gravity, lower, upper, target, q_numba)
        ok_core = _core.planar_ik(links, base, tool, gravity, lower, upper, target, q_core, IK_TOLERANCE)
        assert ok_core == ok_numba
        np.testing.assert_array_equal(q_core, q_numba)
        outcomes.add(bool(ok_core))
    assert outcomes == {True, False}


@pytest.mark.parametrize("p", [6, 3])
def test_square_joint_rates_match_the_numba_kernel_bit_for_bit(p):
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
        want, got = np.zeros((m, nmax)), np.zeros((m, nmax))
        ok_want = numba_ik.square_joint_rates_into(J, dY, dofs, want)
        ok_got = _core.square_joint_rates_into(J, dY, dofs, got)
        assert ok_got == ok_want
        assert ok_got == (trial not in (1, 2))
        if ok_got:
            np.testing.assert_array_equal(got, want)


def test_the_bindings_check_their_arguments():
    q = np.zeros(6)
    with pytest.raises(ValueError, match="kind"):
        _core.spatial_ik(2, np.zeros((6, 16)), np.eye(4), np.eye(4), q, q, q, q, IK_TOLERANCE)
    with pytest.raises(ValueError, match="q"):
        _core.spatial_ik(0, np.zeros((6, 16)), np.eye(4), np.eye(4), q, q, q, np.zeros(5), IK_TOLERANCE)
    with pytest.raises(ValueError, match="links"):
        _core.planar_ik(np.zeros((3, 6)), np.zeros(3), np.zeros(3), np.zeros(2), q[:3], q[:3], q[:3], q[:3],
                        IK_TOLERANCE)
