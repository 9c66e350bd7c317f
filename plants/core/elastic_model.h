// The elastic system's model (docs/model.md s.3, 104-121): its nodes and its interconnections' elements, read
// by name. Each struct is the same doubles, in the same order, as a row of the packed arrays the Python side
// builds (plants/elastic/_layout.py names the same columns), so a numpy row is read as the struct in place.
#pragma once

#include <cstdint>

namespace plants {

/// The element of an interconnection (ElasticEdge::kind).
enum ElementKind : std::int64_t {
    ELEMENT_CENTRAL = 0,  ///< the book's spring with rest length (106-107, 119): SpatialSpring / PlanarSpring
    ELEMENT_OFFSET = 1,   ///< ours: rest offset fixed in node i's frame: SpatialSpring / PlanarSpring
    ELEMENT_MATRIX = 2,   ///< co-rotational element matrix (matrix and beam): SpatialMatrixElement / PlanarMatrixElement
};

/// The dampers' form (ElasticEdge::damping_form).
enum DampingForm : std::int64_t {
    DAMPING_FRAME_INVARIANT = 0,  ///< on the deformation rates only (docs/model.md s.3 [ours])
    DAMPING_BOOK = 1,             ///< the book's (110-111): world velocity and Euler-rate differences
};

/// The rotational spring of a spatial central or offset element (SpatialSpring::rotation_form, a double).
constexpr double ROTATION_BOOK = 0.0;      ///< Euler difference (central), kappa form (offset)
constexpr double ROTATION_GEODESIC = 1.0;  ///< 1/2 e^T C_A e on e = log(R_i^T R_j R0^T)

/// Status codes the kernels return (plants.elastic._layout.STATUS_*).
enum ElasticStatus : int {
    ELASTIC_OK = 0,
    ELASTIC_EULER_SINGULAR = 1,    ///< a node at |cos theta| < EULER_SINGULARITY_COS where L^-1 is needed
    ELASTIC_COINCIDENT_NODES = 2,  ///< a central spring with rest length > 0 at (almost) zero length
    ELASTIC_SINGULAR_MASS = 3,
};

/// The element header of one interconnection: a row of ``edge_index`` (four int64).
struct ElasticEdge {
    std::int64_t i;             ///< first node (0 = the object); carries the offset and the element frame
    std::int64_t j;             ///< second node
    std::int64_t kind;          ///< ElementKind: which struct reads the edge's parameter row
    std::int64_t damping_form;  ///< DampingForm
};

static_assert(sizeof(ElasticEdge) == 4 * sizeof(double), "an edge_index row: four int64, 8 bytes each");

/// A spatial central or offset spring and its dampers: the first 28 doubles of a spatial edge row.
struct SpatialSpring {
    double stiffness[3];        ///< [N/m] c per world axis (central) or per axis of node i's frame (offset)
    double torsion[3];          ///< [N m/rad] cA per Euler axis (psi, theta, phi)
    double rest_length;         ///< [m] l (central)
    double rest_angles[3];      ///< [rad] A0, the rest Euler difference A_i - A_j (central, book rotation form)
    double rest_offset[3];      ///< [m] rho, node j at rest in node i's frame (offset)
    double damping;             ///< [N s/m] d: along the line (central), isotropic (offset)
    double torsion_damping;     ///< [N m s/rad] dA
    double kappa[3];            ///< [N m] rotation-invariant orientation weights per body axis (offset, book form)
    double rest_rotation[9];    ///< R0 = R_i0^T R_j0 row-major, the rest relative rotation (offset; geodesic)
    double rotation_form;       ///< ROTATION_BOOK or ROTATION_GEODESIC
};

/// A spatial matrix (or beam) element, co-rotational, node i clamped in the element frame: a whole spatial row.
struct SpatialMatrixElement {
    double stiffness_jj[36];      ///< K_jj 6x6 row-major [N/m, N, N m/rad] on node j's (u, theta)
    double damping_jj[36];        ///< C_jj 6x6 row-major [N s/m, N s, N m s/rad]
    double rest_offset[3];        ///< [m] u0, node j at rest in the element frame
    double frame_in_i[9];         ///< M = R_i0^T R_e0 row-major: the element frame in node i's frame
    double frame_in_j[9];         ///< N = R_j0^T R_e0 row-major: the element frame in node j's rest frame
    double stiffness_linear[144]; ///< K_lin = G0^T K_jj G0 (12x12 row-major) of the immobile model (4.5)
    double damping_linear[144];   ///< D_lin = G0^T C_jj G0 (12x12 row-major)
};

/// A planar central or offset spring and its dampers: the first 9 doubles of a planar edge row.
struct PlanarSpring {
    double stiffness[2];     ///< [N/m] c (x, z): world axes (central), node i's frame (offset)
    double torsion;          ///< [N m/rad] cA
    double rest_length;      ///< [m] l (central)
    double rest_angle;       ///< [rad] A0 = theta_i - theta_j at rest
    double rest_offset[2];   ///< [m] rho, node j at rest in node i's frame (offset)
    double damping;          ///< [N s/m] d
    double torsion_damping;  ///< [N m s/rad] dA
};

/// A planar matrix (or beam) element: a whole planar row.
struct PlanarMatrixElement {
    double stiffness_jj[9];       ///< K_jj 3x3 row-major [N/m, N, N m/rad] on node j's (u_x, u_z, theta)
    double damping_jj[9];         ///< C_jj 3x3 row-major [N s/m, N s, N m s/rad]
    double rest_offset[2];        ///< [m] u0, node j at rest in the element frame
    double frame_angle;           ///< [rad] alpha = theta_e0 - theta_i0, the element frame in node i's frame
    double rest_angle;            ///< [rad] beta = theta_j0 - theta_i0
    double stiffness_linear[36];  ///< K_lin (6x6 row-major) of the immobile model (4.5)
    double damping_linear[36];    ///< D_lin (6x6 row-major)
};

/// Doubles per row of the packed edge arrays (the widest element of each space).
constexpr int SPATIAL_EDGE_WIDTH = sizeof(SpatialMatrixElement) / sizeof(double);  // 381
constexpr int PLANAR_EDGE_WIDTH = sizeof(PlanarMatrixElement) / sizeof(double);    // 94
static_assert(SPATIAL_EDGE_WIDTH == 381 && PLANAR_EDGE_WIDTH == 94, "plants/elastic/_layout.py's edge widths");
static_assert(sizeof(SpatialSpring) <= sizeof(SpatialMatrixElement) && sizeof(PlanarSpring) <= sizeof(PlanarMatrixElement),
              "a spring fits in its space's edge row");

/// A spatial node: a row of ``node_params`` (4 doubles), or the first 4 of a charted row.
struct SpatialNode {
    double mass;        ///< [kg]
    double inertia[3];  ///< [kg m^2] principal moments (I1, I2, I3) about the body axes (x, y, z)
};

/// A spatial node whose angles are taken in a chart (docs/model.md s.2): a row of 14 doubles.
struct ChartedSpatialNode {
    double mass;        ///< [kg]
    double inertia[3];  ///< [kg m^2]
    double chart_kind;  ///< CHART_WORLD, CHART_STORED or CHART_OWN
    double chart[9];    ///< C row-major (CHART_STORED): R = C R(A)
};
constexpr int SPATIAL_NODE_WIDTH = sizeof(SpatialNode) / sizeof(double);                 // 4
constexpr int SPATIAL_NODE_WIDTH_CHARTED = sizeof(ChartedSpatialNode) / sizeof(double);  // 14

/// Chart kinds (ChartedSpatialNode::chart_kind).
constexpr double CHART_WORLD = 0.0;   ///< the book's world chart, R = R(A)
constexpr double CHART_STORED = 1.0;  ///< a stored constant chart, R = C R(A), C in the node row
constexpr double CHART_OWN = 2.0;     ///< the node's own chart for this evaluation, C in NodeFrames::chart

/// A planar node: a row of ``node_params`` (2 doubles).
struct PlanarNode {
    double mass;     ///< [kg]
    double inertia;  ///< [kg m^2] about the y axis
};

/// One node's frames (a (6, 3, 3) block of the ``frames`` array), evaluated once per node per call.
struct NodeFrames {
    double R[3][3];      ///< the world rotation C R(A) (R(A) = Rz(psi) Ry(theta) Rx(phi) in the world chart)
    double dR[3][3][3];  ///< C dR/dpsi, C dR/dtheta, C dR/dphi
    double L[3][3];      ///< L(A) of omega = L(A) dA (body angular velocity from the Euler rates)
    double chart[3][3];  ///< C (read for a node in a chart only)
};
constexpr int NODE_FRAME_BLOCKS = sizeof(NodeFrames) / (9 * sizeof(double));  // 6

/// The interconnections of one elastic system: the element headers and the parameter rows.
struct Interconnections {
    int count;                 ///< E, the number of interconnections
    const ElasticEdge* edges;  ///< E headers
    const double* params;      ///< E rows of ``width`` doubles, each read as the struct its header's kind names
    int width;                 ///< doubles per row (SPATIAL_EDGE_WIDTH or PLANAR_EDGE_WIDTH)

    /// Edge e's parameter row read as the element struct T (SpatialSpring, PlanarMatrixElement, ...).
    template <class T>
    const T& element(int e) const noexcept {
        return *reinterpret_cast<const T*>(params + static_cast<long>(e) * width);
    }
};

}  // namespace plants
