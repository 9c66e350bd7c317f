"""The elastic system (docs/model.md s.3): forces are exact gradients, the invariances of 4.7,
inertia and the immobile stiffness matrix, parameter validation, and conservation of momentum
by the free system (an independent check of the gyroscopic terms)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from _scenes import scene
from plants.elastic import ElasticSystem, Interconnection, Node
from plants.errors import EulerSingularityError, ParameterError
from plants.frames import body_rate_map, euler_zyx_from_rotation, rotation_planar, rotation_zyx

SPACES = ["spatial", "planar"]
ELEMENTS = ["central", "offset"]
MS = [2, 3]
SEEDS = [0, 1, 2]

# Central differences of Pi with step h = 1e-6 (m, rad): truncation ~ h^2 |Pi'''| ~ 1e-12
# |F| / (length scale 0.1 m)^2 ~ 1e-10 relative, rounding ~ eps |Pi| / h ~ 1e-9 relative to
# |F| (|Pi| ~ 10 J, |F| ~ 100 N). 1e-6 (the required bound) leaves a 1000x margin and catches
# any missing term (e.g. the derivative of beta is O(1) relative).
FD_STEP = 1e-6
FD_RTOL = 1e-6
# Invariances are exact in real arithmetic; the only error is rounding (~1e-15 relative per
# operation on O(1) positions): 1e-10 relative.
INV_RTOL = 1e-10


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300)


def elastic(space, m, element="offset", **kw):
    plant, _ = scene(space, m, arms="contact", element=element, **kw)
    return plant.elastic


def deformed(es, rng, dr=0.02, da=0.05):
    """Reference poses with every node perturbed by ~2 cm and ~0.05 rad."""
    Y = es.Y_ref.copy()
    npos = 3 if es.space == "spatial" else 2
    Y[:, :npos] += rng.normal(0.0, dr, Y[:, :npos].shape)
    Y[:, npos:] += rng.normal(0.0, da, Y[:, npos:].shape)
    return Y.reshape(-1)


def fd_gradient(f, x, h=FD_STEP):
    g = np.empty_like(x)
    for k in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[k] += h
        xm[k] -= h
        g[k] = (f(xp) - f(xm)) / (2 * h)
    return g


# ---------------------------------------------------------------------- gradients
CASES = [(s, e, m) for s in SPACES for e in ELEMENTS for m in MS]


@pytest.mark.parametrize("space,element,m", CASES)
@pytest.mark.parametrize("node_springs", [False, True])
def test_elastic_force_is_gradient_of_potential(space, element, m, node_springs):
    es = elastic(space, m, element, node_springs=node_springs)
    rng = np.random.default_rng(m * 10 + node_springs)
    for _ in range(3):
        Y = deformed(es, rng)
        F = es.elastic_force(Y)
        assert np.linalg.norm(F) > 1.0  # really deformed
        assert rel(F, fd_gradient(es.elastic_potential, Y)) <= FD_RTOL


@pytest.mark.parametrize("space", SPACES)
def test_central_spring_with_explicit_rest_length_and_anisotropic_stiffness(space):
    """beta = (1 - l/|d|)^2 with l != reference distance and per-axis c: the derivative of beta
    is what the book's pi_a(Y) Y misses (120-121)."""
    p = 6 if space == "spatial" else 3
    inertia = (0.02, 0.025, 0.03) if space == "spatial" else (0.02,)
    nodes = [Node(2.0, inertia, name="object"), Node(0.3, inertia, name="nodes[1]"), Node(0.3, inertia, name="nodes[2]")]
    Yr = np.zeros((3, p))
    Yr[1, 0], Yr[2, 0] = -0.2, 0.2
    Yr[2, 1] = 0.05
    c = [1e4, 2e4, 3e4] if space == "spatial" else [1e4, 3e4]
    springs = [Interconnection((0, 1), c, torsion=10.0, rest_length=0.15),
               Interconnection((0, 2), c, torsion=5.0, rest_length=0.25),
               Interconnection((1, 2), 5e3, rest_length=0.0)]
    es = ElasticSystem(space, nodes, springs, Yr)
    rng = np.random.default_rng(7)
    Y = deformed(es, rng)
    F = es.elastic_force(Y)
    assert rel(F, fd_gradient(es.elastic_potential, Y)) <= FD_RTOL
    # the isotropic form: Pi = 1/2 c (|d| - l)^2 (docs/model.md s.3)
    es_iso = ElasticSystem(space, nodes, [Interconnection((0, 1), 1e4, rest_length=0.15)], Yr)
    Yp = Y.reshape(3, p)
    npos = 3 if space == "spatial" else 2
    s = np.linalg.norm(Yp[0, :npos] - Yp[1, :npos])
    assert es_iso.elastic_potential(Y) == pytest.approx(0.5 * 1e4 * (s - 0.15) ** 2, rel=1e-12)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", MS)
def test_immobile_force_is_gradient_and_equals_K_y(space, m):
    es = elastic(space, m, "central", unloaded_state="immobile", node_springs=True)
    rng = np.random.default_rng(3)
    Y = deformed(es, rng)
    F = es.elastic_force(Y)
    assert rel(F, fd_gradient(es.elastic_potential, Y)) <= FD_RTOL
    y = Y - es.Y_ref.reshape(-1)
    # the same linear map evaluated two ways: rounding only
    assert rel(F, es.stiffness_matrix() @ y) <= 1e-12
    assert es.elastic_potential(Y) == pytest.approx(0.5 * y @ es.stiffness_matrix() @ y, rel=1e-12)





@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("shift", [0.4, np.pi - 0.015])
def test_immobile_common_angle_shift_is_a_zero_mode(space, shift):
    """K's zero modes include a common shift of every angle coordinate: Pi and F unchanged."""
    es = elastic(space, 2, "central", unloaded_state="immobile")
    npos = 3 if space == "spatial" else 2
    Y = es.Y_ref.copy()
    Y[:, npos:] += np.array([0.03, -0.02, 0.01])[:, None]
    Ys = Y.copy()
    Ys[:, npos:] += shift  # node 0 ends beyond pi from its reference, nodes 1, 2 do not
    assert es.elastic_potential(Ys) == pytest.approx(es.elastic_potential(Y), rel=INV_RTOL)
    assert rel(es.elastic_force(Ys), es.elastic_force(Y)) <= INV_RTOL


DAMPING_FORMS = ["frame_invariant", "book"]


@pytest.mark.parametrize("space,element,m", CASES)
@pytest.mark.parametrize("damping_form", DAMPING_FORMS)
def test_damping_force_is_gradient_of_dissipation(space, element, m, damping_form):
    es = elastic(space, m, element, damping=30.0, torsion_damping=0.5, node_springs=True, damping_form=damping_form)
    rng = np.random.default_rng(m)
    for _ in range(3):
        Y = deformed(es, rng)
        dY = rng.normal(0.0, 0.5, Y.size)
        Fd = es.damping_force(Y, dY)
        assert np.linalg.norm(Fd) > 0.1
        assert es.dissipation(Y, dY) >= 0.0
        # D is quadratic in dY: central differences are exact up to rounding
        assert rel(Fd, fd_gradient(lambda v: es.dissipation(Y, v), dY)) <= FD_RTOL
        # Rayleigh: dY . dD/ddY = 2 D
        assert dY @ Fd == pytest.approx(2.0 * es.dissipation(Y, dY), rel=1e-12)


def rigid_velocities(es, Y, rng):
    """Node rates of a rigid motion of the whole state ``Y``: a common translation velocity ``v`` and a
    common angular velocity ``omega`` (world frame) about the origin; the Euler rates give each node the
    same ``omega`` (``L(A_k) dA_k = R_k^T omega``)."""
    Y = Y.reshape(es.node_count, es.p)
    dY = np.empty_like(Y)
    if es.space == "spatial":
        v, omega = rng.normal(0.0, 0.5, 3), rng.normal(0.0, 0.3, 3)
        for k in range(es.node_count):
            dY[k, :3] = v + np.cross(omega, Y[k, :3])
            dY[k, 3:] = np.linalg.solve(body_rate_map(Y[k, 3:]), rotation_zyx(Y[k, 3:]).T @ omega)
    else:
        v, omega = rng.normal(0.0, 0.5, 2), rng.normal(0.0, 0.3)
        for k in range(es.node_count):
            x, z = Y[k, :2]
            dY[k, :2] = v + omega * np.array([-z, x])  # omega about the plane's normal, +x towards +z
            dY[k, 2] = omega
    return dY.reshape(-1)


@pytest.mark.parametrize("space,element,m", CASES)
def test_frame_invariant_dampers_do_no_work_under_rigid_motion(space, element, m):
    """docs/model.md s.3 [ours]: zero dissipation and zero damping force for any rigid translation plus
    rotation of a deformed (loaded) state, to rounding; the book's form does dissipate under a spin."""
    es = elastic(space, m, element, damping=60.0, torsion_damping=0.5, node_springs=True)
    rng = np.random.default_rng(40 + m)
    for _ in range(3):
        Y = deformed(es, rng)
        dY = rigid_velocities(es, Y, rng)
        # rounding: |F| ~ d |v| ~ 60 * 0.5 = 30 N, computed with ~1e-16 relative error per operation
        assert es.dissipation(Y, dY) <= 1e-24 * (60.0 * np.abs(dY).max() ** 2 + 1.0)
        assert np.abs(es.damping_force(Y, dY)).max() <= 1e-11 * (60.0 * np.abs(dY).max() + 1.0)
        # a deformation rate is still damped
        assert es.dissipation(Y, rng.normal(0.0, 0.5, Y.size)) > 1e-3
    if space == "spatial" or element == "offset":  # the book's form damps a rigid spin (the finding)
        book = elastic(space, m, element, damping=60.0, torsion_damping=0.5, node_springs=True, damping_form="book")
        Y = deformed(book, rng)
        assert book.dissipation(Y, rigid_velocities(book, Y, rng)) > 1e-4


@pytest.mark.parametrize("space", SPACES)
def test_immobile_damping(space):
    es = elastic(space, 3, "central", damping=30.0, torsion_damping=0.5, unloaded_state="immobile")
    rng = np.random.default_rng(5)
    Y, dY = deformed(es, rng), rng.normal(size=es.size)
    D = es.damping_matrix()
    np.testing.assert_allclose(D, D.T, atol=0)
    assert np.linalg.eigvalsh(D).min() >= -1e-12 * np.abs(D).max()
    assert rel(es.damping_force(Y, dY), fd_gradient(lambda v: es.dissipation(Y, v), dY)) <= FD_RTOL


# ---------------------------------------------------------------------- invariances (4.7)
@pytest.mark.parametrize("space,element,m", CASES)
def test_translation_invariance(space, element, m):
    es = elastic(space, m, element, node_springs=True)
    rng = np.random.default_rng(11)
    npos = 3 if space == "spatial" else 2
    Y = deformed(es, rng).reshape(es.node_count, es.p)
    Pi, F = es.elastic_potential(Y), es.elastic_force(Y)
    eta = rng.normal(0.0, 0.5, npos)
    Ys = Y.copy()
    Ys[:, :npos] += eta
    assert es.elastic_potential(Ys) == pytest.approx(Pi, rel=INV_RTOL)  # (132)
    assert rel(es.elastic_force(Ys), F) <= INV_RTOL  # (137)
    if element == "central":
        # the central element only sees Euler-angle differences: a common shift is free too
        Ya = Y.copy()
        Ya[:, npos:] += rng.normal(0.0, 0.3, es.p - npos)
        assert es.elastic_potential(Ya) == pytest.approx(Pi, rel=INV_RTOL)
        assert rel(es.elastic_force(Ya), F) <= INV_RTOL


def rigid_motion(es, Y, rng):
    """Positions r -> Q r + t, orientations R_i -> Q R_i (Euler angles re-extracted)."""
    Y = Y.reshape(es.node_count, es.p)
    out = Y.copy()
    if es.space == "spatial":
        Q = Rotation.from_euler("ZYX", rng.uniform(-0.6, 0.6, 3)).as_matrix()
        t = rng.normal(0.0, 0.5, 3)
        for k in range(es.node_count):
            out[k, :3] = Q @ Y[k, :3] + t
            out[k, 3:] = euler_zyx_from_rotation(Q @ rotation_zyx(Y[k, 3:]))
            assert abs(np.cos(out[k, 4])) > 0.2
    else:
        a = rng.uniform(-1.0, 1.0)
        t = rng.normal(0.0, 0.5, 2)
        Q = rotation_planar(a)
        for k in range(es.node_count):
            out[k, :2] = Q @ Y[k, :2] + t
            out[k, 2] = Y[k, 2] + a
    return out.reshape(-1)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", MS)
def test_rotation_invariance_central_distance_terms(space, m):
    """(138-150): a rigid motion keeps distances, so the isotropic central springs keep their
    energy (torsion on Euler differences is not rotation invariant in space: dropped)."""
    es = elastic(space, m, "central", torsion=0.0, node_springs=True)
    rng = np.random.default_rng(20 + m)
    for _ in range(3):
        Y = deformed(es, rng)
        Pi = es.elastic_potential(Y)
        assert Pi > 1e-2
        assert es.elastic_potential(rigid_motion(es, Y, rng)) == pytest.approx(Pi, rel=INV_RTOL)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", MS)
def test_rotation_invariance_offset_element(space, m):
    """The offset element (ours) keeps its whole energy, translational and orientation parts."""
    es = elastic(space, m, "offset", torsion=200.0)
    rng = np.random.default_rng(30 + m)
    for _ in range(3):
        Y = deformed(es, rng)
        Pi = es.elastic_potential(Y)
        assert Pi > 1e-2
        assert es.elastic_potential(rigid_motion(es, Y, rng)) == pytest.approx(Pi, rel=INV_RTOL)
    # the orientation part alone (no translational stiffness) is invariant too
    es_rot = elastic(space, m, "offset", stiffness=0.0, torsion=200.0)
    Y = deformed(es_rot, rng)
    Pi = es_rot.elastic_potential(Y)
    assert Pi > 1e-3
    assert es_rot.elastic_potential(rigid_motion(es_rot, Y, rng)) == pytest.approx(Pi, rel=INV_RTOL)


def _angle_hessian(es, node):
    """Hessian of Pi w.r.t. the angles of ``node`` at the reference, by FD of the exact force
    (step 1e-6: truncation ~1e-12, rounding ~1e-10 relative)."""
    Y0 = es.Y_ref.reshape(-1).copy()
    npos = 3 if es.space == "spatial" else 2
    ks = [node * es.p + npos + a for a in range(es.p - npos)]
    Hs = np.empty((len(ks), len(ks)))
    for c, k in enumerate(ks):
        e = np.zeros_like(Y0)
        e[k] = 1e-6
        Hs[:, c] = (es.elastic_force(Y0 + e)[ks] - es.elastic_force(Y0 - e)[ks]) / 2e-6
    return Hs


TORSION_CASES = [
    ("spatial", 200.0),
    ("spatial", [150.0, 200.0, 150.0]),
    ("planar", 200.0),
    ("spatial", [150.0, 200.0, 250.0]),
]


@pytest.mark.parametrize("space,torsion", TORSION_CASES)
def test_offset_element_small_angle_torsion_stiffness(space, torsion):
    """Near the reference (theta = phi = 0 for the contact nodes of the scene) the offset
    element's orientation spring must have stiffness cA per Euler axis, like the central
    element and the immobile K of 4.5 (its linearization, docs/model.md s.3)."""
    es = elastic(space, 2, "offset", stiffness=0.0, torsion=torsion)
    es_c = elastic(space, 2, "central", stiffness=0.0, torsion=torsion)
    expected = np.diag(np.atleast_1d(torsion) * np.ones(es.p // 2 if space == "spatial" else 1))
    K = elastic(space, 2, "central", stiffness=0.0, torsion=torsion, unloaded_state="immobile").stiffness_matrix()
    npos = 3 if space == "spatial" else 2
    Kb = K[es.p + npos:2 * es.p, es.p + npos:2 * es.p]
    np.testing.assert_allclose(Kb, expected, atol=1e-12)
    np.testing.assert_allclose(_angle_hessian(es_c, 1), expected, atol=1e-6 * np.max(expected))
    # 1e-6 of the largest stiffness: FD rounding (~1e-10) with a wide margin
    np.testing.assert_allclose(_angle_hessian(es, 1), expected, atol=1e-6 * np.max(expected))


# ---------------------------------------------------------------------- inertia and K
@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", MS)
def test_inertia_symmetric_positive_definite(space, m):
    es = elastic(space, m)
    rng = np.random.default_rng(40)
    for _ in range(5):
        Y = deformed(es, rng, dr=0.3, da=0.6)
        W = es.inertia(Y)
        np.testing.assert_allclose(W, W.T, rtol=0, atol=1e-15)
        ev = np.linalg.eigvalsh(W)
        assert ev.min() > 0.0
        # the kinetic energy of the rotation blocks is 1/2 omega^T I omega (105)
        if space == "spatial":
            Yk = Y.reshape(-1, 6)
            for k in range(es.node_count):
                dA = rng.normal(size=3)
                w = body_rate_map(Yk[k, 3:]) @ dA
                Wr = W[6 * k + 3:6 * k + 6, 6 * k + 3:6 * k + 6]
                assert dA @ Wr @ dA == pytest.approx(w @ (es.node_params[k, 1:] * w), rel=1e-12)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", MS)
@pytest.mark.parametrize("node_springs", [False, True])
def test_immobile_stiffness_rank(space, m, node_springs):
    es = elastic(space, m, "central", unloaded_state="immobile", node_springs=node_springs)
    K = es.stiffness_matrix()
    np.testing.assert_allclose(K, K.T, rtol=0, atol=0)
    ev = np.linalg.eigvalsh(K)
    top = ev.max()
    p = es.p
    # eigvalsh of an exactly singular Laplacian: zeros come out at ~eps * top; the smallest
    # nonzero eigenvalue here is >= ~torsion/4 / stiffness ~ 1e-3 top: threshold 1e-9 top
    zero = np.abs(ev) <= 1e-9 * top
    assert zero.sum() == p
    assert ev.min() >= -1e-9 * top
    assert np.linalg.matrix_rank(K, tol=1e-9 * top) == p * m
    # the zero modes are the common translations of every coordinate
    for a in range(p):
        v = np.zeros(es.size)
        v[a::p] = 1.0
        assert np.linalg.norm(K @ v) <= 1e-12 * top


# ---------------------------------------------------------------------- validation
def _msg(excinfo):
    return str(excinfo.value)


@pytest.mark.parametrize("mass,needle", [(-1.0, "nodes[1].mass"), (0.0, "nodes[1].mass"), (np.inf, "nodes[1].mass"),
                                         (np.nan, "nodes[1].mass")])
def test_bad_node_mass(mass, needle):
    with pytest.raises(ParameterError) as e:
        Node(mass, (1e-3, 1e-3, 1e-3), name="nodes[1]")
    assert needle in _msg(e)
    assert e.value.parameter == needle


@pytest.mark.parametrize("inertia", [(0.0, 1e-3, 1e-3), (1e-3, -1e-3, 1e-3), (1e-3, 1e-3, 3e-3), (5.0, 1.0, 1.0),
                                     (np.nan, 1.0, 1.0), (0.0,), (-1.0,)])
def test_bad_node_inertia(inertia):
    with pytest.raises(ParameterError) as e:
        Node(1.0, inertia, name="nodes[2]")
    assert "nodes[2].inertia" in _msg(e)


@pytest.mark.parametrize("field,value", [("stiffness", np.nan), ("stiffness", -1.0), ("torsion", np.inf),
                                         ("damping", -2.0), ("damping", np.nan), ("torsion_damping", np.inf),
                                         ("rest_length", -0.1)])
def test_bad_interconnection_values(field, value):
    kw = {"stiffness": 1e3, field: value}
    with pytest.raises(ParameterError) as e:
        Interconnection((0, 1), name="springs[0]", **kw)
    assert f"springs[0].{field}" in _msg(e)


def _three_nodes(space="spatial"):
    inertia = (1e-3, 1e-3, 1e-3) if space == "spatial" else (1e-3,)
    p = 6 if space == "spatial" else 3
    nodes = [Node(1.0, inertia, name=f"nodes[{k}]") for k in range(3)]
    Yr = np.zeros((3, p))
    Yr[1, 0], Yr[2, 0] = -0.1, 0.1
    return nodes, Yr


@pytest.mark.parametrize("space", SPACES)
def test_central_spring_between_coincident_reference_nodes(space):
    nodes, Yr = _three_nodes(space)
    Yr[2, :] = Yr[0, :]  # node 2 on top of the object
    springs = [Interconnection((0, 1), 1e3), Interconnection((0, 2), 1e3, rest_length=0.05, name="springs[1]")]
    with pytest.raises(ParameterError) as e:
        ElasticSystem(space, nodes, springs, Yr)
    assert "springs[1].pair" in _msg(e)
    # rest length 0 there is fine (a zero-length spring)
    ElasticSystem(space, nodes, [springs[0], Interconnection((0, 2), 1e3, rest_length=0.0)], Yr)


def test_pair_out_of_range_and_duplicate():
    nodes, Yr = _three_nodes()
    with pytest.raises(ParameterError) as e:
        ElasticSystem("spatial", nodes, [Interconnection((0, 3), 1e3, name="springs[0]")], Yr)
    assert "springs[0].pair" in _msg(e)
    with pytest.raises(ParameterError) as e:
        ElasticSystem("spatial", nodes, [Interconnection((0, 1), 1e3, name="springs[0]"),
                                         Interconnection((1, 0), 1e3, name="springs[1]")], Yr)
    assert "springs[1].pair" in _msg(e)
    with pytest.raises(ParameterError) as e:
        Interconnection((1, 1), 1e3, name="springs[4]")
    assert "springs[4].pair" in _msg(e)


def test_offset_torsion_triangle_and_planar_inertia_count():
    nodes, Yr = _three_nodes()
    with pytest.raises(ParameterError) as e:
        ElasticSystem("spatial", nodes, [Interconnection((0, 1), 1e3, torsion=[1.0, 1.0, 5.0], element="offset",
                                                         name="springs[0]")], Yr)
    assert "springs[0].torsion" in _msg(e)
    with pytest.raises(ParameterError) as e:
        ElasticSystem("planar", nodes, [Interconnection((0, 1), 1e3)], Yr[:, :3])
    assert "nodes[0].inertia" in _msg(e)


def test_nonfinite_reference_and_singular_reference():
    nodes, Yr = _three_nodes()
    Yr[1, 2] = np.nan
    with pytest.raises(ParameterError) as e:
        ElasticSystem("spatial", nodes, [Interconnection((0, 1), 1e3)], Yr)
    assert "reference_poses" in _msg(e)
    nodes, Yr = _three_nodes()
    Yr[0, 4] = np.pi / 2
    with pytest.raises(EulerSingularityError):
        ElasticSystem("spatial", nodes, [Interconnection((0, 1), 1e3)], Yr)


# ---------------------------------------------------------------------- free system momentum
def momenta(es, x):
    n = es.size
    Y, dY = x[:n].reshape(es.node_count, es.p), x[n:].reshape(es.node_count, es.p)
    mass = es.node_params[:, 0]
    if es.space == "spatial":
        P = (mass[:, None] * dY[:, :3]).sum(0)
        Lw = np.zeros(3)
        for k in range(es.node_count):
            omega = body_rate_map(Y[k, 3:]) @ dY[k, 3:]
            Lw += mass[k] * np.cross(Y[k, :3], dY[k, :3]) + rotation_zyx(Y[k, 3:]) @ (es.node_params[k, 1:] * omega)
        return P, Lw
    P = (mass[:, None] * dY[:, :2]).sum(0)
    Ly = np.sum(mass * (Y[:, 0] * dY[:, 1] - Y[:, 1] * dY[:, 0]) + es.node_params[:, 1] * dY[:, 2])
    return P, np.array([Ly])


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("element", ELEMENTS)
@pytest.mark.parametrize("m", MS)
def test_free_system_conserves_momentum(space, element, m):
    """gravity off, F = 0: linear and angular momentum (world frame, about the origin) are
    invariants. Spatial central springs with Euler-difference torsion are not rotation invariant,
    so those scenes drop torsion (the nodes then spin freely: pure gyroscopic terms)."""
    torsion = 0.0 if (element == "central" and space == "spatial") else 20.0
    es = elastic(space, m, element, stiffness=2e3, torsion=torsion, gravity=0.0, node_springs=True)
    rng = np.random.default_rng(50 + m)
    Y = deformed(es, rng)
    dY = rng.normal(0.0, 0.3, es.size)
    x0 = np.concatenate([Y, dY])
    F = np.zeros(es.size)
    T = 0.4
    sol = solve_ivp(lambda t, x: es.rhs(t, x, F), (0.0, T), x0, method="DOP853", rtol=1e-11, atol=1e-11)
    assert sol.success
    P0, L0 = momenta(es, x0)
    # scale: the sum of the magnitudes of the contributions, so that a near-zero total does
    # not make the test vacuous or impossible
    mass = es.node_params[:, 0]
    n = es.size
    scale_P = np.sum(mass * np.linalg.norm(dY.reshape(es.node_count, es.p)[:, :(3 if space == "spatial" else 2)], axis=1))
    scale_L = scale_P * np.abs(Y).max() + np.abs(dY).max() * es.node_params[:, 1:].max()
    for i in range(0, sol.y.shape[1], max(1, sol.y.shape[1] // 20)):
        P, L = momenta(es, sol.y[:, i])
        # DOP853 at rtol = atol = 1e-11: the states are accurate to ~1e-9 relative over the
        # run, so the momenta to ~1e-9 of their scale; 1e-7 leaves margin, while a missing or
        # wrong gyroscopic term breaks angular momentum at O(1e-2) of its scale
        assert np.linalg.norm(P - P0) <= 1e-7 * scale_P
        assert np.linalg.norm(L - L0) <= 1e-7 * scale_L
    P, L = momenta(es, sol.y[:, -1])
    assert np.linalg.norm(P - P0) <= 1e-7 * scale_P
    assert np.linalg.norm(L - L0) <= 1e-7 * scale_L
    # the run did something: the nodes vibrated
    assert np.abs(sol.y[n:, -1] - dY).max() > 1e-2


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("element", ELEMENTS)
def test_damped_free_system_conserves_momentum_and_loses_energy_monotonically(space, element):
    """Frame-invariant dampers are internal forces that do no work under rigid motion: with gravity off
    and F = 0 they keep the linear and angular momentum; the energy T + Pi decays monotonically, at the
    rate dE/dt = -2 D of the Rayleigh function."""
    torsion = 0.0 if (element == "central" and space == "spatial") else 20.0
    es = elastic(space, 2, element, stiffness=2e3, torsion=torsion, gravity=0.0, node_springs=True,
                 damping=15.0, torsion_damping=0.05)
    rng = np.random.default_rng(70)
    Y = deformed(es, rng)
    dY = rng.normal(0.0, 0.3, es.size) + rigid_velocities(es, Y, rng)  # vibrating and spinning
    x0 = np.concatenate([Y, dY])
    F = np.zeros(es.size)
    n = es.size
    sol = solve_ivp(lambda t, x: es.rhs(t, x, F), (0.0, 0.4), x0, method="DOP853", rtol=1e-11, atol=1e-11,
                    dense_output=True)
    assert sol.success
    t = np.linspace(0.0, 0.4, 401)
    X = sol.sol(t)
    E = np.array([es.energy(x[:n], x[n:]) for x in X.T])
    D = np.array([es.dissipation(x[:n], x[n:]) for x in X.T])
    # DOP853 at 1e-11: E is accurate to ~1e-9 of its size; a step of 1 ms loses 2 D dt, here
    # >= 1e-6 of E while the vibration lasts, so "no rise beyond 1e-8 E0" is a strict monotonicity test
    assert np.all(np.diff(E) <= 1e-8 * E[0])
    assert E[-1] < 0.9 * E[0]  # the dampers did dissipate
    # power balance: dE/dt = -2 D (trapezoid over 1 ms steps: O(dt^2) ~ 1e-4 relative)
    lost = E[0] - E[-1]
    assert lost == pytest.approx(np.trapezoid(2.0 * D, t), rel=1e-3)
    P0, L0 = momenta(es, x0)
    P, L = momenta(es, X[:, -1])
    mass = es.node_params[:, 0]
    npos = 3 if space == "spatial" else 2
    scale_P = np.sum(mass * np.linalg.norm(dY.reshape(es.node_count, es.p)[:, :npos], axis=1))
    scale_L = scale_P * np.abs(Y).max() + np.abs(dY).max() * es.node_params[:, 1:].max()
    # as in test_free_system_conserves_momentum: 1e-7 of the scale is ~100x the integration error
    assert np.linalg.norm(P - P0) <= 1e-7 * scale_P
    assert np.linalg.norm(L - L0) <= 1e-7 * scale_L


def test_damping_form_is_validated():
    with pytest.raises(ParameterError, match=r"springs\[0\]\.damping_form = 'rayleigh' is invalid"):
        Interconnection((0, 1), 1e3, damping_form="rayleigh", name="springs[0]")
