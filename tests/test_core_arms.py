"""plants/core/chain_arm and plants/core/dh_arm (the compiled core's spatial arms, plants._core): the same numbers as
the numba kernels they replace (plants/arms/_chain_kernels.py, plants/arms/_spatial_kernels.py), bit for bit (the
same expressions in the same order, without contraction into fused multiply-adds; sines, cosines, tanh and atan2
from the same C library), on the shipped arms (Puma 560 as DH and as a chain, Panda, UR5e, iiwa 14) and on seeded
random tables with every joint kind; and the arguments checked once at the binding. The classes on the core
(SerialArm, ChainArm) keep their Pinocchio oracle tests (tests/test_arms.py, tests/test_urdf_arms.py)."""

from __future__ import annotations

import numpy as np
import pytest

from plants import _core
from plants.arms import _chain_kernels as chain_numba
from plants.arms import _spatial_kernels as dh_numba
from plants.arms import ChainArm, ChainJoint, iiwa14, panda, puma560, ur5e
from plants.arms.puma560 import GRIPPER_TOOL
from plants.errors import EulerSingularityError
from plants.frames import rotation_zyx

DRAWS = 25


def _pose(rng, reach=0.5):
    T = np.eye(4)
    T[:3, :3] = rotation_zyx(rng.uniform(-np.pi, np.pi, 3))
    T[:3, 3] = rng.uniform(-reach, reach, 3)
    return T


def _random_inertia(rng):
    A = rng.normal(size=(3, 3)) * 0.2
    I = A @ A.T + 0.01 * np.eye(3)
    return np.array([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[0, 2]])


def _random_chain_table(rng, n):
    """n random joints of every kind (revolute about z, about a random axis, prismatic), with Coulomb friction on
    some: a (n, 32) table as ``ChainJoint.row()`` lays it out (plants/core/chain_arm.h ChainJointRow)."""
    table = np.zeros((n, 32))
    for k in range(n):
        kind = rng.integers(0, 3)
        origin = _pose(rng, 0.4)
        axis = rng.normal(size=3)
        table[k, 0] = kind
        table[k, 1:4] = origin[:3, 3]
        table[k, 4:13] = origin[:3, :3].reshape(-1)
        table[k, 13:16] = axis / np.linalg.norm(axis)
        table[k, 16] = rng.uniform(0.0, 5.0)
        table[k, 17:20] = rng.uniform(-0.2, 0.2, 3)
        table[k, 20:26] = _random_inertia(rng)
        table[k, 26:29] = rng.uniform(0.0, 0.5, 3) * (rng.uniform(size=3) < 0.6)
    return table


def _random_dh_table(rng, n):
    """n random DH links: a (n, 16) table as ``DHLink.row()`` lays it out (plants/core/dh_arm.h DHLink)."""
    dh = np.column_stack([rng.uniform(-0.5, 0.5, n), rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.5, 0.5, n),
                          rng.uniform(-np.pi, np.pi, n), rng.uniform(0.0, 5.0, n), rng.uniform(-0.2, 0.2, (n, 3)),
                          np.array([_random_inertia(rng) for _ in range(n)]), rng.uniform(0.0, 0.5, (n, 2))])
    return np.ascontiguousarray(dh)


def _shipped_chains():
    arms = [puma560(tool=GRIPPER_TOOL, motor_inertia=True, viscous_friction=True), panda(), ur5e(), iiwa14()]
    return [(a.name, np.ascontiguousarray(a.kernel_table()), np.ascontiguousarray(a.base), a.kernel_tool(),
             np.asarray(a.gravity), a.q_limits) for a in arms]


def _random_chains():
    rng = np.random.default_rng(7)
    return [(f"random{n}", _random_chain_table(rng, n), _pose(rng), _pose(rng, 0.2), rng.normal(size=3) * 5.0,
             np.tile([-np.pi, np.pi], (n, 1))) for n in (1, 2, 3, 6, 9)]


CHAINS = _shipped_chains() + _random_chains()


def _outputs(n):
    return [np.full((n, n), np.nan), np.full(n, np.nan), np.full(6, np.nan), np.full((6, n), np.nan),
            np.full(6, np.nan)]


def _assert_same(got, want):
    for g, w in zip(got, want):
        np.testing.assert_array_equal(g, w)


def _states(rng, limits):
    lo = np.where(np.isfinite(limits[:, 0]), limits[:, 0], -np.pi)
    hi = np.where(np.isfinite(limits[:, 1]), limits[:, 1], np.pi)
    for _ in range(DRAWS):
        yield rng.uniform(lo, hi), rng.uniform(-2.0, 2.0, lo.shape[0])


@pytest.mark.parametrize("name, table, base, tool, gravity, limits", CHAINS, ids=[c[0] for c in CHAINS])
def test_chain_arm_kernels_match_numba_bit_for_bit(name, table, base, tool, gravity, limits):
    n = table.shape[0]
    rng = np.random.default_rng(n + 31 * len(name))
    for q, dq in _states(rng, limits):
        core, ref = _outputs(n), _outputs(n)
        status = _core.chain_arm_terms(q, dq, table, base, tool, gravity, *core)
        assert status == chain_numba.chain_arm_terms(q, dq, table, base, tool, gravity, *ref)
        _assert_same(core, ref)
        chart, chart_ref = np.full((3, 3), np.nan), np.full((3, 3), np.nan)
        core, ref = _outputs(n), _outputs(n)
        assert _core.chain_arm_terms_own_chart(q, dq, table, base, tool, gravity, *core, chart) == 0
        assert chain_numba.chain_arm_terms_own_chart(q, dq, table, base, tool, gravity, *ref, chart_ref) == 0
        _assert_same(core + [chart], ref + [chart_ref])
        for own_chart in (False, True):
            Y, Y_ref = np.full(6, np.nan), np.full(6, np.nan)
            wk = np.empty((n + 1, chain_numba.CHAIN_WORK_WIDTH))
            assert _core.chain_arm_pose(q, table, base, tool, own_chart, Y) == chain_numba.chain_arm_pose_into(
                q, table, base, tool, own_chart, wk, Y_ref)
            np.testing.assert_array_equal(Y, Y_ref)
        assert _core.chain_arm_potential(q, table, base, gravity) == chain_numba.chain_arm_potential(
            q, table, base, gravity)
        T, Jg, T_ref, Jg_ref = np.empty((4, 4)), np.empty((6, n)), np.empty((4, 4)), np.empty((6, n))
        _core.chain_arm_tip(q, table, base, tool, T, Jg)
        chain_numba.chain_arm_tip(q, table, base, tool, T_ref, Jg_ref)
        _assert_same([T, Jg], [T_ref, Jg_ref])


def _dh_arms():
    rng = np.random.default_rng(11)
    puma = puma560(tool=GRIPPER_TOOL, motor_inertia=True, viscous_friction=True)
    arms = [("puma560", np.ascontiguousarray(puma.dh_array()), np.eye(4), puma.tool, np.asarray(puma.gravity))]
    arms += [(f"random{n}", _random_dh_table(rng, n), _pose(rng), _pose(rng, 0.2), rng.normal(size=3) * 5.0)
             for n in (1, 2, 4, 6, 8)]
    return arms


DH_ARMS = _dh_arms()


@pytest.mark.parametrize("name, dh, base, tool, gravity", DH_ARMS, ids=[a[0] for a in DH_ARMS])
def test_dh_arm_kernels_match_numba_bit_for_bit(name, dh, base, tool, gravity):
    n = dh.shape[0]
    rng = np.random.default_rng(100 + n)
    for q, dq in _states(rng, np.tile([-np.pi, np.pi], (n, 1))):
        core, ref = _outputs(n), _outputs(n)
        status = _core.dh_arm_terms(q, dq, dh, base, tool, gravity, *core)
        assert status == dh_numba.spatial_arm_terms(q, dq, dh, base, tool, gravity, *ref)
        _assert_same(core, ref)
        assert _core.dh_arm_potential(q, dh, base, gravity) == dh_numba.spatial_arm_potential(q, dh, base, gravity)
        T, Jg, T_ref, Jg_ref = np.empty((4, 4)), np.empty((6, n)), np.empty((4, 4)), np.empty((6, n))
        _core.dh_arm_tip(q, dh, base, tool, T, Jg)
        dh_numba.spatial_arm_tip(q, dh, base, tool, T_ref, Jg_ref)
        _assert_same([T, Jg], [T_ref, Jg_ref])


def test_the_singular_tip_returns_1_with_zero_angular_rows_as_numba():
    """A tool pitched by exactly pi/2 puts the tip's theta on the singularity of L (cos theta ~ 6e-17): both kernels
    return 1 and zero the angular rows of J and Jdq; the rest is still the numba kernel's, bit for bit."""
    rng = np.random.default_rng(3)
    tool = np.eye(4)
    tool[:3, :3] = rotation_zyx(np.array([0.0, np.pi / 2, 0.0]))
    dh = _random_dh_table(rng, 3)
    dh[:, 1] = 0.0  # every axis along world z: the tip's pitch stays the tool's
    table = np.zeros((3, 32))
    table[:, 4:13] = np.eye(3).reshape(-1)
    table[:, 16:26] = dh[:, 4:14]
    q, dq, g = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3), np.array([0.0, 0.0, -9.81])
    for core_fn, numba_fn, tab in ((_core.dh_arm_terms, dh_numba.spatial_arm_terms, dh),
                                   (_core.chain_arm_terms, chain_numba.chain_arm_terms, table)):
        core, ref = _outputs(3), _outputs(3)
        assert core_fn(q, dq, tab, np.eye(4), tool, g, *core) == 1
        assert numba_fn(q, dq, tab, np.eye(4), tool, g, *ref) == 1
        _assert_same(core, ref)
        np.testing.assert_array_equal(core[3][3:], 0.0)
        np.testing.assert_array_equal(core[4][3:], 0.0)
    Y = np.empty(6)
    assert _core.chain_arm_pose(q, table, np.eye(4), tool, False, Y) == 1
    assert _core.chain_arm_pose(q, table, np.eye(4), tool, True, Y) == 0
    arm = ChainArm(name="pitched", joints=(ChainJoint(name="j", kind="revolute", origin=np.eye(4), mass=1.0),),
                   tool=tool)
    for query in (lambda: arm.pose([0.3]), lambda: arm.terms([0.3], [0.0])):
        with pytest.raises(EulerSingularityError, match="pitched"):
            query()


def test_the_arm_classes_call_the_core():
    """SerialArm and ChainArm's terms, pose, potential and tip_transform are the core's numbers, bit for bit."""
    rng = np.random.default_rng(5)
    puma = puma560(tool=GRIPPER_TOOL, viscous_friction=True)
    arm = panda()
    for cls_arm, terms, potential, tip, table, tool in (
            (puma, _core.dh_arm_terms, _core.dh_arm_potential, _core.dh_arm_tip, puma.dh_array(), puma.tool),
            (arm, _core.chain_arm_terms, _core.chain_arm_potential, _core.chain_arm_tip, arm.kernel_table(),
             arm.kernel_tool())):
        n = cls_arm.dof
        q, dq = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        t = cls_arm.terms(q, dq)
        out = _outputs(n)
        assert terms(q, dq, table, cls_arm.base, tool, cls_arm.gravity, *out) == 0
        _assert_same([t.H, t.h, t.Y, t.J, t.Jdq], out)
        np.testing.assert_array_equal(cls_arm.pose(q), cls_arm.terms(q, np.zeros(n)).Y)
        assert cls_arm.potential(q) == potential(q, table, cls_arm.base, cls_arm.gravity)
        T, Jg = np.empty((4, 4)), np.empty((6, n))
        tip(q, table, cls_arm.base, tool, T, Jg)
        _assert_same(cls_arm.tip_transform(q), [T, Jg])


def test_arm_kernels_refuse_a_wrong_shape_naming_the_argument():
    name, table, base, tool, gravity, _ = CHAINS[0]
    n = table.shape[0]
    q = np.zeros(n)
    with pytest.raises(ValueError, match=f"^q: expected length {n}, got {n - 1}"):
        _core.chain_arm_terms(q[1:].copy(), q, table, base, tool, gravity, *_outputs(n))
    with pytest.raises(ValueError, match="^table: expected at least one row of 32 columns"):
        _core.chain_arm_terms(q, q, table[:, :16].copy(), base, tool, gravity, *_outputs(n))
    with pytest.raises(ValueError, match=r"^tool: expected shape \(4, 4\)"):
        _core.chain_arm_terms(q, q, table, base, tool[:3].copy(), gravity, *_outputs(n))
    out = _outputs(n)
    out[3] = np.empty((3, n))
    with pytest.raises(ValueError, match=r"^J: expected shape \(6, n\)"):
        _core.chain_arm_terms(q, q, table, base, tool, gravity, *out)
    with pytest.raises(ValueError, match=r"^chart: expected shape \(3, 3\)"):
        _core.chain_arm_terms_own_chart(q, q, table, base, tool, gravity, *_outputs(n), np.empty((3, 2)))
    with pytest.raises(ValueError, match="^dh: expected at least one row of 16 columns"):
        _core.dh_arm_terms(q, q, table, base, tool, gravity, *_outputs(n))
    with pytest.raises(ValueError, match="^gravity: expected length 3, got 2"):
        _core.dh_arm_potential(np.zeros(6), puma560().dh_array(), base, gravity[:2].copy())
