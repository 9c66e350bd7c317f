// The elastic system's kernels in plants._core (plants/core/elastic_*.h): each function checks the shapes of its
// arrays and the edges' node indices and kinds once, reads the numpy rows as the model's structs in place, and
// calls the core. Output arrays are written in place (never converted: a copy would lose the writes).
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nanobind/stl/optional.h>

#include "plants/core/binding_checks.h"
#include "plants/core/elastic_model.h"
#include "plants/core/elastic_nodes.h"
#include "plants/core/elastic_planar.h"
#include "plants/core/elastic_spatial.h"

namespace plants::binding {

namespace {

using Index = nb::ndarray<const std::int64_t, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Blocks = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using Frames = nb::ndarray<double, nb::ndim<4>, nb::c_contig, nb::device::cpu>;
using FramesIn = nb::ndarray<const double, nb::ndim<4>, nb::c_contig, nb::device::cpu>;

constexpr size_t EDGE_HEADER_WIDTH = sizeof(ElasticEdge) / sizeof(std::int64_t);

// The checks below build their messages only when they fail: a call costs no allocation when its arguments are
// right.

/// expect_length, the message built only on failure.
inline void check_length(size_t got, size_t want, const char* name) {
    if (got != want) expect_length(got, want, name);
}

/// n objects of T for one call: on the stack up to a small system's size, else on the heap.
template <class T, size_t SMALL = 16>
class Scratch {
  public:
    explicit Scratch(size_t n) : heap_(n > SMALL ? n : 0) {}
    T* data() noexcept { return heap_.empty() ? small_ : heap_.data(); }

  private:
    T small_[SMALL];
    std::vector<T> heap_;
};

/// The interconnections of N nodes with p coordinates each, checked: (E, 4) headers, (E, width) rows, node indices
/// in 0..N-1 and two different, kinds and damping forms known.
Interconnections interconnections(const Index& edge_index, const Matrix& edge_params, size_t N, int width) {
    const size_t E = edge_index.shape(0);
    if (edge_index.shape(1) != EDGE_HEADER_WIDTH)
        expect(false, "edge_index", "4 columns (i, j, element kind, damping form)");
    if (edge_params.shape(0) != E || edge_params.shape(1) != static_cast<size_t>(width))
        expect(false, "edge_params",
               "shape (" + std::to_string(E) + ", " + std::to_string(width) + ") (one row per edge_index row)");
    const ElasticEdge* edges = reinterpret_cast<const ElasticEdge*>(edge_index.data());
    for (size_t e = 0; e < E; ++e) {
        const ElasticEdge& h = edges[e];
        if (!(h.i >= 0 && h.j >= 0 && static_cast<size_t>(h.i) < N && static_cast<size_t>(h.j) < N && h.i != h.j))
            expect(false, "edge_index",
                   "two different node indices in 0.." + std::to_string(N - 1) + " in row " + std::to_string(e));
        if (!(h.kind == ELEMENT_CENTRAL || h.kind == ELEMENT_OFFSET || h.kind == ELEMENT_MATRIX))
            expect(false, "edge_index", "an element kind 0 (central), 1 (offset) or 2 (matrix) in row " + std::to_string(e));
        if (!(h.damping_form == DAMPING_FRAME_INVARIANT || h.damping_form == DAMPING_BOOK))
            expect(false, "edge_index", "a damping form 0 (frame invariant) or 1 (book) in row " + std::to_string(e));
    }
    return Interconnections{static_cast<int>(E), edges, edge_params.data(), width};
}

void expect_poses(size_t rows, size_t cols, size_t N, size_t p, const char* name) {
    if (rows == N && cols == p) return;
    expect(false, name,
           "shape (" + std::to_string(N) + ", " + std::to_string(p) + "), got (" + std::to_string(rows) + ", " +
               std::to_string(cols) + ")");
}

template <class A>
void expect_same_poses(const A& a, const Matrix& Y, const char* name) {
    expect_poses(a.shape(0), a.shape(1), Y.shape(0), Y.shape(1), name);
}

template <class A>
void expect_frames(const A& frames, size_t N) {
    if (frames.shape(0) == N && frames.shape(1) == NODE_FRAME_BLOCKS && frames.shape(2) == 3 && frames.shape(3) == 3)
        return;
    expect(false, "frames", "shape (" + std::to_string(N) + ", 6, 3, 3)");
}

void expect_node_rows(const Matrix& node_rows, size_t N, bool spatial) {
    if (node_rows.shape(0) == N &&
        (spatial ? node_rows.shape(1) == SPATIAL_NODE_WIDTH || node_rows.shape(1) == SPATIAL_NODE_WIDTH_CHARTED
                 : node_rows.shape(1) == sizeof(PlanarNode) / sizeof(double)))
        return;
    if (spatial)
        expect(node_rows.shape(0) == N && (node_rows.shape(1) == SPATIAL_NODE_WIDTH ||
                                           node_rows.shape(1) == SPATIAL_NODE_WIDTH_CHARTED),
               "node_params", "shape (" + std::to_string(N) + ", 4) (mass, I1, I2, I3) or (" + std::to_string(N) +
                                  ", 14) with charts");
    else
        expect(node_rows.shape(0) == N && node_rows.shape(1) == sizeof(PlanarNode) / sizeof(double), "node_params",
               "shape (" + std::to_string(N) + ", 2) (mass, I)");
}

/// The frames the caller gave (checked), or the book's world frames of Y into own.
const NodeFrames* frames_or_own(const std::optional<FramesIn>& frames, const Matrix& Y, Scratch<NodeFrames>& own) {
    const size_t N = Y.shape(0);
    if (frames) {
        expect_frames(*frames, N);
        return reinterpret_cast<const NodeFrames*>(frames->data());
    }
    node_frames(Y.data(), static_cast<int>(N), own.data());
    return own.data();
}

// ------------------------------------------------------------------ spatial
nb::tuple spatial_elastic_edges_(Matrix Y, Index edge_index, Matrix edge_params, MatrixOut F,
                                 std::optional<FramesIn> frames) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 6, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), SPATIAL_EDGE_WIDTH);
    expect_same_poses(F, Y, "F");
    Scratch<NodeFrames> own(frames ? 0 : Y.shape(0));
    const NodeFrames* fr = frames_or_own(frames, Y, own);
    double Pi = 0.0;
    const int status = spatial_elastic_edges(ic, Y.data(), fr, F.data(), &Pi);
    return nb::make_tuple(Pi, status);
}

double spatial_damping_edges_(Matrix Y, Matrix dY, Index edge_index, Matrix edge_params, MatrixOut F,
                              std::optional<FramesIn> frames) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 6, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), SPATIAL_EDGE_WIDTH);
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(F, Y, "F");
    Scratch<NodeFrames> own(frames ? 0 : Y.shape(0));
    const NodeFrames* fr = frames_or_own(frames, Y, own);
    return spatial_damping_edges(ic, Y.data(), dY.data(), fr, F.data());
}

double spatial_linear_edges_(Matrix Y, Matrix dY, Matrix Y_ref, Index edge_index, Matrix edge_params, MatrixOut F) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 6, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), SPATIAL_EDGE_WIDTH);
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(Y_ref, Y, "Y_ref");
    expect_same_poses(F, Y, "F");
    return spatial_linear_edges(ic, Y.data(), dY.data(), Y_ref.data(), F.data());
}

int spatial_interconnection_terms_(Matrix Y, Matrix dY, Index edge_index, Matrix edge_params, Matrix Y_ref,
                                   bool immobile, MatrixOut w) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 6, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), SPATIAL_EDGE_WIDTH);
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(Y_ref, Y, "Y_ref");
    expect_same_poses(w, Y, "w");
    Scratch<NodeFrames> frames(Y.shape(0));
    return spatial_interconnection_terms(ic, static_cast<int>(Y.shape(0)), Y.data(), dY.data(), Y_ref.data(),
                                         immobile, w.data(), frames.data());
}

void spatial_node_frames_(Matrix Y, Matrix node_params, Frames frames) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 6, "Y");
    expect_node_rows(node_params, Y.shape(0), true);
    expect_frames(frames, Y.shape(0));
    node_frames_charted(Y.data(), static_cast<int>(Y.shape(0)), node_params.data(),
                        static_cast<int>(node_params.shape(1)), reinterpret_cast<NodeFrames*>(frames.data()));
}

int spatial_node_terms_(Matrix Y, Matrix dY, Matrix node_params, Vector gravity, Matrix Y_ref, bool immobile,
                        Blocks Wr, MatrixOut w) {
    const size_t N = Y.shape(0);
    expect_poses(Y.shape(0), Y.shape(1), N, 6, "Y");
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(Y_ref, Y, "Y_ref");
    expect_node_rows(node_params, N, true);
    check_length(gravity.shape(0), 3, "gravity");
    if (!(Wr.shape(0) == N && Wr.shape(1) == 3 && Wr.shape(2) == 3))
        expect(false, "Wr", "shape (" + std::to_string(N) + ", 3, 3)");
    expect_same_poses(w, Y, "w");
    return node_terms(Y.data(), dY.data(), static_cast<int>(N), node_params.data(),
                      static_cast<int>(node_params.shape(1)), gravity.data(), Y_ref.data(), immobile, Wr.data(),
                      w.data());
}

void spatial_node_frames_terms_(Matrix Y, Matrix dY, Matrix node_params, Vector gravity, Frames frames, Blocks Wr,
                                MatrixOut w) {
    const size_t N = Y.shape(0);
    expect_poses(Y.shape(0), Y.shape(1), N, 6, "Y");
    expect_same_poses(dY, Y, "dY");
    expect_node_rows(node_params, N, true);
    check_length(gravity.shape(0), 3, "gravity");
    expect_frames(frames, N);
    if (!(Wr.shape(0) == N && Wr.shape(1) == 3 && Wr.shape(2) == 3))
        expect(false, "Wr", "shape (" + std::to_string(N) + ", 3, 3)");
    expect_same_poses(w, Y, "w");
    node_frames_terms(Y.data(), dY.data(), static_cast<int>(N), node_params.data(),
                      static_cast<int>(node_params.shape(1)), gravity.data(),
                      reinterpret_cast<NodeFrames*>(frames.data()), Wr.data(), w.data());
}

void node_rotational_terms_(Vector A, Vector dA, Vector I, MatrixOut Wr, VectorOut g) {
    check_length(A.shape(0), 3, "A");
    check_length(dA.shape(0), 3, "dA");
    check_length(I.shape(0), 3, "I");
    if (!(Wr.shape(0) == 3 && Wr.shape(1) == 3)) expect(false, "Wr", "shape (3, 3)");
    check_length(g.shape(0), 3, "g");
    node_rotational_terms(A.data(), dA.data(), I.data(), Wr.data(), g.data());
}

bool solve_node_rotation_(Vector A, Vector I, Vector b, VectorOut out) {
    check_length(A.shape(0), 3, "A");
    check_length(I.shape(0), 3, "I");
    check_length(b.shape(0), 3, "b");
    check_length(out.shape(0), 3, "out");
    return solve_node_rotation(A.data(), I.data(), b.data(), out.data());
}

int spatial_elastic_accelerations_(Matrix Y, Matrix dY, Matrix Fc, Matrix node_params, Index edge_index,
                                   Matrix edge_params, Vector gravity, Matrix Y_ref, bool immobile, MatrixOut ddY) {
    const size_t N = Y.shape(0);
    expect_poses(Y.shape(0), Y.shape(1), N, 6, "Y");
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(Fc, Y, "Fc");
    expect_same_poses(Y_ref, Y, "Y_ref");
    expect_same_poses(ddY, Y, "ddY");
    expect_node_rows(node_params, N, true);
    check_length(gravity.shape(0), 3, "gravity");
    SpatialElasticModel model{};
    model.node_count = static_cast<int>(N);
    model.node_rows = node_params.data();
    model.node_width = static_cast<int>(node_params.shape(1));
    model.interconnections = interconnections(edge_index, edge_params, N, SPATIAL_EDGE_WIDTH);
    model.gravity = gravity.data();
    model.Y_ref = Y_ref.data();
    model.immobile = immobile;
    Scratch<NodeFrames> frames(N);
    Scratch<double, 9 * 16> Wr(9 * N);
    Scratch<double, 6 * 16> w(6 * N);
    return spatial_elastic_accelerations(model, Y.data(), dY.data(), Fc.data(), ddY.data(),
                                         SpatialElasticWork{frames.data(), Wr.data(), w.data()});
}

// ------------------------------------------------------------------ planar
nb::tuple planar_elastic_edges_(Matrix Y, Index edge_index, Matrix edge_params, MatrixOut F) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 3, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), PLANAR_EDGE_WIDTH);
    expect_same_poses(F, Y, "F");
    double Pi = 0.0;
    const int status = planar_elastic_edges(ic, Y.data(), F.data(), &Pi);
    return nb::make_tuple(Pi, status);
}

double planar_damping_edges_(Matrix Y, Matrix dY, Index edge_index, Matrix edge_params, MatrixOut F) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 3, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), PLANAR_EDGE_WIDTH);
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(F, Y, "F");
    return planar_damping_edges(ic, Y.data(), dY.data(), F.data());
}

double planar_linear_edges_(Matrix Y, Matrix dY, Matrix Y_ref, Index edge_index, Matrix edge_params, MatrixOut F) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 3, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), PLANAR_EDGE_WIDTH);
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(Y_ref, Y, "Y_ref");
    expect_same_poses(F, Y, "F");
    return planar_linear_edges(ic, Y.data(), dY.data(), Y_ref.data(), F.data());
}

int planar_interconnection_terms_(Matrix Y, Matrix dY, Index edge_index, Matrix edge_params, Matrix Y_ref,
                                  bool immobile, MatrixOut w) {
    expect_poses(Y.shape(0), Y.shape(1), Y.shape(0), 3, "Y");
    const Interconnections ic = interconnections(edge_index, edge_params, Y.shape(0), PLANAR_EDGE_WIDTH);
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(Y_ref, Y, "Y_ref");
    expect_same_poses(w, Y, "w");
    return planar_interconnection_terms(ic, Y.data(), dY.data(), Y_ref.data(), immobile, w.data());
}

int planar_elastic_accelerations_(Matrix Y, Matrix dY, Matrix Fc, Matrix node_params, Index edge_index,
                                  Matrix edge_params, Vector gravity, Matrix Y_ref, bool immobile, MatrixOut ddY) {
    const size_t N = Y.shape(0);
    expect_poses(Y.shape(0), Y.shape(1), N, 3, "Y");
    expect_same_poses(dY, Y, "dY");
    expect_same_poses(Fc, Y, "Fc");
    expect_same_poses(Y_ref, Y, "Y_ref");
    expect_same_poses(ddY, Y, "ddY");
    expect_node_rows(node_params, N, false);
    check_length(gravity.shape(0), 2, "gravity");
    PlanarElasticModel model{};
    model.node_count = static_cast<int>(N);
    model.nodes = reinterpret_cast<const PlanarNode*>(node_params.data());
    model.interconnections = interconnections(edge_index, edge_params, N, PLANAR_EDGE_WIDTH);
    model.gravity = gravity.data();
    model.Y_ref = Y_ref.data();
    model.immobile = immobile;
    Scratch<double, 3 * 16> w(3 * N);
    return planar_elastic_accelerations(model, Y.data(), dY.data(), Fc.data(), ddY.data(), w.data());
}

// ------------------------------------------------------------------ the layout, by name
#define FIELD(S, f) (fields[#f] = nb::make_tuple(offsetof(S, f) / sizeof(double), sizeof(S::f) / sizeof(double)))

nb::dict elastic_layout() {
    nb::dict out;
    {
        nb::dict fields;  // int64 columns: the same 8 bytes as a double
        FIELD(ElasticEdge, i); FIELD(ElasticEdge, j); FIELD(ElasticEdge, kind); FIELD(ElasticEdge, damping_form);
        out["ElasticEdge"] = fields;
    }
    {
        nb::dict fields;
        FIELD(SpatialSpring, stiffness); FIELD(SpatialSpring, torsion); FIELD(SpatialSpring, rest_length);
        FIELD(SpatialSpring, rest_angles); FIELD(SpatialSpring, rest_offset); FIELD(SpatialSpring, damping);
        FIELD(SpatialSpring, torsion_damping); FIELD(SpatialSpring, kappa); FIELD(SpatialSpring, rest_rotation);
        FIELD(SpatialSpring, rotation_form);
        out["SpatialSpring"] = fields;
    }
    {
        nb::dict fields;
        FIELD(SpatialMatrixElement, stiffness_jj); FIELD(SpatialMatrixElement, damping_jj);
        FIELD(SpatialMatrixElement, rest_offset); FIELD(SpatialMatrixElement, frame_in_i);
        FIELD(SpatialMatrixElement, frame_in_j); FIELD(SpatialMatrixElement, stiffness_linear);
        FIELD(SpatialMatrixElement, damping_linear);
        out["SpatialMatrixElement"] = fields;
    }
    {
        nb::dict fields;
        FIELD(PlanarSpring, stiffness); FIELD(PlanarSpring, torsion); FIELD(PlanarSpring, rest_length);
        FIELD(PlanarSpring, rest_angle); FIELD(PlanarSpring, rest_offset); FIELD(PlanarSpring, damping);
        FIELD(PlanarSpring, torsion_damping);
        out["PlanarSpring"] = fields;
    }
    {
        nb::dict fields;
        FIELD(PlanarMatrixElement, stiffness_jj); FIELD(PlanarMatrixElement, damping_jj);
        FIELD(PlanarMatrixElement, rest_offset); FIELD(PlanarMatrixElement, frame_angle);
        FIELD(PlanarMatrixElement, rest_angle); FIELD(PlanarMatrixElement, stiffness_linear);
        FIELD(PlanarMatrixElement, damping_linear);
        out["PlanarMatrixElement"] = fields;
    }
    {
        nb::dict fields;
        FIELD(SpatialNode, mass); FIELD(SpatialNode, inertia);
        out["SpatialNode"] = fields;
    }
    {
        nb::dict fields;
        FIELD(PlanarNode, mass); FIELD(PlanarNode, inertia);
        out["PlanarNode"] = fields;
    }
    {
        nb::dict fields;
        FIELD(ChartedSpatialNode, mass); FIELD(ChartedSpatialNode, inertia); FIELD(ChartedSpatialNode, chart_kind);
        FIELD(ChartedSpatialNode, chart);
        out["ChartedSpatialNode"] = fields;
    }
    {
        nb::dict fields;
        FIELD(NodeFrames, R); FIELD(NodeFrames, dR); FIELD(NodeFrames, L); FIELD(NodeFrames, chart);
        out["NodeFrames"] = fields;
    }
    return out;
}

#undef FIELD

}  // namespace

void bind_elastic(nb::module_& m) {
    m.def("elastic_layout", &elastic_layout,
          "Every elastic struct's fields (plants/core/elastic_model.h): {struct: {field: (first double, doubles)}}.");
    m.def("spatial_elastic_edges", &spatial_elastic_edges_, nb::arg("Y"), nb::arg("edge_index"),
          nb::arg("edge_params"), nb::arg("F").noconvert(), nb::arg("frames") = nb::none(),
          "Add dPi/dY of every interconnection into F (N, 6) in place; (Pi [J], status). frames: every node's "
          "world frames (N, 6, 3, 3) in its chart; None = the book's world angles.");
    m.def("spatial_damping_edges", &spatial_damping_edges_, nb::arg("Y"), nb::arg("dY"), nb::arg("edge_index"),
          nb::arg("edge_params"), nb::arg("F").noconvert(), nb::arg("frames") = nb::none(),
          "Add dD/d(dY) of the dampers into F (N, 6) in place; returns D [W/2].");
    m.def("spatial_linear_edges", &spatial_linear_edges_, nb::arg("Y"), nb::arg("dY"), nb::arg("Y_ref"),
          nb::arg("edge_index"), nb::arg("edge_params"), nb::arg("F").noconvert(),
          "The immobile model (4.5): add K y + D dy into F (N, 6) in place; returns Pi [J].");
    m.def("spatial_interconnection_terms", &spatial_interconnection_terms_, nb::arg("Y"), nb::arg("dY"),
          nb::arg("edge_index"), nb::arg("edge_params"), nb::arg("Y_ref"), nb::arg("immobile"),
          nb::arg("w").noconvert(), "Add every interconnection's part of w (113) into w (N, 6); returns a status.");
    m.def("spatial_node_frames", &spatial_node_frames_, nb::arg("Y"), nb::arg("node_params"),
          nb::arg("frames").noconvert(),
          "Every node's R, dR/dA, L (and chart) into frames (N, 6, 3, 3), in its chart when node_params has 14 "
          "columns.");
    m.def("spatial_node_terms", &spatial_node_terms_, nb::arg("Y"), nb::arg("dY"), nb::arg("node_params"),
          nb::arg("gravity"), nb::arg("Y_ref"), nb::arg("immobile"), nb::arg("Wr").noconvert(),
          nb::arg("w").noconvert(), "Wr (N, 3, 3) and w = (-m g, gyroscopic) (N, 6) of every node; returns 0.");
    m.def("spatial_node_frames_terms", &spatial_node_frames_terms_, nb::arg("Y"), nb::arg("dY"),
          nb::arg("node_params"), nb::arg("gravity"), nb::arg("frames").noconvert(), nb::arg("Wr").noconvert(),
          nb::arg("w").noconvert(), "spatial_node_frames and spatial_node_terms (mobile) in one pass.");
    m.def("node_rotational_terms", &node_rotational_terms_, nb::arg("A"), nb::arg("dA"), nb::arg("I"),
          nb::arg("Wr").noconvert(), nb::arg("g").noconvert(),
          "One node's rotational inertia L^T I L (3, 3) and gyroscopic term (3) in place.");
    m.def("solve_node_rotation", &solve_node_rotation_, nb::arg("A"), nb::arg("I"), nb::arg("b"),
          nb::arg("out").noconvert(), "Solve (L^T I L) out = b for one node; False at the Euler singularity.");
    m.def("spatial_elastic_accelerations", &spatial_elastic_accelerations_, nb::arg("Y"), nb::arg("dY"),
          nb::arg("Fc"), nb::arg("node_params"), nb::arg("edge_index"), nb::arg("edge_params"), nb::arg("gravity"),
          nb::arg("Y_ref"), nb::arg("immobile"), nb::arg("ddY").noconvert(),
          "ddY (N, 6) of the free spatial elastic system (113) in place; returns a status.");
    m.def("planar_elastic_edges", &planar_elastic_edges_, nb::arg("Y"), nb::arg("edge_index"),
          nb::arg("edge_params"), nb::arg("F").noconvert(),
          "Add dPi/dY of every interconnection into F (N, 3) in place; (Pi [J], status).");
    m.def("planar_damping_edges", &planar_damping_edges_, nb::arg("Y"), nb::arg("dY"), nb::arg("edge_index"),
          nb::arg("edge_params"), nb::arg("F").noconvert(),
          "Add dD/d(dY) of the dampers into F (N, 3) in place; returns D [W/2].");
    m.def("planar_linear_edges", &planar_linear_edges_, nb::arg("Y"), nb::arg("dY"), nb::arg("Y_ref"),
          nb::arg("edge_index"), nb::arg("edge_params"), nb::arg("F").noconvert(),
          "The immobile model (4.5): add K y + D dy into F (N, 3) in place; returns Pi [J].");
    m.def("planar_interconnection_terms", &planar_interconnection_terms_, nb::arg("Y"), nb::arg("dY"),
          nb::arg("edge_index"), nb::arg("edge_params"), nb::arg("Y_ref"), nb::arg("immobile"),
          nb::arg("w").noconvert(), "Add every interconnection's part of w into w (N, 3); returns a status.");
    m.def("planar_elastic_accelerations", &planar_elastic_accelerations_, nb::arg("Y"), nb::arg("dY"),
          nb::arg("Fc"), nb::arg("node_params"), nb::arg("edge_index"), nb::arg("edge_params"), nb::arg("gravity"),
          nb::arg("Y_ref"), nb::arg("immobile"), nb::arg("ddY").noconvert(),
          "ddY (N, 3) of the free planar elastic system in place; returns a status.");
}

}  // namespace plants::binding
