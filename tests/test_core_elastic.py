"""plants/core/elastic_* (the compiled core's elastic system, plants._core): the same numbers as the numba kernels
they replace, bit for bit, for every element kind (central and offset springs in both rotation and damping forms,
matrix and beam elements; spatial and planar; mobile, immobile and charted) on seeded random node poses and rates;
the packed rows read by name (the core's structs and plants.elastic._layout name the same columns), checked by a
spring whose stiffness is changed by name and whose force changes as k dx; and the arguments checked once at the
binding."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from plants import _core
from plants.elastic import ElasticSystem, Interconnection, Node
from plants.elastic import _planar_kernels as numba_planar
from plants.elastic import _spatial_kernels as numba_spatial
from plants.elastic._layout import (CHARTED_NODE, EDGE_HEADER, PLANAR_MATRIX, PLANAR_NODE, PLANAR_SPRING,
                                    SPATIAL_MATRIX, SPATIAL_NODE, SPATIAL_SPRING, STATUS_COINCIDENT_NODES, STATUS_OK)
from plants.elastic.fem import BeamElement, planar_beam_stiffness, spatial_beam_stiffness
from plants.frames import rotation_zyx

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
        "R": (0, 9), "dR": (9, 27), "L": (9 * 4, 9), "chart": (9 * numba_spatial.FRAME_CHART, 9)}


@pytest.mark.parametrize("kind", [*SPATIAL_KINDS, "mixed"])
@pytest.mark.parametrize("seed", SEEDS)
def test_spatial_edges_match_the_numba_kernels_bit_for_bit(kind, seed):
    es = _spatial_system(kind, seed)
    ei, ep = es.edge_index, es.edge_params
    Y, dY, _ = _state(es, seed)
    F, F_ref = np.zeros_like(Y), np.zeros_like(Y)
    Pi, status = _core.spatial_elastic_edges(Y, ei, ep, F)
    Pi_ref, status_ref = numba_spatial.elastic_edges(Y, ei, ep, F_ref)
    assert (Pi, status) == (Pi_ref, status_ref) and status == STATUS_OK
    np.testing.assert_array_equal(F, F_ref)
    assert np.any(F != 0.0)
    D = _core.spatial_damping_edges(Y, dY, ei, ep, F)
    assert D == numba_spatial.damping_edges(Y, dY, ei, ep, F_ref)
    np.testing.assert_array_equal(F, F_ref)
    w, w_ref = np.zeros_like(Y), np.zeros_like(Y)
    assert _core.spatial_interconnection_terms(Y, dY, ei, ep, es.Y_ref, False, w) == STATUS_OK
    numba_spatial.interconnection_terms(Y, dY, ei, ep, es.Y_ref, False, w_ref)
    np.testing.assert_array_equal(w, w_ref)


@pytest.mark.parametrize("kind", [*SPATIAL_KINDS, "mixed"])
@pytest.mark.parametrize("seed", SEEDS)
def test_spatial_immobile_model_matches_the_numba_kernels_bit_for_bit(kind, seed):
    es = _spatial_system(kind, seed, unloaded="immobile")
    Y, dY, Fc = _state(es, seed)
    F, F_ref = np.zeros_like(Y), np.zeros_like(Y)
    Pi = _core.spatial_linear_edges(Y, dY, es.Y_ref, es.edge_index, es.edge_params, F)
    assert Pi == numba_spatial.linear_edges(Y, dY, es.Y_ref, es.edge_index, es.edge_params, F_ref)
    np.testing.assert_array_equal(F, F_ref)
    ddY = np.empty_like(Y)
    args = (es.node_rows, es.edge_index, es.edge_params, es.gravity, es.Y_ref, True)
    assert _core.spatial_elastic_accelerations(Y, dY, Fc, *args, ddY) == STATUS_OK
    ddY_ref, status = numba_spatial.elastic_accelerations(Y, dY, Fc, *args)
    assert status == STATUS_OK
    np.testing.assert_array_equal(ddY, ddY_ref)


@pytest.mark.parametrize("kind, charts", [(kind, charts) for kind in ("central geodesic", "offset geodesic", "matrix",
                                                                       "beam") for charts in (False, True)]
                         + [("mixed", False)])  # the mixed system's book forms allow no charts
@pytest.mark.parametrize("seed", SEEDS)
def test_spatial_nodes_and_accelerations_match_the_numba_kernels_bit_for_bit(kind, charts, seed):
    es = _spatial_system(kind, seed, charts=charts)
    rows = es.node_rows
    assert rows.shape[1] == (CHARTED_NODE.width if charts else 4)
    Y, dY, Fc = _state(es, seed, scale=0.3)
    frames = np.zeros((4, 6, 3, 3))
    _core.spatial_node_frames(Y, rows, frames)
    frames_ref = numba_spatial.node_frames_charted(Y, rows)
    np.testing.assert_array_equal(frames, frames_ref)
    F, F_ref = np.zeros_like(Y), np.zeros_like(Y)
    Pi, status = _core.spatial_elastic_edges(Y, es.edge_index, es.edge_params, F, frames)
    assert (Pi, status) == numba_spatial.elastic_edges_framed(Y, es.edge_index, es.edge_params, F_ref, frames_ref)
    D = _core.spatial_damping_edges(Y, dY, es.edge_index, es.edge_params, F, frames)
    assert D == numba_spatial.damping_edges_framed(Y, dY, es.edge_index, es.edge_params, F_ref, frames_ref)
    np.testing.assert_array_equal(F, F_ref)
    ddY = np.empty_like(Y)
    args = (rows, es.edge_index, es.edge_params, es.gravity, es.Y_ref, False)
    assert _core.spatial_elastic_accelerations(Y, dY, Fc, *args, ddY) == STATUS_OK
    ddY_ref, status = numba_spatial.elastic_accelerations(Y, dY, Fc, *args)
    assert status == STATUS_OK
    np.testing.assert_array_equal(ddY, ddY_ref)
    # the node terms alone, and with the frames in one pass
    Wr, w, Wr_ref, w_ref = np.empty((4, 3, 3)), np.empty((4, 6)), np.empty((4, 3, 3)), np.empty((4, 6))
    for immobile in (False, True):
        assert _core.spatial_node_terms(Y, dY, rows, es.gravity, es.Y_ref, immobile, Wr, w) == STATUS_OK
        numba_spatial.node_terms(Y, dY, rows, es.gravity, es.Y_ref, immobile, Wr_ref, w_ref)
        np.testing.assert_array_equal(Wr, Wr_ref)
        np.testing.assert_array_equal(w, w_ref)
    frames_ref = np.zeros((4, 6, 3, 3))
    _core.spatial_node_frames_terms(Y, dY, rows, es.gravity, frames, Wr, w)
    numba_spatial.node_frames_terms_into(Y, dY, rows, es.gravity, frames_ref, Wr_ref, w_ref)
    for got, want in ((frames, frames_ref), (Wr, Wr_ref), (w, w_ref)):
        np.testing.assert_array_equal(got, want)


def test_node_rotation_solve_matches_the_numba_kernel_and_refuses_the_euler_singularity():
    rng = np.random.default_rng(7)
    out, out_ref = np.empty(3), np.empty(3)
    Wr, g, Wr_ref, g_ref = np.empty((3, 3)), np.empty(3), np.empty((3, 3)), np.empty(3)
    for _ in range(50):
        Ang, dA, I, b = rng.uniform(-3, 3, 3), rng.normal(size=3), rng.uniform(0.01, 1.0, 3), rng.normal(size=3)
        assert _core.solve_node_rotation(Ang, I, b, out) == numba_spatial.solve_node_rotation(Ang, I, b, out_ref)
        np.testing.assert_array_equal(out, out_ref)
        _core.node_rotational_terms(Ang, dA, I, Wr, g)
        numba_spatial.node_rotational_terms(Ang, dA, I, Wr_ref, g_ref)
        np.testing.assert_array_equal(Wr, Wr_ref)
        np.testing.assert_array_equal(g, g_ref)
    assert not _core.solve_node_rotation(np.array([0.0, np.pi / 2, 0.0]), np.ones(3), np.ones(3), out)


@pytest.mark.parametrize("kind", PLANAR_KINDS)
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("unloaded", ["mobile", "immobile"])
def test_planar_system_matches_the_numba_kernels_bit_for_bit(kind, seed, unloaded):
    es = _planar_system(kind, seed, unloaded)
    ei, ep = es.edge_index, es.edge_params
    Y, dY, Fc = _state(es, seed, scale=0.3)
    F, F_ref = np.zeros_like(Y), np.zeros_like(Y)
    assert _core.planar_elastic_edges(Y, ei, ep, F) == numba_planar.elastic_edges(Y, ei, ep, F_ref)
    assert _core.planar_damping_edges(Y, dY, ei, ep, F) == numba_planar.damping_edges(Y, dY, ei, ep, F_ref)
    np.testing.assert_array_equal(F, F_ref)
    assert np.any(F != 0.0)
    assert (_core.planar_linear_edges(Y, dY, es.Y_ref, ei, ep, F)
            == numba_planar.linear_edges(Y, dY, es.Y_ref, ei, ep, F_ref))
    np.testing.assert_array_equal(F, F_ref)
    w, w_ref = np.zeros_like(Y), np.zeros_like(Y)
    immobile = unloaded == "immobile"
    assert _core.planar_interconnection_terms(Y, dY, ei, ep, es.Y_ref, immobile, w) == STATUS_OK
    numba_planar.interconnection_terms(Y, dY, ei, ep, es.Y_ref, immobile, w_ref)
    np.testing.assert_array_equal(w, w_ref)
    ddY = np.empty_like(Y)
    args = (es.node_rows, ei, ep, es.gravity, es.Y_ref, immobile)
    assert _core.planar_elastic_accelerations(Y, dY, Fc, *args, ddY) == STATUS_OK
    ddY_ref, status = numba_planar.elastic_accelerations(Y, dY, Fc, *args)
    assert status == STATUS_OK
    np.testing.assert_array_equal(ddY, ddY_ref)


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_coincident_central_nodes_give_the_numba_status(space):
    es = _spatial_system("central book", 0) if space == "spatial" else _planar_system("central", 0)
    Y = np.ascontiguousarray(es.Y_ref.copy())
    Y[1] = Y[0]  # nodes 0 and 1 of the first central spring coincide
    F, F_ref = np.zeros_like(Y), np.zeros_like(Y)
    core = _core.spatial_elastic_edges if space == "spatial" else _core.planar_elastic_edges
    kern = numba_spatial if space == "spatial" else numba_planar
    assert core(Y, es.edge_index, es.edge_params, F) == kern.elastic_edges(Y, es.edge_index, es.edge_params, F_ref)
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
