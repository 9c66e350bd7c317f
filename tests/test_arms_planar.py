"""Planar arms: the 3R arm against Pinocchio (revolute about -y), finite differences, energy
consistency, inverse kinematics, torque limits and parameter validation."""

from __future__ import annotations

import numpy as np
import pytest

from plants.arms import PlanarArm, PlanarLink, planar3r
from plants.errors import ParameterError, UnreachablePoseError

# Exact algorithms on both sides: ~1e-15 relative; 1e-9 leaves a wide margin.
ORACLE_RTOL = 1e-9
# Central differences, step 1e-6: truncation ~1e-12, rounding ~eps/s ~1e-10 relative.
FD_STEP = 1e-6
FD_RTOL = 1e-7
SEEDS = list(range(12))


def rel_err(a, b):
    return np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b)


def random_state(seed, arm):
    rng = np.random.default_rng(seed)
    q = rng.uniform(arm.q_limits[:, 0], arm.q_limits[:, 1])
    dq = rng.uniform(-2.0, 2.0, arm.dof)
    return q, dq


def default_arm():
    return planar3r()


def mounted_arm():
    """Asymmetric COMs, a base pose, a tool offset, motor inertia and friction."""
    links = (
        PlanarLink(0.5, 3.0, (0.2, 0.03), 0.08, motor_inertia=0.01, viscous=0.2),
        PlanarLink(0.35, 2.0, (0.15, -0.02), 0.03),
        PlanarLink(0.2, 0.7, (0.05, 0.01), 0.004, viscous=0.05),
        PlanarLink(0.1, 0.3, (0.04, 0.0), 0.001),
    )
    return PlanarArm("mounted", links, base=(0.3, 0.8, -0.4), tool=(0.05, 0.02, 0.3))


ARMS = [default_arm, mounted_arm]


# ---------------------------------------------------------------- Pinocchio oracle
def pinocchio_model(arm):
    """Our theta runs from +x towards +z, i.e. a rotation about -y: revolute joints on -y."""
    pin = pytest.importorskip("pinocchio")
    axis = np.array([0.0, -1.0, 0.0])

    def planar_se3(x, z, theta):
        return pin.SE3(pin.utils.rotate("y", -theta), np.array([x, 0.0, z]))

    model = pin.Model()
    model.gravity.linear = np.array([arm.gravity[0], 0.0, arm.gravity[1]])
    placement = planar_se3(*arm.base)
    parent = 0
    for k, link in enumerate(arm.links):
        joint = model.addJoint(parent, pin.JointModelRevoluteUnaligned(axis), placement, f"j{k}")
        inertia = np.diag([link.izz, link.izz, link.izz])  # only the -y moment matters in plane
        com = np.array([link.rc[0], 0.0, link.rc[1]])
        model.appendBodyToJoint(joint, pin.Inertia(link.mass, com, inertia), pin.SE3.Identity())
        parent, placement = joint, planar_se3(link.length, 0.0, 0.0)
    tool = placement * planar_se3(*arm.tool)
    frame = model.addFrame(pin.Frame("tool", parent, tool, pin.FrameType.OP_FRAME))
    return pin, model, frame


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("make", ARMS)
def test_planar_matches_pinocchio(make, seed):
    arm = make()
    pin, model, frame = pinocchio_model(arm)
    data = model.createData()
    q, dq = random_state(seed, arm)
    t = arm.terms(q, dq)
    motor = np.diag([link.motor_inertia for link in arm.links])
    friction = np.array([link.viscous for link in arm.links]) * dq
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    assert rel_err(t.H - motor, M) <= ORACLE_RTOL
    assert rel_err(t.h - friction, pin.nonLinearEffects(model, data, q, dq)) <= ORACLE_RTOL
    pin.forwardKinematics(model, data, q, dq, np.zeros(arm.dof))
    pin.updateFramePlacements(model, data)
    oMf = data.oMf[frame]
    R = oMf.rotation
    assert rel_err(t.Y[:2], oMf.translation[[0, 2]]) <= ORACLE_RTOL
    assert abs(np.angle(np.exp(1j * (t.Y[2] - np.arctan2(R[2, 0], R[0, 0]))))) <= 1e-12
    Jp = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
    Jref = np.vstack([Jp[0], Jp[2], -Jp[4]])
    assert rel_err(t.J, Jref) <= ORACLE_RTOL
    a = pin.getFrameClassicalAcceleration(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
    assert rel_err(t.Jdq, [a.linear[0], a.linear[2], -a.angular[1]]) <= ORACLE_RTOL


# ---------------------------------------------------------------- finite differences
@pytest.mark.parametrize("seed", SEEDS[:6])
@pytest.mark.parametrize("make", ARMS)
def test_jacobian_and_jacobian_dot(make, seed):
    arm = make()
    q, dq = random_state(seed, arm)
    fd = np.empty((3, arm.dof))
    for k in range(arm.dof):
        e = np.zeros(arm.dof)
        e[k] = FD_STEP
        fd[:, k] = (arm.pose(q + e) - arm.pose(q - e)) / (2 * FD_STEP)
    assert rel_err(arm.jacobian(q), fd) <= FD_RTOL
    fd_dot = (arm.jacobian(q + FD_STEP * dq) @ dq - arm.jacobian(q - FD_STEP * dq) @ dq) / (2 * FD_STEP)
    assert rel_err(arm.jacobian_dot_qd(q, dq), fd_dot) <= FD_RTOL


@pytest.mark.parametrize("seed", SEEDS[:6])
@pytest.mark.parametrize("make", ARMS)
def test_gravity_and_energy(make, seed):
    arm = make()
    q, dq = random_state(seed, arm)
    friction = np.array([link.viscous for link in arm.links]) * dq
    grad = np.empty(arm.dof)
    for k in range(arm.dof):
        e = np.zeros(arm.dof)
        e[k] = FD_STEP
        grad[k] = (arm.potential(q + e) - arm.potential(q - e)) / (2 * FD_STEP)
    gravity = arm.bias(q, np.zeros(arm.dof))
    assert rel_err(gravity, grad) <= FD_RTOL
    # dq^T (dH/dt - 2C) dq = 0
    coriolis = arm.bias(q, dq) - gravity - friction
    Hdot = (arm.inertia(q + FD_STEP * dq) - arm.inertia(q - FD_STEP * dq)) / (2 * FD_STEP)
    rhs = 0.5 * dq @ Hdot @ dq
    assert abs(dq @ coriolis - rhs) <= FD_RTOL * abs(rhs) + 1e-12


# ---------------------------------------------------------------- inverse kinematics
@pytest.mark.parametrize("seed", SEEDS[:5])
@pytest.mark.parametrize("make", [default_arm])
def test_inverse_kinematics_round_trip(make, seed):
    arm = make()
    q, _ = random_state(seed, arm)
    Y = arm.pose(q)
    q_ik = arm.inverse_kinematics(Y)
    err = arm.pose(q_ik) - Y
    err[2] = np.angle(np.exp(1j * err[2]))
    assert np.linalg.norm(err[:2]) <= 1e-9 and abs(err[2]) <= 1e-9


def test_inverse_kinematics_unreachable():
    arm = planar3r()
    with pytest.raises(UnreachablePoseError, match="planar3r"):
        arm.inverse_kinematics([2.0, 0.0, 0.0], seeds=3)


# ---------------------------------------------------------------- torque limits
@pytest.mark.parametrize("seed", SEEDS[:6])
def test_planar3r_holds_itself_and_payload(seed):
    """Static torque with 5 kg at the tip stays below tau_max / 1.5 everywhere."""
    arm = planar3r()
    q, _ = random_state(seed, arm)
    t = arm.terms(q, np.zeros(3))
    f_c = np.array([0.0, -5.0 * 9.81, 0.0])  # the payload pulls the node down
    tau = t.h - t.J.T @ f_c  # H qdd + h = tau + J^T f_c at rest
    assert np.all(np.abs(tau) <= arm.tau_max / 1.5)


def test_planar3r_defaults():
    arm = planar3r()
    assert arm.space == "planar" and arm.dof == 3
    assert arm.link_array().shape == (3, 7)
    assert arm.links[0].izz == pytest.approx(4.0 * 0.4**2 / 12)
    assert np.all(np.isfinite(arm.tau_max))


def test_with_base_and_tool():
    arm = planar3r()
    q = np.array([0.3, -0.2, 0.5])
    moved = arm.with_base((1.0, 2.0, 0.0)).with_tool((0.1, 0.0, 0.0))
    assert np.allclose(moved.inertia(q), arm.inertia(q), rtol=1e-13)
    Y = arm.pose(q)
    assert np.allclose(moved.pose(q), Y + [1.0 + 0.1 * np.cos(Y[2]), 2.0 + 0.1 * np.sin(Y[2]), 0.0])


# ---------------------------------------------------------------- errors
@pytest.mark.parametrize(
    "kwargs, parameter",
    [
        (dict(length=0.3, mass=-1.0), "links[1].mass"),
        (dict(length=float("nan")), "links[1].length"),
        (dict(length=0.3, izz=-0.1), "links[1].izz"),
        (dict(length=0.3, rc=(0.0, float("inf"))), "links[1].rc"),
        (dict(length=0.3, viscous=-1.0), "links[1].viscous"),
    ],
)
def test_bad_link_parameters(kwargs, parameter):
    with pytest.raises(ParameterError) as info:
        PlanarLink.named("links[1]", **kwargs)
    assert info.value.parameter == parameter


def test_bad_masses_in_factory():
    with pytest.raises(ParameterError) as info:
        planar3r(masses=(1.0, -2.0, 1.0))
    assert info.value.parameter == "links[1].mass"
