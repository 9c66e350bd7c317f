"""The cooperative plant (docs/model.md s.5, 177, 183): mass matrix, an independent re-assembly of the
arm and object equations, contact points against the elastic system, static deflections
against analytic spring solutions, the immobile linearization, contact wrenches, the nominal
motion (148), the Euler singularity, size reports and the leader/follower regrouping."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq, root

from _scenes import scene
from plants.cooperative import ContactPoint, CooperativePlant, assemble_plant, nominal_node_motion, nominal_node_poses
from plants.elastic import ElasticSystem, Interconnection, Node
from plants.errors import EulerSingularityError, ParameterError
from plants.frames import body_rate_map, body_rate_map_dot, rotation_zyx

SPACES = ["spatial", "planar"]
ELEMENTS = ["central", "offset"]
MS = [2, 3]
CASES = [(s, e, m) for s in SPACES for e in ELEMENTS for m in MS]
# Two evaluations of the same equations in a different order (numba fused kernel vs. numpy
# blocks): rounding only, amplified by cond(N) (~1e4 for the Puma with heavy nodes) -> 1e-9.
ASSEMBLY_RTOL = 1e-9


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300)


def npos(space):
    return 3 if space == "spatial" else 2


def random_state(plant, x0, rng, dq=0.05, dv=0.5):
    """x0 with joints (or contact poses) and the object perturbed, and random rates."""
    x = x0.copy()
    nz, p = plant.nz, plant.p
    nq = nz - p
    x[:nq] += rng.normal(0.0, dq, nq)
    x[nq:nz - p + npos(plant.space)] += rng.normal(0.0, 0.01, npos(plant.space))
    x[nz - p + npos(plant.space):nz] += rng.normal(0.0, 0.03, p - npos(plant.space))
    x[nz:] = rng.normal(0.0, dv, nz)
    return x


def _split(plant, v):
    """Rows of an (m+1)p node vector: (m+1, p)."""
    return np.asarray(v).reshape(plant.node_count, plant.p)


# ---------------------------------------------------------------------- mass matrix
@pytest.mark.parametrize("space,element,m", CASES)
def test_mass_matrix_spd_and_blocks(space, element, m):
    plant, x0 = scene(space, m, arms="full", element=element)
    es = plant.elastic
    rng = np.random.default_rng(m)
    for _ in range(3):
        x = random_state(plant, x0, rng)
        G = plant.mass_matrix(x)
        np.testing.assert_allclose(G, G.T, rtol=0, atol=1e-14 * np.abs(G).max())
        assert np.linalg.eigvalsh(G).min() > 0.0
        Y = plant.node_poses(x)
        W = es.inertia(Y)
        p, nz = plant.p, plant.nz
        expected = np.zeros_like(G)
        for i, arm in enumerate(plant.arms):
            sl = plant.q_slice(i)
            t = arm.terms(x[sl], x[nz:][sl])
            Wi = W[(i + 1) * p:(i + 2) * p, (i + 1) * p:(i + 2) * p]
            expected[sl, sl] = t.H + t.J.T @ Wi @ t.J  # N_i = H_i + J_i^T W_i J_i
        expected[-p:, -p:] = W[:p, :p]
        np.testing.assert_allclose(G, expected, rtol=0, atol=1e-12 * np.abs(G).max())


# ---------------------------------------------------------------------- assembly (177, 183)
@pytest.mark.parametrize("space,element,m", CASES)
def test_assembly_against_arm_and_node_equations(space, element, m):
    plant, x0 = scene(space, m, arms="full", element=element, damping=20.0, torsion_damping=0.2,
                      node_springs=(m == 3))
    es = plant.elastic
    rng = np.random.default_rng(10 + m)
    p, nz = plant.p, plant.nz
    for _ in range(3):
        x = random_state(plant, x0, rng)
        tau = rng.normal(0.0, 10.0, plant.input_size)
        ddz = plant.rhs(0.0, x, tau)[nz:]
        np.testing.assert_array_equal(plant.rhs(0.0, x, tau)[:nz], x[nz:])
        Y, dY = plant.node_poses(x), plant.node_velocities(x)
        Yr, dYr = _split(plant, Y), _split(plant, dY)
        ddY = np.zeros((plant.node_count, p))
        terms = []
        for i, arm in enumerate(plant.arms):
            sl = plant.q_slice(i)
            t = arm.terms(x[sl], x[nz:][sl])
            terms.append(t)
            # kinematics (169-172) through the arm's own model
            np.testing.assert_allclose(Yr[i + 1], t.Y, atol=1e-12)
            np.testing.assert_allclose(dYr[i + 1], t.J @ x[nz:][sl], atol=1e-12)
            ddY[i + 1] = t.J @ ddz[sl] + t.Jdq
        ddY[0] = ddz[-p:]
        W, w = es.inertia(Y), es.w(Y, dY)
        Fnode = _split(plant, W @ ddY.reshape(-1) + w)  # F_i = W_i Y_i'' + w_i (113)
        for i, t in enumerate(terms):
            sl = plant.q_slice(i)
            lhs = t.H @ ddz[sl] + t.h
            rhs = tau[sl] - t.J.T @ Fnode[i + 1]  # (166), f_c = -F (168)
            scale = max(np.linalg.norm(t.H @ ddz[sl]), np.linalg.norm(t.h), np.linalg.norm(tau[sl]),
                        np.linalg.norm(t.J.T @ Fnode[i + 1]))
            assert np.linalg.norm(lhs - rhs) <= ASSEMBLY_RTOL * scale
        # object: W_0 Y_0'' + w_0 = 0 (115)
        w0 = _split(plant, w)[0]
        assert np.linalg.norm(Fnode[0]) <= ASSEMBLY_RTOL * np.linalg.norm(w0)


@pytest.mark.parametrize("space,element,m", CASES)
def test_contact_points_equal_elastic_system(space, element, m):
    """Contact points (J = I, H = h = 0): the plant is the elastic system (113) with F = tau."""
    plant, x0 = scene(space, m, arms="contact", element=element, damping=20.0, torsion_damping=0.2,
                      node_springs=True)
    es = plant.elastic
    rng = np.random.default_rng(20 + m)
    p, nz = plant.p, plant.nz
    for _ in range(3):
        x = random_state(plant, x0, rng, dq=0.02)
        tau = rng.normal(0.0, 10.0, plant.input_size)
        z, dz = x[:nz], x[nz:]
        Y = np.concatenate([z[-p:], z[:-p]])  # plant z = (Y_1..Y_m, Y_0)
        dY = np.concatenate([dz[-p:], dz[:-p]])
        F = np.concatenate([np.zeros(p), tau])
        ddY = es.accelerations(Y, dY, F)
        ddz = plant.rhs(0.0, x, tau)[nz:]
        expected = np.concatenate([ddY[p:], ddY[:p]])
        assert rel(ddz, expected) <= 1e-12  # same kernels, same order: rounding only
        np.testing.assert_allclose(plant.node_poses(x), Y, atol=0)
        # the plant's energy is the elastic system's (no arm terms)
        assert plant.energy(x) == pytest.approx(es.energy(Y, dY), rel=1e-12)


# ---------------------------------------------------------------------- static deflection
def _hanging(space, contacts, object_guess, c, l0, m0, g=9.81):
    """Contact points at fixed positions, object hanging in central springs (no torsion)."""
    p = 6 if space == "spatial" else 3
    inertia = (0.02, 0.025, 0.03) if space == "spatial" else (0.02,)
    nodes = [Node(m0, inertia, name="object")] + [Node(0.3, inertia, name=f"nodes[{k + 1}]")
                                                   for k in range(len(contacts))]
    Yr = np.zeros((len(contacts) + 1, p))
    Yr[0, :npos(space)] = object_guess
    for k, cpos in enumerate(contacts):
        Yr[k + 1, :npos(space)] = cpos
    springs = [Interconnection((0, k + 1), c, rest_length=l0) for k in range(len(contacts))]
    es = ElasticSystem(space, nodes, springs, Yr, gravity=g)
    plant = CooperativePlant(es, [ContactPoint(space) for _ in contacts])
    nz = plant.nz
    z = np.concatenate([*Yr[1:], Yr[0]])
    tau = np.zeros(plant.input_size)

    def object_acc(r):
        x = np.zeros(2 * nz)
        x[:nz] = z
        x[nz - p:nz - p + npos(space)] = r
        acc = plant.rhs(0.0, x, tau)[2 * nz - p:]
        assert np.abs(acc[npos(space):]).max() <= 1e-12  # central springs: no torque on the MC
        return acc[:npos(space)]

    sol = root(object_acc, np.asarray(object_guess, float), method="hybr", tol=1e-14)
    assert sol.success
    assert np.abs(object_acc(sol.x)).max() <= 1e-9
    return sol.x


@pytest.mark.parametrize("space", SPACES)
def test_static_deflection_two_springs(space):
    a, h, l0, c, m0, g = 0.15, 0.5, 0.1, 2e3, 2.0, 9.81
    if space == "spatial":
        contacts = [(-a, 0.0, h), (a, 0.0, h)]
        guess = (0.01, 0.005, h - 0.15)
    else:
        contacts = [(-a, h), (a, h)]
        guess = (0.01, h - 0.15)
    r = _hanging(space, contacts, guess, c, l0, m0, g)

    def balance(z):
        s = np.hypot(a, h - z)
        return 2 * c * (s - l0) * (h - z) / s - m0 * g

    z_exact = brentq(balance, h - 2.0, h - 1e-9, xtol=1e-15, rtol=1e-15)
    # both sides solved to machine precision of the force balance; the sensitivity of z to a
    # force error is 1/stiffness ~ 1e-3 m/N, so 1e-9 relative is ~1000x the rounding
    assert r[-1] == pytest.approx(z_exact, rel=1e-9)
    np.testing.assert_allclose(r[:-1], 0.0, atol=1e-12)  # symmetric: no lateral offset


@pytest.mark.parametrize("space", SPACES)
def test_static_deflection_single_vertical_spring(space):
    h, l0, c, m0, g = 0.5, 0.2, 3e3, 2.0, 9.81
    contacts = [(0.0, 0.0, h)] if space == "spatial" else [(0.0, h)]
    guess = (0.003, -0.002, h - l0) if space == "spatial" else (0.003, h - l0)
    r = _hanging(space, contacts, guess, c, l0, m0, g)
    assert h - l0 - r[-1] == pytest.approx(m0 * g / c, rel=1e-9)  # deflection m0 g / c
    np.testing.assert_allclose(r[:-1], 0.0, atol=1e-12)


# ---------------------------------------------------------------------- immobile linearization
def _immobile_linearization(space="planar"):
    plant, x0 = scene(space, 2, arms="contact", element="central", unloaded_state="immobile",
                      damping=20.0, torsion_damping=0.3)
    es = plant.elastic
    p, nz, n = plant.p, plant.nz, es.size
    K, D = es.stiffness_matrix(), es.damping_matrix()
    W = es.inertia(es.Y_ref)
    # equilibrium holding the contacts at the reference: K_00 y_0 = Q_g0, F_c = K_c0 y_0 - Q_gc
    Qg = np.zeros(n)
    for k in range(es.node_count):
        Qg[k * p:k * p + npos(space)] = es.node_params[k, 0] * es.gravity
    y = np.zeros(n)
    y[:p] = np.linalg.solve(K[:p, :p], Qg[:p])
    tau_eq = (K @ y - Qg)[p:]
    Yeq = es.Y_ref.reshape(-1) + y
    x_eq = np.zeros(2 * nz)
    x_eq[:nz] = np.concatenate([Yeq[p:], Yeq[:p]])
    assert np.abs(plant.rhs(0.0, x_eq, tau_eq)).max() <= 1e-10
    A, B = plant.jacobians(x_eq, tau_eq)
    # expected in the elastic ordering (Y_0, Y_1, Y_2), then permuted to z = (Y_1, Y_2, Y_0)
    Wi = np.linalg.inv(W)
    A_e = np.block([[np.zeros((n, n)), np.eye(n)], [-Wi @ K, -Wi @ D]])
    B_e = np.vstack([np.zeros((n, n - p)), Wi[:, p:]])
    perm = np.r_[np.arange(p, n), np.arange(p)]
    perm2 = np.r_[perm, perm + n]
    A_exp, B_exp = A_e[np.ix_(perm2, perm2)], B_e[perm2]
    # central differences of a linear map with step 1e-6 max(1, |x|): rounding only,
    # ~eps |f| / h ~ 1e-16 * 1e2 / 1e-6 = 1e-8 against entries up to K/m ~ 1e5
    np.testing.assert_allclose(A, A_exp, rtol=0, atol=1e-9 * np.abs(A_exp).max())
    np.testing.assert_allclose(B, B_exp, rtol=0, atol=1e-9 * np.abs(B_exp).max())
    # the linear plant is what rhs computes anywhere (it is linear): a random state
    rng = np.random.default_rng(3)
    dx = rng.normal(0.0, 1e-3, 2 * nz)
    du = rng.normal(0.0, 1.0, plant.input_size)
    f = plant.rhs(0.0, x_eq + dx, tau_eq + du)
    np.testing.assert_allclose(f, A @ dx + B @ du, rtol=0, atol=1e-9 * np.abs(f).max())
    return plant, x_eq, tau_eq, A, B


@pytest.mark.parametrize("space", SPACES)
def test_immobile_linearization(space):
    """Immobile unloaded state (4.5), contact points: about the gravity-balanced equilibrium the
    Jacobians are exactly A = [[0, I], [-W^-1 K, -W^-1 D]], B = [0; W^-1 E] (E: node inputs),
    W = W(Y_ref)."""
    _immobile_linearization(space)


def test_linearize_named_statespace():
    plant, x_eq, tau_eq, A, B = _immobile_linearization()
    nz = plant.nz
    sys_ = plant.linearize(x_eq, tau_eq)
    np.testing.assert_allclose(sys_.A, A, rtol=0, atol=1e-9 * np.abs(A).max())
    np.testing.assert_allclose(sys_.B, B, rtol=0, atol=1e-9 * np.abs(B).max())
    assert list(sys_.state_labels[:nz]) == ["arm1_x", "arm1_z", "arm1_theta", "arm2_x", "arm2_z", "arm2_theta",
                                           "object_x", "object_z", "object_theta"]
    assert list(sys_.state_labels[nz:]) == ["d" + s for s in sys_.state_labels[:nz]]
    assert list(sys_.input_labels) == plant.input_names()
    assert plant.input_names() == ["arm1_fx", "arm1_fz", "arm1_n", "arm2_fx", "arm2_fz", "arm2_n"]


def test_named_states_full_arms():
    plant, _ = scene("spatial", 2, arms="full")
    names = plant.state_names()
    assert names[:7] == ["arm1_q1", "arm1_q2", "arm1_q3", "arm1_q4", "arm1_q5", "arm1_q6", "arm2_q1"]
    assert names[12:18] == ["object_x", "object_y", "object_z", "object_psi", "object_theta", "object_phi"]
    assert len(names) == plant.state_size
    assert plant.input_names()[-1] == "arm2_tau6"


# ---------------------------------------------------------------------- contact wrenches
@pytest.mark.parametrize("element", ELEMENTS)
@pytest.mark.parametrize("m", MS)
def test_contact_wrenches_planar(element, m):
    plant, x0 = scene("planar", m, arms="full", element=element, damping=20.0, torsion_damping=0.2,
                      node_springs=True)
    es = plant.elastic
    rng = np.random.default_rng(60 + m)
    p, nz = plant.p, plant.nz
    x = random_state(plant, x0, rng)
    ddY0 = plant.rhs(0.0, x, np.zeros(plant.input_size))[-p:]
    Y, dY = plant.node_poses(x), plant.node_velocities(x)
    Yr = _split(plant, Y)
    wr = plant.contact_wrenches(x)
    total = np.zeros(3)
    for i in range(m):
        f, n = wr[i, :2], wr[i, 2]
        d = Yr[i + 1, :2] - Yr[0, :2]
        total += np.r_[f, n + d[0] * f[1] - d[1] * f[0]]  # G_i F_i
    m0, I0 = es.node_params[0]
    grav = np.r_[m0 * es.gravity, 0.0]
    W0ddY0 = np.r_[m0 * ddY0[:2], I0 * ddY0[2]]
    # the interconnections' generalized force on the object, from the force functions
    edge = -(es.elastic_force(Y) + es.damping_force(Y, dY))[:p]
    np.testing.assert_allclose(W0ddY0 - grav, edge, rtol=0, atol=1e-10 * np.abs(edge).max())
    np.testing.assert_allclose(total, edge, rtol=0, atol=1e-10 * np.abs(edge).max())


@pytest.mark.parametrize("element", ELEMENTS)
@pytest.mark.parametrize("m", MS)
def test_contact_wrenches_spatial(element, m):
    plant, x0 = scene("spatial", m, arms="full", element=element, damping=20.0, torsion_damping=0.2,
                      node_springs=True)
    es = plant.elastic
    rng = np.random.default_rng(70 + m)
    p = plant.p
    x = random_state(plant, x0, rng)
    ddY0 = plant.rhs(0.0, x, np.zeros(plant.input_size))[-p:]
    Yr = _split(plant, plant.node_poses(x))
    dY0 = _split(plant, plant.node_velocities(x))[0]
    wr = plant.contact_wrenches(x)
    force = wr[:, :3].sum(0)
    moment = sum(wr[i, 3:] + np.cross(Yr[i + 1, :3] - Yr[0, :3], wr[i, :3]) for i in range(m))
    m0, I0 = es.node_params[0, 0], es.node_params[0, 1:]
    # Newton: sum f = m0 r0'' - m0 g
    expected_f = m0 * ddY0[:3] - m0 * es.gravity
    np.testing.assert_allclose(force, expected_f, rtol=0, atol=1e-10 * np.abs(expected_f).max())
    # Euler (independent of the Euler-angle machinery of W): world moment about the MC
    A, dA, ddA = Yr[0, 3:], dY0[3:], ddY0[3:]
    w = body_rate_map(A) @ dA
    wd = body_rate_map(A) @ ddA + body_rate_map_dot(A, dA) @ dA
    expected_n = rotation_zyx(A) @ (I0 * wd + np.cross(w, I0 * w))
    assert np.linalg.norm(moment - expected_n) <= 1e-9 * max(np.linalg.norm(expected_n), np.abs(wr[:, 3:]).max())


# ---------------------------------------------------------------------- nominal motion (148)
@pytest.mark.parametrize("space", SPACES)
def test_nominal_node_motion_matches_finite_differences(space):
    rng = np.random.default_rng(80)
    p = 6 if space == "spatial" else 3
    m = 3
    grasps = np.column_stack([rng.uniform(-0.2, 0.2, (m, npos(space))), rng.uniform(-0.6, 0.6, (m, p - npos(space)))])
    c, a, om, ph = rng.normal(0, 0.2, p), rng.uniform(0.1, 0.5, p), rng.uniform(0.5, 2.0, p), rng.uniform(0, 6, p)

    def traj(t):
        return c + a * np.sin(om * t + ph), a * om * np.cos(om * t + ph), -a * om ** 2 * np.sin(om * t + ph)

    def wrap(v):
        v = v.copy()
        v[:, npos(space):] = (v[:, npos(space):] + np.pi) % (2 * np.pi) - np.pi
        return v

    h = 1e-5
    for t in (0.0, 0.7, 1.9):
        Y, dY, ddY = nominal_node_motion(*traj(t), grasps, space)
        np.testing.assert_allclose(Y, nominal_node_poses(traj(t)[0], grasps, space), atol=1e-14)
        fdY = wrap(nominal_node_poses(traj(t + h)[0], grasps, space) - nominal_node_poses(traj(t - h)[0], grasps, space)) / (2 * h)
        fddY = (nominal_node_motion(*traj(t + h), grasps, space)[1] - nominal_node_motion(*traj(t - h), grasps, space)[1]) / (2 * h)
        # central differences, h = 1e-5: truncation h^2 |Y'''| ~ 1e-10 x O(10), rounding
        # eps / h ~ 1e-11: 1e-7 absolute on O(1) rates
        np.testing.assert_allclose(dY, fdY, atol=1e-7)
        np.testing.assert_allclose(ddY, fddY, atol=1e-7)
        # contacts carried rigidly: distances to the object MC are the grasp offsets
        for j in range(m):
            assert np.linalg.norm(Y[j + 1, :npos(space)] - Y[0, :npos(space)]) == pytest.approx(
                np.linalg.norm(grasps[j, :npos(space)]), rel=1e-12)


# ---------------------------------------------------------------------- Euler singularity
@pytest.mark.parametrize("arms", ["contact", "full"])
def test_object_euler_singularity_raises(arms):
    plant, x0 = scene("spatial", 2, arms=arms)
    x = x0.copy()
    x[plant.nz - 2] = np.pi / 2  # object theta
    with pytest.raises(EulerSingularityError) as e:
        plant.rhs(0.0, x, np.zeros(plant.input_size))
    assert "object" in str(e.value)
    x[plant.nz - 2] = np.pi / 2 - 1e-3  # near, but regular: no error
    assert np.all(np.isfinite(plant.rhs(0.0, x, np.zeros(plant.input_size))))


def test_contact_node_euler_singularity_raises():
    plant, x0 = scene("spatial", 2, arms="contact")
    x = x0.copy()
    x[4] = -np.pi / 2  # theta of contact node 1 (arm 1 is a contact point: z starts with Y_1)
    with pytest.raises(EulerSingularityError) as e:
        plant.rhs(0.0, x, np.zeros(plant.input_size))
    assert "contact node 1" in str(e.value)


def _singular_tip_state():
    """A Puma state whose tip (node 1) has pitch theta = -pi/2: joints 4, 5 turn the node's x axis
    vertical (solved on the rotation matrix, which has no Euler singularity)."""
    plant, x0 = scene("spatial", 2, arms="full")
    arm = plant.arms[0]
    q0 = x0[:6].copy()

    def res(v):
        q = q0.copy()
        q[3:5] = v
        return arm.tip_transform(q)[0][2, 1:3]  # R21 = R22 = 0 <=> |R20| = 1

    sol = root(res, q0[3:5] + [0.3, 1.2], tol=1e-14)
    q = q0.copy()
    q[3:5] = sol.x
    assert np.abs(res(sol.x)).max() <= 1e-12
    x = x0.copy()
    x[:6] = q
    return plant, x


def test_arm_tip_euler_singularity_raises():
    plant, x = _singular_tip_state()
    with pytest.raises(EulerSingularityError) as e:
        plant.rhs(0.0, x, np.zeros(plant.input_size))
    assert "contact node 1" in str(e.value)


def test_arm_tip_euler_singularity_reports_theta():
    plant, x = _singular_tip_state()
    with pytest.raises(EulerSingularityError) as e:
        plant.rhs(0.0, x, np.zeros(plant.input_size))
    assert abs(abs(e.value.theta) - np.pi / 2) <= 1e-9


def test_coincident_nodes_at_runtime_raise():
    """beta = (1 - l/|d|)^2 is undefined at |d| = 0: a clear ParameterError, not nan."""
    plant, x0 = scene("planar", 2, arms="contact", element="central")
    x = x0.copy()
    x[0:2] = x[plant.nz - 3:plant.nz - 1]  # node 1 on the object's MC
    with pytest.raises(ParameterError):
        plant.rhs(0.0, x, np.zeros(plant.input_size))
    with pytest.raises(ParameterError):
        plant.elastic.elastic_force(plant.node_poses(x))


def test_singular_reference_pose_raises():
    obj = Node(2.0, (0.02, 0.025, 0.03), name="object")
    nodes = [Node(0.3, (1e-3, 1.2e-3, 1.4e-3)) for _ in range(2)]
    springs = [Interconnection((0, k + 1), 1e4) for k in range(2)]
    pose = np.array([0.0, 0.0, 0.5, 0.0, np.pi / 2, 0.0])
    with pytest.raises(EulerSingularityError):
        assemble_plant("spatial", obj, pose, [ContactPoint(), ContactPoint()],
                       np.array([[0.15, 0, 0, 0, 0, 0], [-0.15, 0, 0, np.pi, 0, 0]]), nodes, springs)
    Yr = np.zeros((3, 6))
    Yr[1, 0], Yr[2, 0] = 0.15, -0.15
    Yr[0, 4] = np.pi / 2
    with pytest.raises(EulerSingularityError):
        ElasticSystem("spatial", [obj, *nodes], springs, Yr)


# ---------------------------------------------------------------------- sizes and regrouping
def test_size_report():
    sp, _ = scene("spatial", 2, arms="full")
    pl, _ = scene("planar", 2, arms="full")
    cp, _ = scene("spatial", 2, arms="contact")
    r_sp, r_pl, r_cp = sp.size_report(), pl.size_report(), cp.size_report()
    assert r_pl["state_size"] < r_sp["state_size"]
    assert r_sp["state_size"] == 2 * (6 + 6 + 6) and r_pl["state_size"] == 2 * (3 + 3 + 3)
    assert r_sp["arm_models"] == ["SerialArm", "SerialArm"]
    assert r_pl["arm_models"] == ["PlanarArm", "PlanarArm"]
    assert r_cp["arm_models"] == ["ContactPoint", "ContactPoint"]
    assert r_sp["dof_per_arm"] == [6, 6] and r_sp["input_size"] == 12
    assert r_sp["torsion_springs"] == 2 * 3 and r_pl["torsion_springs"] == 2
    assert scene("spatial", 3, arms="contact", torsion=0.0)[0].size_report()["torsion_springs"] == 0
    assert scene("planar", 3, arms="contact", torsion=0.0)[0].size_report()["torsion_springs"] == 0
    r3 = scene("spatial", 3, arms="contact", node_springs=True)[0].size_report()
    assert r3["interconnections"] == 3 + 2 and r3["node_count"] == 4


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("leader", [0, 2])
def test_leader_follower(space, leader):
    base, x0 = scene(space, 3, arms="full")
    plant = CooperativePlant(base.elastic, base.arms, leader=leader)
    x = random_state(plant, x0, np.random.default_rng(90))
    lf = plant.leader_follower(x)
    Y, dY = _split(plant, plant.node_poses(x)), _split(plant, plant.node_velocities(x))
    sl = plant.q_slice(leader)
    np.testing.assert_array_equal(lf["q_v"], x[sl])
    np.testing.assert_array_equal(lf["dq_v"], x[plant.nz:][sl])
    followers = [i for i in range(3) if i != leader]
    np.testing.assert_array_equal(lf["Y_s"], np.concatenate([Y[i + 1] for i in followers]))
    np.testing.assert_array_equal(lf["dY_s"], np.concatenate([dY[i + 1] for i in followers]))
    np.testing.assert_array_equal(lf["Y_0"], Y[0])
    np.testing.assert_array_equal(lf["dY_0"], dY[0])
    np.testing.assert_array_equal(lf["Y_0"], x[plant.nz - plant.p:plant.nz])
    # the leader's node is Phi_v(q_v)
    np.testing.assert_allclose(plant.arms[leader].pose(lf["q_v"]), Y[leader + 1], atol=1e-12)
