"""Arms from URDF against Pinocchio (the oracle), built from the same file.

``H``, ``h`` (gravity and joint damping included), the tip pose, the Jacobian into the
project's pose coordinates ``(r, A)`` (ZYX Euler, docs/model.md s.2) and ``dJ dq`` agree within
1e-9 relative at seeded random configurations: both sides are exact rigid-body algorithms in
double precision, so they differ only by rounding (observed ~1e-14).
"""

from __future__ import annotations

import numpy as np
import pytest

from plants.arms import ChainArm, from_urdf, iiwa14, panda, puma560, ur5e
from plants.arms.named_robots import NAMED_ROBOTS, urdf_path
from plants.errors import ParameterError
from plants.frames import body_rate_map_dot, body_rate_map_inv, euler_zyx_from_rotation

pin = pytest.importorskip("pinocchio")

REL = 1e-9  # relative agreement required (rounding-level differences only)
ROBOTS = {"panda": panda, "ur5e": ur5e, "iiwa14": iiwa14}


def _pin_model(robot):
    path, base_link, tip_link = urdf_path(robot), NAMED_ROBOTS[robot][1], NAMED_ROBOTS[robot][2]
    full = pin.buildModelFromUrdf(path)
    arm = ROBOTS[robot]()
    keep = set(arm.joint_names)
    lock = [full.getJointId(nm) for nm in full.names[1:] if nm not in keep]
    model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
    assert list(model.names[1:]) == list(arm.joint_names)
    return model, model.getFrameId(tip_link), arm


def _close(a, b, what):
    scale = max(np.linalg.norm(b), 1e-12)
    err = np.linalg.norm(np.asarray(a) - np.asarray(b)) / scale
    assert err <= REL, f"{what}: relative error {err:.3g}"


def _pin_pose_terms(model, data, fid, q, dq):
    """Tip pose Y, analytic J and dJ dq in (r, ZYX Euler) coordinates from Pinocchio."""
    pin.forwardKinematics(model, data, q, dq, np.zeros(model.nv))
    pin.updateFramePlacements(model, data)
    M = data.oMf[fid]
    R = M.rotation
    A = euler_zyx_from_rotation(np.ascontiguousarray(R))
    Y = np.concatenate([M.translation, A])
    pin.computeJointJacobians(model, data, q)
    Jg = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
    Linv = body_rate_map_inv(A)
    J = np.vstack([Jg[:3], Linv @ R.T @ Jg[3:]])
    acc = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
    w = Jg[3:] @ dq
    dA = Linv @ R.T @ w
    ddA = Linv @ (R.T @ acc.angular - body_rate_map_dot(A, dA) @ dA)
    return Y, J, np.concatenate([acc.linear, ddA])


@pytest.mark.parametrize("robot", sorted(ROBOTS))
def test_arm_matches_pinocchio(robot):
    model, fid, arm = _pin_model(robot)
    data = model.createData()
    rng = np.random.default_rng(13)
    lower, upper = arm.q_limits[:, 0], arm.q_limits[:, 1]
    damping = np.array([j.viscous for j in arm.joints])
    for _ in range(5):
        q = rng.uniform(np.maximum(lower, -np.pi), np.minimum(upper, np.pi))
        dq = rng.uniform(-1.5, 1.5, arm.dof)
        t = arm.terms(q, dq)
        _close(t.H, _sym(pin.crba(model, data, q)), f"{robot} H")
        h_pin = pin.rnea(model, data, q, dq, np.zeros(arm.dof)) + damping * dq
        _close(t.h, h_pin, f"{robot} h")
        Y, J, Jdq = _pin_pose_terms(model, data, fid, q, dq)
        _close(t.Y[:3], Y[:3], f"{robot} tip position")
        # angles compared through the rotation (Euler angles wrap at +-pi)
        from plants.frames import rotation_zyx
        _close(rotation_zyx(t.Y[3:]), rotation_zyx(Y[3:]), f"{robot} tip rotation")
        _close(t.J, J, f"{robot} J")
        _close(t.Jdq, Jdq, f"{robot} dJ dq")
        # public API, one quantity each
        _close(arm.inertia(q), t.H, "inertia()")
        _close(arm.jacobian_dot_qd(q, dq), t.Jdq, "jacobian_dot_qd()")


def _sym(H):
    H = np.array(H)
    return np.triu(H) + np.triu(H, 1).T


def test_puma_chain_kernel_matches_dh_kernel():
    """The DH arm converted to general joints (a ChainArm) gives the DH arm's terms (exact conversion)."""
    arm = puma560(viscous_friction=True, motor_inertia=True)
    chain = ChainArm(arm.name, arm.chain_joints(), base=arm.base, tool=arm.kernel_tool(), gravity=arm.gravity)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = rng.uniform(-2.0, 2.0, 6)
        dq = rng.uniform(-1.0, 1.0, 6)
        ref = arm.terms(q, dq)
        t = chain.terms(q, dq)
        H, h, Y, J, Jdq = t.H, t.h, t.Y, t.J, t.Jdq
        for a, b, what in ((H, ref.H, "H"), (h, ref.h, "h"), (Y, ref.Y, "Y"), (J, ref.J, "J"), (Jdq, ref.Jdq, "Jdq")):
            _close(a, b, f"puma chain {what}")


def test_tip_is_the_tip_link_frame_and_tool_composes():
    arm = ur5e()
    q = np.array([0.3, -1.2, 1.4, -0.5, 0.7, 0.2])
    T, _ = arm.tip_transform(q)
    tool = np.eye(4)
    tool[:3, 3] = (0.0, 0.0, 0.1)
    T2, _ = ur5e(tool=tool).tip_transform(q)
    assert np.allclose(T2[:3, 3], T[:3, 3] + 0.1 * T[:3, 2], atol=1e-12)


def test_fingers_are_a_rigid_payload_of_link_7():
    """Hand (0.73 kg) and fingers (2 x 0.015 kg) are folded into the last link of the Panda."""
    arm = panda()
    assert arm.dof == 7
    assert arm.joints[-1].mass == pytest.approx(0.735522 + 0.73 + 2 * 0.015, rel=1e-12)


def test_continuous_and_prismatic_joints(tmp_path):
    """A continuous joint takes any angle (no limits); a prismatic joint moves along its axis."""
    urdf = tmp_path / "rp.urdf"
    urdf.write_text(_RP_URDF)
    arm = from_urdf(urdf, "base", "tip")
    assert np.all(np.isinf(arm.q_limits[0])) and arm.tau_max[1] == 50.0
    T, _ = arm.tip_transform([7.0, 0.2])  # beyond 2 pi
    assert np.allclose(T[:3, 3], [0.2 * np.cos(7.0) + 0.1 * np.cos(7.0), 0.2 * np.sin(7.0) + 0.1 * np.sin(7.0), 0.5])
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    q_pin = np.array([np.cos(7.0), np.sin(7.0), 0.2])  # continuous joint: (cos, sin) in Pinocchio
    dq = np.array([0.7, -0.4])
    t = arm.terms([7.0, 0.2], dq)
    _close(t.H, _sym(pin.crba(model, data, q_pin)), "H continuous+prismatic")
    _close(t.h, pin.rnea(model, data, q_pin, dq, np.zeros(2)), "h continuous+prismatic")


_RP_URDF = """<?xml version="1.0"?>
<robot name="rp">
  <link name="base"/>
  <link name="l1"><inertial><origin xyz="0.1 0 0.02" rpy="0.1 0.2 0.3"/><mass value="2"/>
    <inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0.001" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><origin xyz="0.05 0.01 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="prismatic"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.5" effort="50" velocity="1"/></joint>
  <joint name="jt" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0.1 0 0"/></joint>
</robot>
"""


@pytest.mark.parametrize("mutate, field", [
    (lambda s: s, "tip_link"),
    (lambda s: s.replace('type="continuous"', 'type="floating"'), "joint 'j1'.type"),
    (lambda s: s.replace('<link name="l2"><inertial><origin xyz="0.05 0.01 0"/><mass value="1"/>\n    '
                         '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>',
                         '<link name="l2"/>'), "link 'l2'.inertial"),
])
def test_bad_urdf_names_the_field(tmp_path, mutate, field):
    urdf = tmp_path / "rp.urdf"
    urdf.write_text(mutate(_RP_URDF))
    tip = "nope" if field == "tip_link" else "tip"
    with pytest.raises(ParameterError) as err:
        from_urdf(urdf, "base", tip)
    assert err.value.parameter == field


def test_missing_urdf_file(tmp_path):
    with pytest.raises(ParameterError) as err:
        from_urdf(tmp_path / "missing.urdf", "base", "tip")
    assert err.value.parameter == "urdf"


def test_dynamics_damping_and_friction_enter_h(tmp_path):
    """``<dynamics damping friction>``: ``h`` gains ``damping dq + friction tanh(dq / v_s)``."""
    from plants.arms.urdf import COULOMB_SMOOTHING

    plain = tmp_path / "plain.urdf"
    plain.write_text(_RP_URDF)
    rough = tmp_path / "rough.urdf"
    rough.write_text(_RP_URDF.replace('<axis xyz="0 0 1"/></joint>', '<axis xyz="0 0 1"/><dynamics damping="0.2" friction="0.5"/></joint>'))
    q, dq = np.array([0.4, 0.1]), np.array([0.003, -0.2])
    h0 = from_urdf(plain, "base", "tip").bias(q, dq)
    h1 = from_urdf(rough, "base", "tip").bias(q, dq)
    expected = h0 + np.array([0.2 * dq[0] + 0.5 * np.tanh(dq[0] / COULOMB_SMOOTHING), 0.0])
    assert np.allclose(h1, expected, rtol=0.0, atol=1e-12)


def test_motor_inertia_adds_to_the_diagonal():
    q = np.zeros(6)
    J_m = np.array([0.1, 0.2, 0.3, 0.01, 0.02, 0.03])
    assert np.allclose(ur5e(motor_inertia=J_m).inertia(q) - ur5e().inertia(q), np.diag(J_m), atol=1e-12)


_GENERAL_AXES_URDF = """<?xml version="1.0"?>
<robot name="axes">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.05 0.02 0.1" rpy="0.3 -0.2 0.1"/><mass value="1.5"/>
    <inertia ixx="0.02" iyy="0.025" izz="0.015" ixy="0.001" ixz="-0.002" iyz="0.0005"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.1 0 0.03"/><mass value="0.8"/>
    <inertia ixx="0.004" iyy="0.006" izz="0.007" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><origin xyz="0 0.04 0.05" rpy="0 0.4 0"/><mass value="0.6"/>
    <inertia ixx="0.003" iyy="0.002" izz="0.0025" ixy="0" ixz="0.0002" iyz="0"/></inertial></link>
  <link name="d"><inertial><origin xyz="0.02 0 0.06"/><mass value="0.4"/>
    <inertia ixx="0.001" iyy="0.0012" izz="0.0008" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"/>
  <joint name="r_skew" type="revolute"><parent link="base"/><child link="a"/><origin xyz="0 0 0.2" rpy="0.1 0.2 0.3"/>
    <axis xyz="0.3 0.5 0.81"/><limit lower="-3" upper="3" effort="80" velocity="1"/></joint>
  <joint name="p_skew" type="prismatic"><parent link="a"/><child link="b"/><origin xyz="0.2 0.05 0.1" rpy="-0.4 0 0.2"/>
    <axis xyz="0 1 1"/><limit lower="-0.3" upper="0.3" effort="200" velocity="1"/></joint>
  <joint name="r_x" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0.15 0 0" rpy="0 0.5 0"/>
    <axis xyz="1 0 0"/><limit lower="-3" upper="3" effort="40" velocity="1"/></joint>
  <joint name="r_y" type="revolute"><parent link="c"/><child link="d"/><origin xyz="0 0.1 0.1"/>
    <axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="40" velocity="1"/></joint>
  <joint name="t" type="fixed"><parent link="d"/><child link="tip"/><origin xyz="0.05 0.02 0.12" rpy="0.2 0.1 -0.3"/></joint>
</robot>
"""


def test_general_axes_and_prismatic_against_pinocchio(tmp_path):
    """Skewed revolute axis (Rodrigues path), skewed prismatic axis, x and -y axes."""
    urdf = tmp_path / "axes.urdf"
    urdf.write_text(_GENERAL_AXES_URDF)
    arm = from_urdf(urdf, "base", "tip")
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    fid = model.getFrameId("tip")
    rng = np.random.default_rng(23)
    for _ in range(5):
        q = rng.uniform([-2.0, -0.3, -2.0, -2.0], [2.0, 0.3, 2.0, 2.0])
        dq = rng.uniform(-1.5, 1.5, 4)
        t = arm.terms(q, dq)
        _close(t.H, _sym(pin.crba(model, data, q)), "H")
        _close(t.h, pin.rnea(model, data, q, dq, np.zeros(4)), "h")
        Y, J, Jdq = _pin_pose_terms(model, data, fid, q, dq)
        _close(t.Y[:3], Y[:3], "tip position")
        _close(t.J, J, "J")
        _close(t.Jdq, Jdq, "dJ dq")


def test_jacobians_against_finite_differences(tmp_path):
    """``J = dY/dq`` and ``dJ dq = d(J dq)/dt`` by central differences (step 1e-6: truncation
    ~1e-12, rounding ~1e-10 relative; tolerance 1e-6 relative)."""
    urdf = tmp_path / "axes.urdf"
    urdf.write_text(_GENERAL_AXES_URDF)
    arm = from_urdf(urdf, "base", "tip")
    rng = np.random.default_rng(29)
    q = rng.uniform([-1.0, -0.2, -1.0, -1.0], [1.0, 0.2, 1.0, 1.0])
    dq = rng.uniform(-1.0, 1.0, 4)
    eps = 1e-6
    J_fd = np.column_stack([(arm.pose(q + eps * e) - arm.pose(q - eps * e)) / (2 * eps) for e in np.eye(4)])
    assert np.linalg.norm(arm.jacobian(q) - J_fd) <= 1e-6 * np.linalg.norm(J_fd)
    Jdq_fd = (arm.jacobian(q + eps * dq) - arm.jacobian(q - eps * dq)) @ dq / (2 * eps)
    assert np.linalg.norm(arm.jacobian_dot_qd(q, dq) - Jdq_fd) <= 1e-6 * np.linalg.norm(Jdq_fd)
