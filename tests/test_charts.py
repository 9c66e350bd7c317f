"""Rotation charts (plants.charts, docs/model.md s.2): a node's ZYX angles taken about a constant rotation.
Re-centring keeps the rotation and the angular velocity, the book's coordinates are recovered from any
chart (and refused where they do not exist), the elastic system gives the same physical motion in any
chart, and a passive object turns through pitch 90 deg with its energy conserved."""

from __future__ import annotations

import numpy as np
import pytest

from _passive import integrate_passive, pitch_about_y
from plants.charts import chart_array, recentre, world_coordinates
from plants.elastic import ElasticSystem, Interconnection, Node
from plants.errors import EulerSingularityError, ParameterError
from plants.frames import body_rate_map, euler_zyx_from_rotation, rotation_zyx

# Rounding only (a few products of rotations): 1e-12 relative.
EXACT_RTOL = 1e-12


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.linalg.norm(a - b) / max(np.linalg.norm(b), 1e-300)


def Ry(beta):
    return rotation_zyx(np.array([0.0, beta, 0.0]))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_recentre_keeps_the_rotation_and_the_angular_velocity(seed):
    rng = np.random.default_rng(seed)
    C, A, dA = rotation_zyx(rng.uniform(-3, 3, 3)), rng.uniform(-1.2, 1.2, 3), rng.normal(size=3)
    Cn, An, dAn = recentre(C, A, dA)
    assert np.array_equal(An, np.zeros(3))
    assert rel(Cn, C @ rotation_zyx(A)) <= EXACT_RTOL
    assert rel(body_rate_map(An) @ dAn, body_rate_map(A) @ dA) <= EXACT_RTOL


@pytest.mark.parametrize("seed", [0, 1])
def test_world_coordinates_match_a_differentiated_motion(seed):
    """A world motion ``A_w(t) = A_w + t dA_w + t^2/2 ddA_w`` seen in a chart ``C`` (its angles by
    ``euler(C^T R(A_w(t)))``, rates by central differences) maps back to ``(A_w, dA_w, ddA_w)``."""
    rng = np.random.default_rng(seed)
    Aw, dAw, ddAw = rng.uniform(-1.0, 1.0, 3), rng.normal(size=3), rng.normal(size=3)
    C = rotation_zyx(rng.uniform(-2.0, 2.0, 3))

    def chart_angles(t):
        return euler_zyx_from_rotation(np.ascontiguousarray(C.T @ rotation_zyx(Aw + t * dAw + 0.5 * t * t * ddAw)))

    h = 1e-4
    A, Ap, Am = chart_angles(0.0), chart_angles(h), chart_angles(-h)
    assert abs(np.cos(A[1])) > 0.2  # the chart's angles are regular here
    dA, ddA = (Ap - Am) / (2 * h), (Ap - 2 * A + Am) / h**2
    A_back, dA_back, ddA_back = world_coordinates(C, A, dA, ddA)
    assert rel(A_back, Aw) <= EXACT_RTOL
    # central differences: truncation ~h^2 = 1e-8, rounding of the second difference ~eps/h^2 ~ 1e-8
    assert rel(dA_back, dAw) <= 1e-6
    assert rel(ddA_back, ddAw) <= 1e-6


def test_world_coordinates_refuse_the_singular_pitch():
    with pytest.raises(EulerSingularityError, match="object"):
        world_coordinates(Ry(np.pi / 2), np.zeros(3), np.ones(3), np.zeros(3), "object")
    # the identity chart is the book's: its coordinates come back as given
    A = np.array([0.1, 0.2, 0.3])
    assert np.array_equal(world_coordinates(np.eye(3), A, A, A)[0], A)


def test_chart_array_is_validated():
    with pytest.raises(ParameterError, match=r"charts\[1\] = .*a rotation matrix \(orthonormal, det \+1\)"):
        chart_array("charts", [np.eye(3), 2.0 * np.eye(3)], 2)
    with pytest.raises(ParameterError, match=r"charts = \(3, 3\) is invalid: expected 2 rotation matrices"):
        chart_array("charts", np.eye(3), 2)
    with pytest.raises(ParameterError, match=r"charts\[0\].*det \+1"):
        chart_array("charts", [np.diag([1.0, 1.0, -1.0]), np.eye(3)], 2)


# ---------------------------------------------------------------------- the elastic system in charts
OBJECT = Node(2.0, (0.02, 0.03, 0.025), name="object")  # y the axis of largest inertia: a stable spin
CONTACT = Node(0.3, (1e-3, 1.2e-3, 1.4e-3), name="contact")
Y_REF = np.array([[0.0, 0.0, 0.5, 0.0, 0.0, 0.0], [0.15, 0.0, 0.5, 0.0, 0.0, 0.0]])


def object_and_contact(torsion=0.01, damping=0.0, torsion_damping=0.0, gravity=0.0, rotation_form="geodesic"):
    spring = Interconnection((0, 1), stiffness=500.0, torsion=torsion, damping=damping,
                             torsion_damping=torsion_damping, rotation_form=rotation_form)
    return ElasticSystem("spatial", [OBJECT, CONTACT], [spring], Y_REF, gravity=gravity)


def test_the_same_state_in_two_charts_gives_the_same_book_coordinates():
    es = object_and_contact(torsion=[3.0, 4.0, 5.0], damping=3.0, torsion_damping=0.2, gravity=9.81)
    rng = np.random.default_rng(4)
    x = np.r_[(Y_REF + rng.normal(0.0, 0.3, Y_REF.shape)).reshape(-1), rng.normal(size=12)]
    dx = es.rhs(0.0, x, np.zeros(12))
    book = es.book_coordinates(x, dx)
    # the same physical state in random charts C: angles of C^T R, the same body angular velocity
    C = np.stack([rotation_zyx(rng.uniform(-3, 3, 3)) for _ in range(2)])
    xc = x.copy()
    for k in range(2):
        A = euler_zyx_from_rotation(np.ascontiguousarray(C[k].T @ rotation_zyx(x[6 * k + 3:6 * k + 6])))
        xc[6 * k + 3:6 * k + 6] = A
        xc[12 + 6 * k + 3:12 + 6 * k + 6] = np.linalg.solve(body_rate_map(A), body_rate_map(x[6 * k + 3:6 * k + 6])
                                                            @ x[12 + 6 * k + 3:12 + 6 * k + 6])
    recentred, xr = es.recentred(x)
    assert recentred.charted and np.array_equal(xr[:12].reshape(2, 6)[:, 3:], np.zeros((2, 3)))
    for es2, x2 in ((recentred, xr), (es.with_charts(C), xc)):
        assert es2.energy(x2[:12], x2[12:]) == pytest.approx(es.energy(x[:12], x[12:]), rel=EXACT_RTOL)
        for a, b in zip(es2.book_coordinates(x2, es2.rhs(0.0, x2, np.zeros(12))), book):
            assert rel(a, b) <= EXACT_RTOL


def test_a_passive_object_turns_through_pitch_90_deg_with_its_energy_conserved():
    """No damping, no gravity, no input: the object spins about y from pitch 60 deg through 90 deg
    (its charts re-centred between segments), held back by a soft geodesic torsion spring to a free
    contact node. The book's world chart stops at the same state (the old singularity)."""
    es = object_and_contact()
    Y = Y_REF.copy()
    Y[0, 3:] = (0.0, np.radians(60.0), 0.0)
    dY = np.zeros_like(Y)
    dY[0, 4] = 2.0  # [rad/s] about y
    x0 = np.r_[Y.reshape(-1), dY.reshape(-1)]
    E0 = es.energy(x0[:12], x0[12:])

    def world_rotation(plant, x):
        return plant.charts[0] @ rotation_zyx(x[3:6])

    times, states, plants = integrate_passive(
        es, x0, lambda p, t, x: p.rhs(t, x, np.zeros(12)), lambda p, x: p.recentred(x),
        lambda p, x: p.chart_cos(x), 2.0, 0.02)
    E = np.array([p.energy(x[:12], x[12:]) for p, x in zip(plants, states)])
    # energy drift (see _passive: ~1e-11 expected), relative to the energy of the motion (0.07 J)
    assert np.max(np.abs(E - E0)) / abs(E0) <= 1e-8
    beta = np.degrees(np.unwrap([pitch_about_y(world_rotation(p, x)) for p, x in zip(plants, states)]))
    cos_world = [np.hypot(*world_rotation(p, x)[2, 1:]) for p, x in zip(plants, states)]
    assert beta[0] == pytest.approx(60.0) and np.max(beta) > 100.0  # through 90 deg ...
    assert min(cos_world) < 0.05  # ... where the world angles are within 3 deg of their singularity
    assert len({id(p) for p in plants}) > 3  # the object's chart was re-centred on the way
    # the book's world chart at the same physical state, pitch exactly 90 deg: no accelerations
    Yw = Y.copy()
    Yw[0, 3:] = (0.0, np.pi / 2, 0.0)
    xw = np.r_[Yw.reshape(-1), dY.reshape(-1)]
    with pytest.raises(EulerSingularityError):
        es.rhs(0.0, xw, np.zeros(12))
    es_c, xc = es.with_charts(np.stack([Ry(np.pi / 2), np.eye(3)])), xw.copy()
    xc[3:6] = 0.0
    assert np.all(np.isfinite(es_c.rhs(0.0, xc, np.zeros(12))))
    with pytest.raises(EulerSingularityError):
        es_c.book_coordinates(xc, es_c.rhs(0.0, xc, np.zeros(12)))
