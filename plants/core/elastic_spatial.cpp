#include "plants/core/elastic_spatial.h"

#include "plants/core/elastic_matrix.h"
#include "plants/core/elastic_nodes.h"
#include "plants/core/elastic_springs.h"

namespace plants {

int spatial_elastic_edges(const Interconnections& ic, const double* Y, const NodeFrames* frames, double* F,
                          double* Pi) noexcept {
    double sum = 0.0;
    for (int e = 0; e < ic.count; ++e) {
        const ElasticEdge& edge = ic.edges[e];
        const int i = static_cast<int>(edge.i), j = static_cast<int>(edge.j);
        if (edge.kind == ELEMENT_CENTRAL) {
            if (central_spring(ic.element<SpatialSpring>(e), i, j, Y, frames, F, sum) != ELASTIC_OK) {
                *Pi = sum;
                return ELASTIC_COINCIDENT_NODES;
            }
        } else if (edge.kind == ELEMENT_MATRIX) {
            sum += spatial_matrix_element(ic.element<SpatialMatrixElement>(e), i, j, Y, Y, frames, F, false);
        } else {
            offset_spring(ic.element<SpatialSpring>(e), i, j, Y, frames, F, sum);
        }
    }
    *Pi = sum;
    return ELASTIC_OK;
}

double spatial_damping_edges(const Interconnections& ic, const double* Y, const double* dY,
                             const NodeFrames* frames, double* F) noexcept {
    double D = 0.0;
    for (int e = 0; e < ic.count; ++e) {
        const ElasticEdge& edge = ic.edges[e];
        if (edge.kind == ELEMENT_MATRIX) {
            D += spatial_matrix_element(ic.element<SpatialMatrixElement>(e), static_cast<int>(edge.i),
                                        static_cast<int>(edge.j), Y, dY, frames, F, true);
            continue;
        }
        spring_dampers(ic.element<SpatialSpring>(e), edge, Y, dY, frames, F, D);
    }
    return D;
}

double spatial_linear_edges(const Interconnections& ic, const double* Y, const double* dY, const double* Y_ref,
                            double* F) noexcept {
    double Pi = 0.0;
    for (int e = 0; e < ic.count; ++e) {
        const ElasticEdge& edge = ic.edges[e];
        const int i = static_cast<int>(edge.i), j = static_cast<int>(edge.j);
        if (edge.kind == ELEMENT_MATRIX) {
            const SpatialMatrixElement& m = ic.element<SpatialMatrixElement>(e);
            Pi += linear_matrix_element(m.stiffness_linear, m.damping_linear, 6, 3, i, j, Y, dY, Y_ref, F);
            continue;
        }
        linear_spring(ic.element<SpatialSpring>(e), i, j, Y, dY, Y_ref, F, Pi);
    }
    return Pi;
}

int spatial_interconnection_terms(const Interconnections& ic, int N, const double* Y, const double* dY,
                                  const double* Y_ref, bool immobile, double* w, NodeFrames* frames) noexcept {
    if (immobile) {
        spatial_linear_edges(ic, Y, dY, Y_ref, w);
        return ELASTIC_OK;
    }
    node_frames(Y, N, frames);
    double Pi;
    const int status = spatial_elastic_edges(ic, Y, frames, w, &Pi);
    if (status != ELASTIC_OK) return status;
    spatial_damping_edges(ic, Y, dY, frames, w);
    return ELASTIC_OK;
}

int spatial_elastic_accelerations(const SpatialElasticModel& model, const double* Y, const double* dY,
                                  const double* Fc, double* ddY, const SpatialElasticWork& work) noexcept {
    const int N = model.node_count;
    const Interconnections& ic = model.interconnections;
    double* w = work.w;
    node_terms(Y, dY, N, model.node_rows, model.node_width, model.gravity, model.Y_ref, model.immobile, work.Wr, w);
    int status;
    if (model.immobile) {
        status = spatial_interconnection_terms(ic, N, Y, dY, model.Y_ref, true, w, work.frames);
    } else {  // the interconnection terms with each node's frames in its chart
        node_frames_charted(Y, N, model.node_rows, model.node_width, work.frames);
        double Pi;
        status = spatial_elastic_edges(ic, Y, work.frames, w, &Pi);
        if (status == ELASTIC_OK) spatial_damping_edges(ic, Y, dY, work.frames, w);
    }
    if (status != ELASTIC_OK) {
        for (int k = 0; k < 6 * N; ++k) ddY[k] = 0.0;
        return status;
    }
    double b[3], out[3];
    for (int k = 0; k < N; ++k) {
        const SpatialNode& node =
            *reinterpret_cast<const SpatialNode*>(model.node_rows + static_cast<long>(k) * model.node_width);
        const double m = node.mass;
        for (int a = 0; a < 6; ++a) {
            const double f = (k > 0 ? Fc[6 * k + a] : 0.0) - w[6 * k + a];
            if (a < 3)
                ddY[6 * k + a] = f / m;
            else
                b[a - 3] = f;
        }
        const double* A = (model.immobile ? model.Y_ref : Y) + 6 * k + 3;
        if (!solve_node_rotation(A, node.inertia, b, out)) return ELASTIC_EULER_SINGULAR;
        ddY[6 * k + 3] = out[0];
        ddY[6 * k + 4] = out[1];
        ddY[6 * k + 5] = out[2];
    }
    return ELASTIC_OK;
}

}  // namespace plants
