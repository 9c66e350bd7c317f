"""Spatial arms: the Puma 560 against the Robotics Toolbox and Pinocchio, finite differences,
energy consistency, inverse kinematics and parameter validation."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from plants.arms import ChainArm, DHLink, SerialArm, puma560
from plants.errors import EulerSingularityError, ParameterError, UnreachablePoseError
from plants.frames import body_rate_map, rotation_zyx

# Oracles (rtb, Pinocchio) agree with us to rounding: the algorithms differ but are exact, so
# relative errors are ~1e-15; 1e-9 leaves six orders of margin.
ORACLE_RTOL = 1e-9
# Central differences with step 1e-6: truncation O(s^2) ~ 1e-12 and rounding ~ eps / s ~ 1e-10
# relative to the scale of the differentiated function, so ~1e-8 relative is a safe bound.
FD_STEP = 1e-6
FD_RTOL = 1e-7
SEEDS = list(range(12))


def rel_err(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b)


def random_state(seed, arm):
    rng = np.random.default_rng(seed)
    lim = arm.q_limits
    q = rng.uniform(lim[:, 0], lim[:, 1])
    dq = rng.uniform(-2.0, 2.0, arm.dof)
    return q, dq


def random_transform(rng, scale=0.5):
    T = np.eye(4)
    T[:3, :3] = rotation_zyx(rng.uniform(-1.0, 1.0, 3))
    T[:3, 3] = rng.uniform(-scale, scale, 3)
    return T


def geometric_from_analytic(Y, J):
    """``[J_v; R L J_A]``: the world geometric Jacobian of our analytic one."""
    A = Y[3:]
    Jg = J.copy()
    Jg[3:] = rotation_zyx(A) @ body_rate_map(A) @ J[3:]
    return Jg


def wrap(x):
    return (x + np.pi) % (2 * np.pi) - np.pi


@pytest.fixture(scope="module")
def arm():
    return puma560()


# ---------------------------------------------------------------- Robotics Toolbox oracle
@pytest.fixture(scope="module")
def rtb_puma():
    rtb = pytest.importorskip("roboticstoolbox")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rtb.models.DH.Puma560().nofriction(coulomb=True, viscous=True)
    for link in robot.links:
        link.Jm = 0.0
    # rtb's gravity is the acceleration vector (0, 0, -9.81), like ours.
    assert np.allclose(robot.gravity, [0.0, 0.0, -9.81])
    return robot


@pytest.mark.parametrize("seed", SEEDS)
def test_puma_matches_rtb(arm, rtb_puma, seed):
    q, dq = random_state(seed, arm)
    t = arm.terms(q, dq)
    assert rel_err(t.H, rtb_puma.inertia(q)) <= ORACLE_RTOL
    assert rel_err(t.h, rtb_puma.rne(q, dq, np.zeros(6))) <= ORACLE_RTOL
    assert rel_err(arm.bias(q, np.zeros(6)), rtb_puma.gravload(q)) <= ORACLE_RTOL
    assert rel_err(geometric_from_analytic(t.Y, t.J), rtb_puma.jacob0(q)) <= ORACLE_RTOL
    T = rtb_puma.fkine(q).A
    assert rel_err(t.Y[:3], T[:3, 3]) <= ORACLE_RTOL
    assert rel_err(rotation_zyx(t.Y[3:]), T[:3, :3]) <= ORACLE_RTOL


def test_puma_parameters_are_rtb_numbers(arm, rtb_puma):
    # rtb stores d1 as 0.6718299999999999 (the result of its own arithmetic): compare to 1 ulp-ish.
    for ours, theirs in zip(arm.links, rtb_puma.links):
        assert np.allclose([ours.a, ours.alpha, ours.d, ours.offset], [theirs.a, theirs.alpha, theirs.d, theirs.offset], rtol=1e-15, atol=0)
        assert ours.mass == theirs.m
        assert np.array_equal(ours.rc, theirs.r)
        assert np.array_equal(ours.inertia_matrix(), theirs.I)
    assert np.allclose(arm.q_limits, rtb_puma.qlim.T)


# ---------------------------------------------------------------- Pinocchio oracle
def dh_placement(pin, row):
    """``Rz(offset) Tz(d) Tx(a) Rx(alpha)`` as a pinocchio SE3."""
    a, alpha, d, offset = row[0], row[1], row[2], row[3]
    Rz = pin.utils.rotate("z", offset)
    Rx = pin.utils.rotate("x", alpha)
    return pin.SE3(Rz, np.zeros(3)) * pin.SE3(np.eye(3), np.array([0.0, 0.0, d])) * pin.SE3(
        Rx, np.array([a, 0.0, 0.0])
    )


def pinocchio_model(arm):
    """Joint k is a revolute-Z joint in DH frame k-1; link k hangs on it through its DH placement."""
    pin = pytest.importorskip("pinocchio")
    model = pin.Model()
    model.gravity.linear = arm.gravity
    parent = 0
    placement = pin.SE3(arm.base[:3, :3], arm.base[:3, 3])
    for k, row in enumerate(arm.dh_array()):
        joint = model.addJoint(parent, pin.JointModelRZ(), placement, f"j{k}")
        P = dh_placement(pin, row)
        link = arm.links[k]
        model.appendBodyToJoint(joint, P.act(pin.Inertia(link.mass, np.array(link.rc), link.inertia_matrix())), pin.SE3.Identity())
        parent, placement = joint, P
    tool = placement * pin.SE3(arm.tool[:3, :3], arm.tool[:3, 3])
    frame = model.addFrame(pin.Frame("tool", parent, tool, pin.FrameType.OP_FRAME))
    return pin, model, frame


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("mounted", [False, True])
def test_puma_matches_pinocchio(seed, mounted):
    arm = puma560()
    if mounted:
        rng = np.random.default_rng(100 + seed)
        arm = arm.with_base(random_transform(rng, 2.0)).with_tool(random_transform(rng, 0.2))
    pin, model, frame = pinocchio_model(arm)
    data = model.createData()
    q, dq = random_state(seed, arm)
    t = arm.terms(q, dq)
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    assert rel_err(t.H, M) <= ORACLE_RTOL
    assert rel_err(t.h, pin.nonLinearEffects(model, data, q, dq)) <= ORACLE_RTOL
    pin.forwardKinematics(model, data, q, dq, np.zeros(arm.dof))
    pin.updateFramePlacements(model, data)
    Jp = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
    assert rel_err(geometric_from_analytic(t.Y, t.J), Jp) <= ORACLE_RTOL
    oMf = data.oMf[frame]
    assert rel_err(t.Y[:3], oMf.translation) <= ORACLE_RTOL
    assert rel_err(rotation_zyx(t.Y[3:]), oMf.rotation) <= ORACLE_RTOL
    # Jdq: classical acceleration of the tool frame at qdd = 0, mapped to Euler coordinates
    a = pin.getFrameClassicalAcceleration(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
    assert rel_err(t.Jdq[:3], a.linear) <= ORACLE_RTOL
    A, dA = t.Y[3:], t.J[3:] @ dq
    from plants.frames import body_rate_map_dot

    R, L = rotation_zyx(A), body_rate_map(A)
    # omega_body = L dA  =>  R^T alpha_w = L ddA + Ldot dA
    assert rel_err(R @ (L @ t.Jdq[3:] + body_rate_map_dot(A, dA) @ dA), a.angular) <= ORACLE_RTOL


def test_motor_inertia_and_viscous_friction(arm):
    rich = puma560(motor_inertia=True, viscous_friction=True)
    q, dq = random_state(3, arm)
    Jm = np.array([200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6])
    G = np.array([-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686])
    B = np.array([1.48e-3, 0.817e-3, 1.38e-3, 71.2e-6, 82.6e-6, 36.7e-6])
    assert np.allclose(rich.inertia(q) - arm.inertia(q), np.diag(Jm * G**2), rtol=1e-12, atol=1e-12)
    assert np.allclose(rich.bias(q, dq) - arm.bias(q, dq), B * G**2 * dq, rtol=1e-12, atol=1e-12)
    assert all(link.motor_inertia == 0.0 and link.viscous == 0.0 for link in arm.links)


# ---------------------------------------------------------------- finite differences
def mounted_puma():
    rng = np.random.default_rng(7)
    return puma560(base=random_transform(rng, 1.0), tool=random_transform(rng, 0.15))


@pytest.mark.parametrize("seed", SEEDS[:6])
@pytest.mark.parametrize("make", [puma560, mounted_puma])
def test_jacobian_is_derivative_of_pose(make, seed):
    arm = make()
    q, _ = random_state(seed, arm)
    J = arm.jacobian(q)
    fd = np.empty_like(J)
    for k in range(arm.dof):
        e = np.zeros(arm.dof)
        e[k] = FD_STEP
        d = arm.pose(q + e) - arm.pose(q - e)
        d[3:] = wrap(d[3:])
        fd[:, k] = d / (2 * FD_STEP)
    assert rel_err(J, fd) <= FD_RTOL


@pytest.mark.parametrize("seed", SEEDS[:6])
@pytest.mark.parametrize("make", [puma560, mounted_puma])
def test_jacobian_dot_qd_is_derivative_of_jacobian(make, seed):
    arm = make()
    q, dq = random_state(seed, arm)
    fd = (arm.jacobian(q + FD_STEP * dq) @ dq - arm.jacobian(q - FD_STEP * dq) @ dq) / (2 * FD_STEP)
    assert rel_err(arm.jacobian_dot_qd(q, dq), fd) <= FD_RTOL


@pytest.mark.parametrize("seed", SEEDS[:6])
@pytest.mark.parametrize("make", [puma560, mounted_puma])
def test_gravity_is_gradient_of_potential(make, seed):
    arm = make()
    q, _ = random_state(seed, arm)
    grad = np.empty(arm.dof)
    for k in range(arm.dof):
        e = np.zeros(arm.dof)
        e[k] = FD_STEP
        grad[k] = (arm.potential(q + e) - arm.potential(q - e)) / (2 * FD_STEP)
    assert rel_err(arm.bias(q, np.zeros(arm.dof)), grad) <= FD_RTOL


@pytest.mark.parametrize("seed", SEEDS[:6])
def test_energy_consistency(arm, seed):
    """``dq^T (dH/dt - 2 C) dq = 0``: the velocity part of h does no work beyond 1/2 dq^T dH dq."""
    q, dq = random_state(seed, arm)
    coriolis = arm.bias(q, dq) - arm.bias(q, np.zeros(arm.dof))
    Hdot = (arm.inertia(q + FD_STEP * dq) - arm.inertia(q - FD_STEP * dq)) / (2 * FD_STEP)
    lhs, rhs = dq @ coriolis, 0.5 * dq @ Hdot @ dq
    assert abs(lhs - rhs) <= FD_RTOL * abs(rhs) + 1e-12
    assert arm.kinetic(q, dq) == pytest.approx(0.5 * dq @ arm.inertia(q) @ dq, rel=1e-14)


def test_terms_consistent_with_single_methods(arm):
    q, dq = random_state(1, arm)
    t = arm.terms(q, dq)
    assert np.array_equal(t.H, arm.inertia(q))
    assert np.array_equal(t.h, arm.bias(q, dq))
    assert np.array_equal(t.Y, arm.pose(q))
    assert np.array_equal(t.J, arm.jacobian(q))
    assert np.array_equal(t.Jdq, arm.jacobian_dot_qd(q, dq))
    assert arm.dh_array().shape == (6, 16) and arm.dh_array().dtype == np.float64
    assert arm.space == "spatial" and arm.dof == 6


def test_base_translation_shifts_pose_only(arm):
    q, dq = random_state(2, arm)
    base = np.eye(4)
    base[:3, 3] = [1.0, -2.0, 0.5]
    moved = arm.with_base(base)
    assert np.allclose(moved.inertia(q), arm.inertia(q), rtol=1e-13, atol=1e-13)
    assert np.allclose(moved.bias(q, dq), arm.bias(q, dq), rtol=1e-12, atol=1e-12)
    assert np.allclose(moved.pose(q)[:3], arm.pose(q)[:3] + base[:3, 3], atol=1e-13)
    assert np.array_equal(arm.base, np.eye(4))


# ---------------------------------------------------------------- inverse kinematics
@pytest.mark.parametrize("seed", SEEDS[:5])
def test_inverse_kinematics_round_trip(arm, seed):
    q, _ = random_state(seed, arm)
    # keep the wrist away from its singularity (q5 = 0) so that the pose is well defined
    q[4] = np.sign(q[4]) * max(abs(q[4]), 0.3)
    Y = arm.pose(q)
    q_ik = arm.inverse_kinematics(Y)
    assert np.all(q_ik >= arm.q_limits[:, 0]) and np.all(q_ik <= arm.q_limits[:, 1])
    T_ik, _ = arm.tip_transform(q_ik)
    T, _ = arm.tip_transform(q)
    assert np.linalg.norm(T_ik[:3, 3] - T[:3, 3]) <= 1e-9
    assert np.linalg.norm(T_ik[:3, :3] - T[:3, :3]) <= 1e-9


def test_inverse_kinematics_unreachable(arm):
    with pytest.raises(UnreachablePoseError, match="puma560") as info:
        arm.inverse_kinematics([3.0, 0.0, 0.5, 0.0, 0.0, 0.0], seeds=3)
    assert info.value.residual > 1.0


# ---------------------------------------------------------------- errors
def test_euler_singular_tip_raises(arm):
    q = np.zeros(6)
    T, _ = arm.tip_transform(q)
    tool = np.eye(4)
    tool[:3, :3] = T[:3, :3].T @ rotation_zyx(np.array([0.3, np.pi / 2, 0.0]))
    with pytest.raises(EulerSingularityError, match="puma560' tip") as info:
        arm.with_tool(tool).terms(q, np.zeros(6))
    assert info.value.where == "arm 'puma560' tip"
    with pytest.raises(EulerSingularityError):
        arm.with_tool(tool).pose(q)


@pytest.mark.parametrize(
    "kwargs, parameter",
    [
        (dict(mass=-1.0), "links[2].mass"),
        (dict(mass=float("nan")), "links[2].mass"),
        (dict(a=float("inf")), "links[2].a"),
        (dict(inertia=(1.0, -1.0, 1.0, 0.0, 0.0, 0.0)), "links[2].inertia"),
        (dict(mass=1.0, inertia=(0.1, 0.1, 0.5, 0.0, 0.0, 0.0)), "links[2].inertia"),
        (dict(inertia=(1.0, 1.0, 1.0, 2.0, 0.0, 0.0)), "links[2].inertia"),
        (dict(rc=(0.0, float("nan"), 0.0)), "links[2].rc"),
        (dict(motor_inertia=-1e-3), "links[2].motor_inertia"),
        (dict(viscous=-0.1), "links[2].viscous"),
    ],
)
def test_bad_link_parameters(kwargs, parameter):
    with pytest.raises(ParameterError, match=parameter.replace("[", r"\[").replace("]", r"\]")) as info:
        DHLink.named("links[2]", **kwargs)
    assert info.value.parameter == parameter


def test_bad_arm_parameters():
    link = DHLink(a=0.3, mass=1.0, inertia=(0.01, 0.01, 0.01, 0, 0, 0))
    with pytest.raises(ParameterError, match="base"):
        SerialArm("x", (link,), base=np.ones((4, 4)))
    with pytest.raises(ParameterError, match="tau_max"):
        SerialArm("x", (link,), tau_max=[-1.0])
    with pytest.raises(ParameterError, match="q_limits"):
        SerialArm("x", (link,), q_limits=[[1.0, -1.0]])
    with pytest.raises(ParameterError, match="gravity"):
        SerialArm("x", (link,), gravity=[0.0, float("nan"), 0.0])
    with pytest.raises(ParameterError, match="q"):
        SerialArm("x", (link,)).inertia([0.0, 0.0])


# ---------------------------------------------------------------- the node in its own chart
@pytest.mark.parametrize("singular", [False, True])
def test_own_chart_terms_are_the_geometric_ones_everywhere(arm, singular):
    """``ChainArm.terms_in_own_chart``: the node's angles in its own chart ``C = R_tip`` (``A = 0``,
    docs/model.md s.2) exist at every pose, the tip at pitch 90 deg included (``singular``: the world
    angles raise there). ``C L(0) J_A`` is the world geometric Jacobian, ``H``, ``h`` and the
    translational rows are the world chart's, and the angular ``Jdq`` gives the classical angular
    acceleration ``C (L(0) Jdq + Ldot(0, dA) dA)``, checked by central differences of ``Jg(q) dq``."""
    from plants.frames import body_rate_map_dot

    q, dq = random_state(3, arm)
    world = ChainArm(arm.name, arm.chain_joints(), base=arm.base, tool=arm.kernel_tool(), gravity=arm.gravity).terms(q, dq)
    if singular:
        T, _ = arm.tip_transform(q)
        tool = np.eye(4)
        tool[:3, :3] = T[:3, :3].T @ rotation_zyx(np.array([0.3, np.pi / 2, 0.0]))
        arm = arm.with_tool(tool)  # the same tip point: H, h and the translational rows are unchanged
    chain = ChainArm(arm.name, arm.chain_joints(), base=arm.base, tool=arm.kernel_tool(), gravity=arm.gravity)
    t, C = chain.terms_in_own_chart(q, dq)
    H, h, Y, J, Jdq = t.H, t.h, t.Y, t.J, t.Jdq
    if singular:
        with pytest.raises(EulerSingularityError):
            chain.terms(q, dq)
    T, Jg = arm.tip_transform(q)
    assert np.array_equal(Y[3:], np.zeros(3))
    assert rel_err(C, T[:3, :3]) <= ORACLE_RTOL
    assert rel_err(Y[:3], T[:3, 3]) <= ORACLE_RTOL
    L0 = body_rate_map(np.zeros(3))
    assert rel_err(C @ L0 @ J[3:], Jg[3:]) <= ORACLE_RTOL
    assert np.array_equal(H, world.H) and np.array_equal(h, world.h)
    assert np.array_equal(J[:3], world.J[:3]) and np.array_equal(Jdq[:3], world.Jdq[:3])
    dA = J[3:] @ dq
    alpha = C @ (L0 @ Jdq[3:] + body_rate_map_dot(np.zeros(3), dA) @ dA)
    fd = (arm.tip_transform(q + FD_STEP * dq)[1][3:] @ dq - arm.tip_transform(q - FD_STEP * dq)[1][3:] @ dq) / (2 * FD_STEP)
    assert rel_err(alpha, fd) <= FD_RTOL
