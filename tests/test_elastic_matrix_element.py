"""The matrix element (co-rotational) in the plant: gradient and damping force against finite
differences, rigid-motion invariance (4.7), zero damping power under rigid motion, its immobile
model equal to the mobile one's linearization and to the finite-element assembly, and energy
conservation in a passive run. Tolerances: central differences with step 1e-6 of forces of order
1e2 N leave about 1e-6 relative (truncation h^2 and rounding 1e-16/h); the invariances are exact
in exact arithmetic and hold to rounding (1e-9 relative)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from plants.elastic import ElasticSystem, Interconnection, Node
from plants.elastic.fem import planar_beam_stiffness, spatial_beam_stiffness
from plants.errors import ParameterError
from plants.frames import rotation_zyx

E, G = 70e9, 26e9
B, H = 0.02, 0.01
A, IY, IZ, J = B * H, B * H**3 / 12, H * B**3 / 12, 0.229 * B * H**3


def _euler(R):
    return Rotation.from_matrix(R).as_euler("ZYX")


def _spatial_system(damped=True, unloaded="mobile", seed=0):
    rng = np.random.default_rng(seed)
    Y_ref = np.zeros((3, 6))
    Y_ref[1, :3] = (0.3, 0.05, -0.02)
    Y_ref[2, :3] = (-0.25, 0.1, 0.04)
    Y_ref[:, 3:] = rng.uniform(-0.6, 0.6, size=(3, 3))
    springs = []
    for k, (i, j) in enumerate(((0, 1), (0, 2))):
        L = float(np.linalg.norm(Y_ref[j, :3] - Y_ref[i, :3]))
        K = spatial_beam_stiffness(E, G, A, IY, IZ, J, L)
        C = 1e-4 * K if damped else None
        springs.append(Interconnection((i, j), 0.0, element="matrix", matrix=K, matrix_damping=C, name=f"springs[{k}]"))
    nodes = [Node(2.0, (0.02, 0.03, 0.04)), Node(0.3, (1e-3, 2e-3, 1.5e-3)), Node(0.3, (1e-3, 1e-3, 2e-3))]
    return ElasticSystem("spatial", nodes, springs, Y_ref, gravity=0.0, unloaded_state=unloaded)


def _planar_system(damped=True, unloaded="mobile"):
    Y_ref = np.array([[0.0, 0.0, 0.1], [0.3, 0.05, -0.2], [-0.25, 0.02, 0.3]])
    springs = []
    for k, (i, j) in enumerate(((0, 1), (0, 2))):
        L = float(np.hypot(*(Y_ref[j, :2] - Y_ref[i, :2])))
        K = planar_beam_stiffness(E, A, IY, L)
        springs.append(Interconnection((i, j), 0.0, element="matrix", matrix=K,
                                       matrix_damping=1e-4 * K if damped else None, name=f"springs[{k}]"))
    nodes = [Node(2.0, (0.02,)), Node(0.3, (1e-3,)), Node(0.3, (1e-3,))]
    return ElasticSystem("planar", nodes, springs, Y_ref, gravity=0.0, unloaded_state=unloaded)


def _deformed(sys, scale, seed):
    rng = np.random.default_rng(seed)
    return sys.Y_ref + scale * rng.normal(size=sys.Y_ref.shape)


def _fd_gradient(f, Y, h=1e-6):
    g = np.zeros(Y.size)
    for k in range(Y.size):
        Yp, Ym = Y.reshape(-1).copy(), Y.reshape(-1).copy()
        Yp[k] += h
        Ym[k] -= h
        g[k] = (f(Yp.reshape(Y.shape)) - f(Ym.reshape(Y.shape))) / (2 * h)
    return g


@pytest.mark.parametrize("make", [_spatial_system, _planar_system])
@pytest.mark.parametrize("seed", [1, 2])
def test_elastic_force_is_the_gradient_of_the_potential(make, seed):
    sys = make()
    Y = _deformed(sys, 2e-3, seed)
    F = sys.elastic_force(Y)
    fd = _fd_gradient(sys.elastic_potential, Y)
    np.testing.assert_allclose(F, fd, rtol=0, atol=2e-6 * np.max(np.abs(F)))


@pytest.mark.parametrize("make", [_spatial_system, _planar_system])
def test_damping_force_is_the_gradient_of_the_rayleigh_function(make):
    sys = make()
    Y = _deformed(sys, 2e-3, 3)
    dY = np.random.default_rng(4).normal(size=Y.shape)
    F = sys.damping_force(Y, dY)
    fd = _fd_gradient(lambda V: sys.dissipation(Y, V), dY)
    np.testing.assert_allclose(F, fd, rtol=0, atol=2e-6 * np.max(np.abs(F)))


def _rigid_spatial(Y, R, t):
    out = Y.copy()
    for k in range(len(Y)):
        out[k, :3] = R @ Y[k, :3] + t
        out[k, 3:] = _euler(R @ rotation_zyx(Y[k, 3:]))
    return out


def test_spatial_rigid_motion_stores_no_energy_and_turns_the_forces():
    sys = _spatial_system()
    Y = _deformed(sys, 2e-3, 5)
    R = Rotation.from_rotvec([0.7, -1.1, 0.4]).as_matrix()
    t = np.array([0.3, -0.2, 1.0])
    Yr = _rigid_spatial(Y, R, t)
    assert sys.elastic_potential(Yr) == pytest.approx(sys.elastic_potential(Y), rel=1e-9)
    assert sys.elastic_potential(_rigid_spatial(sys.Y_ref, R, t)) == pytest.approx(0.0, abs=1e-12)
    # the translational forces turn with the system (4.7)
    F, Fr = sys.elastic_force(Y).reshape(-1, 6), sys.elastic_force(Yr).reshape(-1, 6)
    np.testing.assert_allclose(Fr[:, :3], F[:, :3] @ R.T, rtol=0, atol=1e-9 * np.max(np.abs(F)))


def test_planar_rigid_motion_stores_no_energy():
    sys = _planar_system()
    Y = _deformed(sys, 2e-3, 6)
    a, t = 2.3, np.array([0.4, -0.7])
    c, s = np.cos(a), np.sin(a)
    Yr = Y.copy()
    Yr[:, :2] = Y[:, :2] @ np.array([[c, -s], [s, c]]).T + t
    Yr[:, 2] += a
    assert sys.elastic_potential(Yr) == pytest.approx(sys.elastic_potential(Y), rel=1e-9)


@pytest.mark.parametrize("make", [_spatial_system, _planar_system])
def test_dampers_do_no_work_under_rigid_motion(make):
    sys = make()
    Y = _deformed(sys, 2e-3, 7)
    rng = np.random.default_rng(8)
    if sys.space == "spatial":
        # a rigid velocity: v_k = v + w x r_k, body rates of a common world spin w
        v, w = rng.normal(size=3), rng.normal(size=3)
        dY = np.zeros_like(Y)
        for k in range(len(Y)):
            dY[k, :3] = v + np.cross(w, Y[k, :3])
            Rk = rotation_zyx(Y[k, 3:])
            th, ph = Y[k, 4], Y[k, 5]
            L = np.array([[-np.sin(th), 0, 1], [np.sin(ph) * np.cos(th), np.cos(ph), 0], [np.cos(ph) * np.cos(th), -np.sin(ph), 0]])
            dY[k, 3:] = np.linalg.solve(L, Rk.T @ w)
    else:
        v, w = rng.normal(size=2), rng.normal()
        dY = np.column_stack((v[0] - w * Y[:, 1], v[1] + w * Y[:, 0], np.full(len(Y), w)))
    assert sys.dissipation(Y, dY) == pytest.approx(0.0, abs=1e-12 * float(np.sum(dY**2)))
    np.testing.assert_allclose(sys.damping_force(Y, dY), 0.0, atol=1e-9)


@pytest.mark.parametrize("make", [_spatial_system, _planar_system])
def test_immobile_model_is_the_linearization_of_the_mobile_one(make):
    mobile, immobile = make(), make(unloaded="immobile")
    K = immobile.stiffness_matrix()
    Kfd = np.column_stack([_fd_gradient(lambda Y: mobile.elastic_force(Y)[k], mobile.Y_ref, h=1e-7)
                           for k in range(K.shape[0])])
    np.testing.assert_allclose(K, Kfd, rtol=0, atol=1e-5 * np.max(np.abs(K)))
    np.testing.assert_allclose(immobile.stiffness_assembly().K, K, rtol=0, atol=1e-12 * np.max(np.abs(K)))
    Y = _deformed(immobile, 1e-4, 9)
    np.testing.assert_allclose(immobile.elastic_force(Y), K @ (Y - immobile.Y_ref).reshape(-1),
                               rtol=0, atol=1e-9 * np.max(np.abs(K)) * 1e-4)


def test_immobile_stiffness_equals_the_finite_element_assembly_at_zero_angles():
    """At zero Euler angles the plant's (r, A = (psi, theta, phi)) are the world translations and
    the small rotations (rz, ry, rx): the immobile K is the assembly's K with that permutation."""
    from plants.elastic.fem import BeamElement, stiffness_assembly

    P = np.array([[0.0, 0, 0], [0.3, 0.05, -0.02]])
    L = float(np.linalg.norm(P[1]))
    sys = ElasticSystem("spatial", [Node(1.0, (1e-2,) * 3), Node(0.3, (1e-3,) * 3)],
                        [Interconnection((0, 1), 0.0, element="matrix", matrix=spatial_beam_stiffness(E, G, A, IY, IZ, J, L))],
                        np.c_[P, np.zeros((2, 3))], gravity=0.0, unloaded_state="immobile")
    fem = stiffness_assembly([BeamElement((0, 1), E=E, G=G, A=A, Iy=IY, Iz=IZ, J=J, internal_nodes=3)], P).K
    perm = np.r_[0, 1, 2, 5, 4, 3, 6, 7, 8, 11, 10, 9]
    np.testing.assert_allclose(sys.stiffness_matrix(), fem[np.ix_(perm, perm)], rtol=0, atol=1e-9 * np.max(np.abs(fem)))


@pytest.mark.parametrize("make", [_spatial_system, _planar_system])
def test_undamped_passive_run_conserves_energy(make):
    sys = make(damped=False)
    n = sys.size
    rng = np.random.default_rng(11)
    x0 = np.r_[_deformed(sys, 1e-3, 10).reshape(-1), 0.5 * rng.normal(size=n)]
    E0 = sys.energy(x0[:n], x0[n:])
    F = np.zeros(n)
    sol = solve_ivp(lambda t, x: sys.rhs(t, x, F), (0.0, 0.05), x0, method="DOP853", rtol=1e-11, atol=1e-13)
    assert sol.success
    E1 = sys.energy(sol.y[:n, -1], sol.y[n:, -1])
    # DOP853 at rtol 1e-11 over the run: drift far below 1e-8 of the energy (about 1e-11 measured)
    assert abs(E1 - E0) <= 1e-8 * abs(E0)


@pytest.mark.parametrize("bad, match", [
    (dict(matrix=np.arange(144.0).reshape(12, 12)), "symmetric"),
    (dict(matrix=-np.eye(12)), "positive semi-definite"),
    (dict(matrix=np.eye(12)), "rigid motions free"),
    (dict(matrix=None), "matrix"),
    (dict(matrix=np.eye(5)), "12x12"),
])
def test_bad_matrix_elements_are_refused_naming_the_field(bad, match):
    with pytest.raises(ParameterError, match=match) as err:
        ElasticSystem("spatial", [Node(1.0, (1e-2,) * 3), Node(0.3, (1e-3,) * 3)],
                      [Interconnection((0, 1), 0.0, element="matrix", name="springs[0]", **bad)],
                      np.array([[0.0, 0, 0, 0, 0, 0], [0.3, 0, 0, 0, 0, 0]]), gravity=0.0)
    assert "springs[0].matrix" in str(err.value)
