"""plants/core/elastic_* (the compiled core's elastic system, plants._core), for every element kind (central and
offset springs in both rotation and damping forms, matrix and beam elements; spatial and planar; mobile, immobile
and charted) on seeded random node poses and rates: the elastic forces are the gradient of the potential and the
damping forces that of the dissipation function in the rates (central differences), the interconnection terms
their sum, the accelerations the solve of ``W Y'' = F - w`` with the nodes' inertia, the node frames ``C R(A)``
with their partials and ``L(A)``, the node terms ``L^T I L``, the entry points that take frames the numbers of
those that make them; the packed rows read by name (the core's structs and plants.elastic._layout name the same
columns), checked by a spring whose stiffness is changed by name and whose force changes as k dx; and the
arguments checked once at the binding. The bit-for-bit comparison with the numba kernels these replaced went with
them: it was run when the core was ported, and the golden records (tests/golden) lock a run's numbers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from plants import _core
from plants.elastic import ElasticSystem, Interconnection, Node
from plants.elastic._layout import (CHARTED_NODE, EDGE_HEADER, PLANAR_MATRIX, PLANAR_NODE, PLANAR_SPRING,
                                    SPATIAL_MATRIX, SPATIAL_NODE, SPATIAL_SPRING, STATUS_COINCIDENT_NODES, STATUS_OK)
from plants.elastic.fem import BeamElement, planar_beam_stiffness, spatial_beam_stiffness
from plants.frames import body_rate_map, rotation_zyx, rotation_zyx_partials

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"

# an aluminium bar section (as tests/test_elastic_matrix_element.py)
E, G = 70e9, 26e9
B, H = 0.02, 0.01
A, IY, IZ, J = B * H, B * H**3 / 12, H * B**3 / 12, 0.229 * B * H**3
EDGES = ((0, 1), (0, 2), (0, 3), (1, 2))
SEEDS = range(4)
#: spatial interconnections by kind: (element, rotation form, damping form)
SPATIAL_KINDS = {
    "central book": ("central", "book", "frame_invariant"),
    "central book damping": ("central", "book", "book"),
    "central geodesic": ("central", "geodesic", "frame_invariant"),
    "offset book": ("offset", "book", "frame_invariant"),
    "offset book damping": ("offset", "book", "book"),
    "offset geodesic": ("offset", "geodesic", "frame_invariant"),
    "matrix": ("matrix", "book", "frame_invariant"),
    "beam": ("beam", "book", "frame_invariant"),
}
PLANAR_KINDS = {
    "central": ("central", "frame_invariant"),
    "offset": ("offset", "frame_invariant"),
    "offset book damping": ("offset", "book"),
    "matrix": ("matrix", "frame_invariant"),
    "beam": ("beam", "frame_invariant"),
}


def _spatial_spring(rng, pair, Y_ref, element, rotation_form, damping_form, name):
    i, j = pair
    length = float(np.linalg.norm(Y_ref[j, :3] - Y_ref[i, :3]))
    if element == "matrix":
        K = spatial_beam_stiffness(E, G, A, IY, IZ, J, length)
        return Interconnection(pair, 0.0, element="matrix", matrix=K, matrix_damping=1e-4 * K, name=name)
    if element == "beam":
        beam = BeamElement(pair, E=E, G=G, A=A, Iy=IY, Iz=IZ, J=J, internal_nodes=1)
        return Interconnection(pair, 0.0, element="beam", beam=beam, rayleigh_damping=1e-4, name=name)
    # torsion components within the sum of the other two (the offset element's kappa >= 0)
    return Interconnection(pair, stiffness=rng.uniform(1e2, 1e4, 3), torsion=rng.uniform(4.0, 6.0, 3),
                           damping=rng.uniform(1.0, 10.0), torsion_damping=rng.uniform(0.1, 1.0), element=element,
                           rotation_form=rotation_form, damping_form=damping_form,
                           rest_length=0.8 * length if element == "central" else None, name=name)


def _spatial_system(kind, seed, unloaded="mobile", charts=False):
    rng = np.random.default_rng(seed)
    Y_ref = np.zeros((4, 6))
    Y_ref[:, :3] = rng.uniform(-0.4, 0.4, (4, 3))
    Y_ref[:, 3:] = rng.uniform(-0.6, 0.6, (4, 3))
    kinds = list(SPATIAL_KINDS.values()) if kind == "mixed" else [SPATIAL_KINDS[kind]] * len(EDGES)
    springs = [_spatial_spring(rng, pair, Y_ref, *kinds[k % len(kinds)], f"springs[{k}]")
               for k, pair in enumerate(EDGES)]
    if kind == "mixed":  # one of each kind, on a longer chain of edges
        springs = [_spatial_spring(rng, (0, 1 + k % 3) if k < 3 else (1 + (k - 3) % 3, 1 + (k - 2) % 3),
                                   Y_ref, *kinds[k], f"springs[{k}]") for k in range(6)]
    nodes = [Node(rng.uniform(1.0, 3.0), tuple(rng.uniform(0.03, 0.05, 3))) for _ in range(4)]
    C = np.stack([rotation_zyx(rng.uniform(-1.0, 1.0, 3)) for _ in range(4)]) if charts else None
    return ElasticSystem("spatial", nodes, springs, Y_ref, gravity=9.81, unloaded_state=unloaded, charts=C)


def _planar_system(kind, seed, unloaded="mobile"):
    rng = np.random.default_rng(seed)
    Y_ref = np.column_stack([rng.uniform(-0.4, 0.4, (4, 2)), rng.uniform(-0.6, 0.6, 4)])
    element, damping_form = PLANAR_KINDS[kind]
    springs = []
    for k, (i, j) in enumerate(EDGES):
        length = float(np.hypot(*(Y_ref[j, :2] - Y_ref[i, :2])))
        if element == "matrix":
            K = planar_beam_stiffness(E, A, IY, length)
            springs.append(Interconnection((i, j), 0.0, element="matrix", matrix=K, matrix_damping=1e-4 * K))
        elif element == "beam":
            beam = BeamElement((i, j), E=E, G=G, A=A, Iy=IY, Iz=IZ, J=J, internal_nodes=2)
            springs.append(Interconnection((i, j), 0.0, element="beam", beam=beam, rayleigh_damping=1e-4))
        else:
            springs.append(Interconnection((i, j), stiffness=rng.uniform(1e2, 1e4, 2), torsion=rng.uniform(1.0, 10.0),
                                           damping=rng.uniform(1.0, 10.0), torsion_damping=rng.uniform(0.1, 1.0),
                                           element=element, damping_form=damping_form,
                                           rest_length=0.8 * length if element == "central" else None))
    nodes = [Node(rng.uniform(1.0, 3.0), (rng.uniform(0.01, 0.05),)) for _ in range(4)]
    return ElasticSystem("planar", nodes, springs, Y_ref, gravity=9.81, unloaded_state=unloaded)


def _state(es, seed, scale=0.1):
    rng = np.random.default_rng(1000 + seed)
    Y = np.ascontiguousarray(es.Y_ref + scale * rng.normal(size=es.Y_ref.shape))
    dY = np.ascontiguousarray(rng.normal(size=es.Y_ref.shape))
    Fc = np.ascontiguousarray(rng.normal(size=es.Y_ref.shape))
    return Y, dY, Fc


def test_the_core_structs_name_the_columns_of_the_packed_rows():
    layout = _core.elastic_layout()
    for rows in (EDGE_HEADER, SPATIAL_SPRING, SPATIAL_MATRIX, PLANAR_SPRING, PLANAR_MATRIX, SPATIAL_NODE, PLANAR_NODE,
                 CHARTED_NODE):
        assert {name: tuple(v) for name, v in layout[rows.struct].items()} == rows.fields, rows.struct
    assert SPATIAL_NODE.col("mass") == PLANAR_NODE.col("mass") and SPATIAL_NODE.col("inertia") == PLANAR_NODE.col(
        "inertia")  # the kernels' NODE_MASS and NODE_INERTIA serve both spaces
    assert {name: tuple(v) for name, v in layout["NodeFrames"].items()} == {
        "R": (0, 9), "dR": (9, 27), "L": (9 * 4, 9), "chart": (9 * 5, 9)}  # blocks R, dR (3), L, chart


#: Central differences of the potential and the dissipation: step 1e-7 [m, rad, m/s, rad/s] on springs of up to
#: ~1e9 N/m; truncation ~h^2, rounding ~eps |Pi| / h: 1e-6 of the largest force is a wide margin still well
#: below any wrong term.
FD_STEP, FD_RTOL = 1e-7, 1e-6
#: Two statements of the same sums (forces added in another order, a solve checked by its product).
SUM_RTOL = 1e-10


def _scaled(a, b, rtol):
    np.testing.assert_allclose(a, b, rtol=0.0, atol=rtol * (1.0 + np.abs(b).max()))


def _gradient(f, X):
    """Central differences of the scalar ``f`` at every entry of ``X``."""
    G = np.empty_like(X)
    for idx in np.ndindex(X.shape):
        Xp, Xm = X.copy(), X.copy()
        Xp[idx] += FD_STEP
        Xm[idx] -= FD_STEP
        G[idx] = (f(Xp) - f(Xm)) / (2 * FD_STEP)
    return G


def _assert_edges_are_gradients(elastic_edges, damping_edges, Y, dY):
    """``F = dPi/dY`` from ``elastic_edges(Y, F) -> Pi`` and ``F_d = dD/d(dY)`` from ``damping_edges(Y, dY, F) -> D``;
    returns the sum of both forces."""
    F = np.zeros_like(Y)
    elastic_edges(Y, F)
    assert np.any(F != 0.0)
    _scaled(F, _gradient(lambda Z: elastic_edges(Z, np.zeros_like(Z)), Y), FD_RTOL)
    Fd = np.zeros_like(Y)
    damping_edges(Y, dY, Fd)
    _scaled(Fd, _gradient(lambda V: damping_edges(Y, V, np.zeros_like(V)), dY), FD_RTOL)
    return F + Fd


def _assert_accelerations_solve(accelerations, es, Y, dY, Fc):
    """``W(Y) (Y''(F) - Y''(0)) = F`` on the free nodes (node 0's input is 0), ``W`` the elastic system's inertia."""
    Fc = Fc.copy()
    Fc[0] = 0.0
    ddY, ddY0 = np.empty_like(Y), np.empty_like(Y)
    assert accelerations(Y, dY, Fc, ddY) == STATUS_OK
    assert accelerations(Y, dY, np.zeros_like(Fc), ddY0) == STATUS_OK
    W = es.inertia(Y.reshape(-1))
    _scaled(W @ (ddY - ddY0).reshape(-1), Fc.reshape(-1), SUM_RTOL * max(1.0, np.abs(W).max() * np.abs(ddY).max()))


def _spatial_edges(es, framed=False):
    """The elastic and damping edges as functions of ``Y`` (and ``dY``); ``framed``: the entry points that take the
    node frames, the frames made at each ``Y`` (``spatial_node_frames``)."""
    def extra(Y):
        if not framed:
            return ()
        frames = np.zeros((Y.shape[0], 6, 3, 3))
        _core.spatial_node_frames(Y, es.node_rows, frames)
        return (frames,)

    def elastic(Y, F):
        Pi, status = _core.spatial_elastic_edges(Y, es.edge_index, es.edge_params, F, *extra(Y))
        assert status == STATUS_OK
        return Pi

    def damping(Y, dY, F):
        return _core.spatial_damping_edges(Y, dY, es.edge_index, es.edge_params, F, *extra(Y))
    return elastic, damping


@pytest.mark.parametrize("kind", [*SPATIAL_KINDS, "mixed"])
@pytest.mark.parametrize("seed", SEEDS)
def test_spatial_edges_are_the_gradients_of_the_potential_and_the_dissipation(kind, seed):
    es = _spatial_system(kind, seed)
    Y, dY, _ = _state(es, seed)
    F = _assert_edges_are_gradients(*_spatial_edges(es), Y, dY)
    w = np.zeros_like(Y)
    assert _core.spatial_interconnection_terms(Y, dY, es.edge_index, es.edge_params, es.Y_ref, False, w) == STATUS_OK
    _scaled(w, F, SUM_RTOL)


@pytest.mark.parametrize("kind", [*SPATIAL_KINDS, "mixed"])
@pytest.mark.parametrize("seed", SEEDS)
def test_spatial_immobile_model_is_linear_and_its_accelerations_solve_with_the_inertia(kind, seed):
    es = _spatial_system(kind, seed, unloaded="immobile")
    Y, dY, Fc = _state(es, seed)

    def linear(Y_, dY_):
        F = np.zeros_like(Y_)
        return _core.spatial_linear_edges(Y_, dY_, es.Y_ref, es.edge_index, es.edge_params, F), F

    Pi, F_rest = linear(Y, np.zeros_like(dY))
    _scaled(F_rest, _gradient(lambda Z: linear(Z, np.zeros_like(dY))[0], Y), FD_RTOL)
    _, F1 = linear(Y, dY)
    _, F2 = linear(Y, 2.0 * dY)
    _scaled(F2 - F_rest, 2.0 * (F1 - F_rest), SUM_RTOL)  # the damping, linear in the rates
    args = (es.node_rows, es.edge_index, es.edge_params, es.gravity, es.Y_ref, True)
    _assert_accelerations_solve(lambda Y_, dY_, F_, out: _core.spatial_elastic_accelerations(Y_, dY_, F_, *args, out),
                                es, Y, dY, Fc)


@pytest.mark.parametrize("kind, charts", [(kind, charts) for kind in ("central geodesic", "offset geodesic", "matrix",
                                                                       "beam") for charts in (False, True)]
                         + [("mixed", False)])  # the mixed system's book forms allow no charts
@pytest.mark.parametrize("seed", SEEDS)
def test_spatial_nodes_frames_and_accelerations(kind, charts, seed):
    es = _spatial_system(kind, seed, charts=charts)
    rows = es.node_rows
    assert rows.shape[1] == (CHARTED_NODE.width if charts else 4)
    Y, dY, Fc = _state(es, seed, scale=0.3)
    frames = np.zeros((4, 6, 3, 3))
    _core.spatial_node_frames(Y, rows, frames)
    for k in range(4):
        C, A = (frames[k, 5], Y[k, 3:]) if charts else (np.eye(3), Y[k, 3:])  # no chart: the world's
        _scaled(C @ C.T, np.eye(3), SUM_RTOL)
        _scaled(frames[k, 0], C @ rotation_zyx(A), SUM_RTOL)
        for i, dR in enumerate(rotation_zyx_partials(A)):
            _scaled(frames[k, 1 + i], C @ dR, SUM_RTOL)
        _scaled(frames[k, 4], body_rate_map(A), SUM_RTOL)
    F = _assert_edges_are_gradients(*_spatial_edges(es, framed=True), Y, dY)
    if not charts:  # the entry points without frames make the world's
        _scaled(F, _assert_edges_are_gradients(*_spatial_edges(es), Y, dY), SUM_RTOL)
    args = (rows, es.edge_index, es.edge_params, es.gravity, es.Y_ref, False)
    if not charts:  # es.inertia reads the angles in the world chart
        _assert_accelerations_solve(lambda Y_, dY_, F_, out: _core.spatial_elastic_accelerations(Y_, dY_, F_, *args,
                                                                                                   out), es, Y, dY, Fc)
    # the node terms alone, and with the frames in one pass
    Wr, w, Wr2, w2, frames2 = (np.empty((4, 3, 3)), np.empty((4, 6)), np.empty((4, 3, 3)), np.empty((4, 6)),
                               np.zeros((4, 6, 3, 3)))
    for immobile in (False, True):
        assert _core.spatial_node_terms(Y, dY, rows, es.gravity, es.Y_ref, immobile, Wr, w) == STATUS_OK
    _core.spatial_node_terms(Y, dY, rows, es.gravity, es.Y_ref, False, Wr, w)
    _core.spatial_node_frames_terms(Y, dY, rows, es.gravity, frames2, Wr2, w2)
    for got, want in ((frames2, frames), (Wr2, Wr), (w2, w)):
        np.testing.assert_array_equal(got, want)
    for k in range(4):
        L = body_rate_map(Y[k, 3:])
        _scaled(Wr[k], L.T @ np.diag(rows[k, 1:4]) @ L, SUM_RTOL)


def test_node_rotation_solve_is_the_rotational_inertias_and_refuses_the_euler_singularity():
    """``solve_node_rotation`` solves ``W_r x = b`` with ``W_r = L^T I L`` (``node_rotational_terms``), and its
    gyroscopic term is ``L^T (I dL dA + omega x I omega)``, ``omega = L dA`` (the body rates' Euler equations)."""
    from plants.frames import body_rate_map_dot

    rng = np.random.default_rng(7)
    out = np.empty(3)
    Wr, g = np.empty((3, 3)), np.empty(3)
    for _ in range(50):
        Ang, dA, I, b = rng.uniform(-1.4, 1.4, 3), rng.normal(size=3), rng.uniform(0.01, 1.0, 3), rng.normal(size=3)
        assert _core.solve_node_rotation(Ang, I, b, out)
        _core.node_rotational_terms(Ang, dA, I, Wr, g)
        L = body_rate_map(Ang)
        _scaled(Wr, L.T @ np.diag(I) @ L, SUM_RTOL)
        _scaled(Wr @ out, b, 1e-9)  # cond(W_r) <= ~(max I / min I) / cos(1.4)^2
        omega = L @ dA
        _scaled(g, L.T @ (np.diag(I) @ body_rate_map_dot(Ang, dA) @ dA + np.cross(omega, I * omega)), SUM_RTOL)
    assert not _core.solve_node_rotation(np.array([0.0, np.pi / 2, 0.0]), np.ones(3), np.ones(3), out)


@pytest.mark.parametrize("kind", PLANAR_KINDS)
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("unloaded", ["mobile", "immobile"])
def test_planar_system_forces_are_gradients_and_its_accelerations_solve_with_the_inertia(kind, seed, unloaded):
    es = _planar_system(kind, seed, unloaded)
    ei, ep = es.edge_index, es.edge_params
    Y, dY, Fc = _state(es, seed, scale=0.3)

    def elastic(Y_, F):
        Pi, status = _core.planar_elastic_edges(Y_, ei, ep, F)
        assert status == STATUS_OK
        return Pi

    F = _assert_edges_are_gradients(elastic, lambda Y_, dY_, F_: _core.planar_damping_edges(Y_, dY_, ei, ep, F_),
                                    Y, dY)
    immobile = unloaded == "immobile"
    F_lin = np.zeros_like(Y)
    _core.planar_linear_edges(Y, np.zeros_like(dY), es.Y_ref, ei, ep, F_lin)
    _scaled(F_lin, _gradient(lambda Z: _core.planar_linear_edges(Z, np.zeros_like(dY), es.Y_ref, ei, ep,
                                                                 np.zeros_like(Z)), Y), FD_RTOL)
    w = np.zeros_like(Y)
    assert _core.planar_interconnection_terms(Y, dY, ei, ep, es.Y_ref, immobile, w) == STATUS_OK
    if not immobile:
        _scaled(w, F, SUM_RTOL)
    args = (es.node_rows, ei, ep, es.gravity, es.Y_ref, immobile)
    _assert_accelerations_solve(lambda Y_, dY_, F_, out: _core.planar_elastic_accelerations(Y_, dY_, F_, *args, out),
                                es, Y, dY, Fc)


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_coincident_central_nodes_give_their_status(space):
    es = _spatial_system("central book", 0) if space == "spatial" else _planar_system("central", 0)
    Y = np.ascontiguousarray(es.Y_ref.copy())
    Y[1] = Y[0]  # nodes 0 and 1 of the first central spring coincide
    F = np.zeros_like(Y)
    core = _core.spatial_elastic_edges if space == "spatial" else _core.planar_elastic_edges
    assert core(Y, es.edge_index, es.edge_params, F)[1] == STATUS_COINCIDENT_NODES


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("element", ["offset", "central"])
def test_a_springs_stiffness_changed_by_name_changes_its_force_as_k_dx(space, element):
    """One spring between two nodes at the world chart's zero angles, node 1 displaced by dx along x from its
    rest pose. The offset spring's elongation is e = dx (node i's frame is the world's): the force on node 1 is
    c_x dx. The central spring with rest length 0 (beta = 1) pulls with c_x (x_1 - x_0). Writing c_x by name into
    the model's packed row changes the force to the new k dx; equal to rounding of r_j - r_i - rho (1e-12
    relative)."""
    p = 6 if space == "spatial" else 3
    Y_ref = np.zeros((2, p))
    Y_ref[1, 0], Y_ref[1, 1] = 0.3, 0.1
    nodes = [Node(2.0, (0.1, 0.1, 0.1) if p == 6 else (0.1,)), Node(1.0, (0.01, 0.01, 0.01) if p == 6 else (0.01,))]
    spring = Interconnection((0, 1), stiffness=500.0, element=element,
                             rest_length=0.0 if element == "central" else None, name="springs[0]")
    es = ElasticSystem(space, nodes, [spring], Y_ref, gravity=0.0)
    rows = SPATIAL_SPRING if space == "spatial" else PLANAR_SPRING
    dx = 0.01
    Y = Y_ref.copy()
    Y[1, 0] += dx
    stretch = dx if element == "offset" else Y[1, 0] - Y[0, 0]
    for k in (500.0, 2000.0, 7.5):
        es.edge_params[0, rows["stiffness"]] = k  # the model, by name
        F = es.elastic_force(Y).reshape(2, p)
        np.testing.assert_allclose(F[1, 0], k * stretch, rtol=1e-12)
        np.testing.assert_allclose(F[0, 0], -k * stretch, rtol=1e-12)


def test_the_carry_scenes_spring_stiffness_changed_by_name_changes_its_force_as_k_dx():
    """The shipped two-Puma carry's elastic system: its spring named "springs[1]" (an offset element, object to
    contact node 2) stretched by dx along the object's x axis from the unloaded poses. Its elongation in the
    object's frame is (dx, 0, 0), so the force on node 2 is c_x dx along that axis; writing c_x by name into
    the model's packed row changes it to the new k dx. The other spring stays at rest (its force is rounding
    of r_j - r_i - rho, about 1e-16 of k |rho|): equal to 1e-9 relative."""
    import coopctrl
    from coopctrl.scenario.build import build_plant

    es = build_plant(coopctrl.load_scenario(SCENARIOS / "spatial_two_puma_carry.toml")).elastic
    e = next(k for k, ic in enumerate(es.interconnections) if ic.name == "springs[1]")
    assert es.interconnections[e].element == "offset"
    i, j = es.interconnections[e].pair
    axis = rotation_zyx(es.Y_ref[i, 3:6])[:, 0]  # node i's x axis in the world
    dx = 1e-3
    Y = es.Y_ref.copy()
    Y[j, :3] += dx * axis
    for k in (2e4, 5e4, 3e3):
        stiffness = es.edge_params[e, SPATIAL_SPRING["stiffness"]]
        stiffness[0] = k  # the model's c_x, by name (a view of the packed row)
        F = es.elastic_force(Y).reshape(-1, 6)
        np.testing.assert_allclose(F[j, :3], k * dx * axis, rtol=1e-9, atol=1e-9 * k * dx)


def test_the_binding_refuses_wrong_shapes_naming_the_argument():
    es = _spatial_system("offset book", 0)
    Y, dY, _ = _state(es, 0)
    F = np.zeros_like(Y)
    with pytest.raises(ValueError, match=r"^edge_params: expected shape \(4, 381\)"):
        _core.spatial_elastic_edges(Y, es.edge_index, es.edge_params[:, :27].copy(), F)
    with pytest.raises(ValueError, match="^edge_index: expected two different node indices in 0..3 in row 0"):
        bad = es.edge_index.copy()
        bad[0, 1] = 9
        _core.spatial_elastic_edges(Y, bad, es.edge_params, F)
    with pytest.raises(ValueError, match=r"^F: expected shape \(4, 6\), got \(4, 3\)"):
        _core.spatial_elastic_edges(Y, es.edge_index, es.edge_params, np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"^frames: expected shape \(4, 6, 3, 3\)"):
        _core.spatial_elastic_edges(Y, es.edge_index, es.edge_params, F, np.zeros((4, 5, 3, 3)))
    with pytest.raises(TypeError):  # an output array is never converted (a copy would lose the writes)
        _core.spatial_elastic_edges(Y, es.edge_index, es.edge_params, np.zeros((4, 6), dtype=np.float32))
