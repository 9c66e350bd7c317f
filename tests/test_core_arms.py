"""plants/core/chain_arm and plants/core/dh_arm (the compiled core's spatial arms, plants._core), on the shipped arms
(Puma 560 as DH and as a chain, Panda, UR5e, iiwa 14) and on seeded random tables with every joint kind: ``H``
symmetric positive definite, the gravity torque at rest the potential's gradient and the tip's velocity the
geometric Jacobian's (central differences), the analytic Jacobian the geometric one mapped to Euler rates, the pose
and tip entry points the terms' numbers, the node in its own chart the world chart's terms with ``C = R_tip``, the
Euler singularity reported; and the arguments checked once at the binding. The classes on the core (SerialArm,
ChainArm) keep their Pinocchio oracle tests (tests/test_arms.py, tests/test_urdf_arms.py). The bit-for-bit
comparison with the numba kernels these replaced went with them: it was run when the core was ported, and the
golden records (tests/golden) lock a run's numbers."""

from __future__ import annotations

import numpy as np
import pytest

from plants import _core
from plants.arms import ChainArm, ChainJoint, iiwa14, panda, puma560, ur5e
from plants.arms.puma560 import GRIPPER_TOOL
from plants.errors import EulerSingularityError
from plants.frames import body_rate_map, rotation_zyx

DRAWS = 25
#: Identities of exact arithmetic evaluated two ways (tests/test_arms.py's ORACLE_RTOL).
EXACT_RTOL = 1e-9
#: Central differences, step 1e-6 on O(1) functions: truncation ~h^2, rounding ~eps/h (tests/test_arms.py's).
FD_STEP, FD_RTOL = 1e-6, 1e-7


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


def _scaled(a, b, rtol):
    np.testing.assert_allclose(a, b, rtol=0.0, atol=rtol * (1.0 + np.abs(b).max()))


def _assert_arm_physics(terms, potential, tip, table, base, tool, gravity, q, dq):
    """One arm's core entry points at (q, dq); returns the terms' status and outputs."""
    n = q.shape[0]
    out = _outputs(n)
    status = terms(q, dq, table, base, tool, gravity, *out)
    H, h, Y, J, Jdq = out
    np.testing.assert_array_equal(H, H.T)
    assert np.linalg.eigvalsh(H).min() > 0.0
    T, Jg = np.empty((4, 4)), np.empty((6, n))
    tip(q, table, base, tool, T, Jg)
    _scaled(Y[:3], T[:3, 3], EXACT_RTOL)
    _scaled(J[:3], Jg[:3], EXACT_RTOL)
    if status == 0:
        _scaled(rotation_zyx(Y[3:]), T[:3, :3], EXACT_RTOL)
        _scaled(T[:3, :3] @ body_rate_map(Y[3:]) @ J[3:], Jg[3:], EXACT_RTOL)
    v = (_tip_position(tip, q + FD_STEP * dq, table, base, tool) - _tip_position(tip, q - FD_STEP * dq, table, base,
                                                                               tool)) / (2 * FD_STEP)
    _scaled(Jg[:3] @ dq, v, FD_RTOL)
    rest = _outputs(n)
    terms(q, np.zeros(n), table, base, tool, gravity, *rest)
    grad = np.array([(potential(q + FD_STEP * e, table, base, gravity) - potential(q - FD_STEP * e, table, base, gravity))
                     / (2 * FD_STEP) for e in np.eye(n)])
    _scaled(rest[1], grad, FD_RTOL)  # friction vanishes at rest: h(q, 0) is gravity's torque
    return status, out


def _tip_position(tip, q, table, base, tool):
    T, Jg = np.empty((4, 4)), np.empty((6, q.shape[0]))
    tip(q, table, base, tool, T, Jg)
    return T[:3, 3]


@pytest.mark.parametrize("name, table, base, tool, gravity, limits", CHAINS, ids=[c[0] for c in CHAINS])
def test_chain_arm_kernels_are_the_arms_mechanics(name, table, base, tool, gravity, limits):
    n = table.shape[0]
    rng = np.random.default_rng(n + 31 * len(name))
    for q, dq in _states(rng, limits):
        status, world = _assert_arm_physics(_core.chain_arm_terms, _core.chain_arm_potential, _core.chain_arm_tip,
                                            table, base, tool, gravity, q, dq)
        chart = np.full((3, 3), np.nan)
        own = _outputs(n)
        assert _core.chain_arm_terms_own_chart(q, dq, table, base, tool, gravity, *own, chart) == 0
        _assert_same([own[0], own[1], own[2][:3], own[3][:3], own[4][:3]],
                     [world[0], world[1], world[2][:3], world[3][:3], world[4][:3]])
        np.testing.assert_array_equal(own[2][3:], 0.0)
        T, Jg = np.empty((4, 4)), np.empty((6, n))
        _core.chain_arm_tip(q, table, base, tool, T, Jg)
        np.testing.assert_array_equal(chart, T[:3, :3])
        _scaled(chart @ body_rate_map(np.zeros(3)) @ own[3][3:], Jg[3:], EXACT_RTOL)
        for own_chart, want in ((False, world), (True, own)):
            Y = np.full(6, np.nan)
            assert _core.chain_arm_pose(q, table, base, tool, own_chart, Y) == (0 if own_chart else status)
            np.testing.assert_array_equal(Y, want[2])


def _dh_arms():
    rng = np.random.default_rng(11)
    puma = puma560(tool=GRIPPER_TOOL, motor_inertia=True, viscous_friction=True)
    arms = [("puma560", np.ascontiguousarray(puma.dh_array()), np.eye(4), puma.tool, np.asarray(puma.gravity))]
    arms += [(f"random{n}", _random_dh_table(rng, n), _pose(rng), _pose(rng, 0.2), rng.normal(size=3) * 5.0)
             for n in (1, 2, 4, 6, 8)]
    return arms


DH_ARMS = _dh_arms()


@pytest.mark.parametrize("name, dh, base, tool, gravity", DH_ARMS, ids=[a[0] for a in DH_ARMS])
def test_dh_arm_kernels_are_the_arms_mechanics(name, dh, base, tool, gravity):
    n = dh.shape[0]
    rng = np.random.default_rng(100 + n)
    for q, dq in _states(rng, np.tile([-np.pi, np.pi], (n, 1))):
        _assert_arm_physics(_core.dh_arm_terms, _core.dh_arm_potential, _core.dh_arm_tip, dh, base, tool, gravity,
                            q, dq)


def test_the_singular_tip_returns_1_with_zero_angular_rows():
    """A tool pitched by exactly pi/2 puts the tip's theta on the singularity of L (cos theta ~ 6e-17): the DH and
    the chain terms return 1 and zero the angular rows of J and Jdq, the rest still written (finite, ``H`` symmetric)."""
    rng = np.random.default_rng(3)
    tool = np.eye(4)
    tool[:3, :3] = rotation_zyx(np.array([0.0, np.pi / 2, 0.0]))
    dh = _random_dh_table(rng, 3)
    dh[:, 1] = 0.0  # every axis along world z: the tip's pitch stays the tool's
    table = np.zeros((3, 32))
    table[:, 4:13] = np.eye(3).reshape(-1)
    table[:, 16:26] = dh[:, 4:14]
    q, dq, g = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3), np.array([0.0, 0.0, -9.81])
    for core_fn, tab in ((_core.dh_arm_terms, dh), (_core.chain_arm_terms, table)):
        core = _outputs(3)
        assert core_fn(q, dq, tab, np.eye(4), tool, g, *core) == 1
        np.testing.assert_array_equal(core[3][3:], 0.0)
        np.testing.assert_array_equal(core[4][3:], 0.0)
        assert all(np.all(np.isfinite(a)) for a in core)
        np.testing.assert_array_equal(core[0], core[0].T)
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
