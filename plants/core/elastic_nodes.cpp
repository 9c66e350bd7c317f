#include "plants/core/elastic_nodes.h"

#include <cmath>

#include "plants/core/elastic_rotation.h"

namespace plants {

using elastic_detail::EULER_SINGULARITY_COS;
using elastic_detail::rotation_and_partials_from_trig;

namespace {

void body_rate_matrix(const double* A, double L[3][3]) noexcept {
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    L[0][0] = -sth; L[0][1] = 0.0; L[0][2] = 1.0;
    L[1][0] = sph * cth; L[1][1] = cph; L[1][2] = 0.0;
    L[2][0] = cph * cth; L[2][1] = -sph; L[2][2] = 0.0;
}

/// M <- C M in place (3x3), column by column.
void left_multiply(const double C[3][3], double M[3][3]) noexcept {
    for (int b = 0; b < 3; ++b) {
        const double m0 = M[0][b], m1 = M[1][b], m2 = M[2][b];
        M[0][b] = C[0][0] * m0 + C[0][1] * m1 + C[0][2] * m2;
        M[1][b] = C[1][0] * m0 + C[1][1] * m1 + C[1][2] * m2;
        M[2][b] = C[2][0] * m0 + C[2][1] * m1 + C[2][2] * m2;
    }
}

void rotational_terms_from_trig(double cth, double sth, double cph, double sph, const double* dA, const double* I,
                                double* Wr, double* g) noexcept {
    const double L00 = -sth, L01 = 0.0, L02 = 1.0;
    const double L10 = sph * cth, L11 = cph, L12 = 0.0;
    const double L20 = cph * cth, L21 = -sph, L22 = 0.0;
    const double col[3][3] = {{L00, L10, L20}, {L01, L11, L21}, {L02, L12, L22}};  // the columns of L
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            Wr[3 * a + b] = I[0] * col[a][0] * col[b][0] + I[1] * col[a][1] * col[b][1] + I[2] * col[a][2] * col[b][2];
    const double dth = dA[1], dph = dA[2];
    const double w0 = L00 * dA[0] + L02 * dA[2];
    const double w1 = L10 * dA[0] + L11 * dA[1];
    const double w2 = L20 * dA[0] + L21 * dA[1];
    // Ldot dA
    const double ld0 = -cth * dth * dA[0];
    const double ld1 = (cph * cth * dph - sph * sth * dth) * dA[0] - sph * dph * dA[1];
    const double ld2 = (-sph * cth * dph - cph * sth * dth) * dA[0] - cph * dph * dA[1];
    const double Iw0 = I[0] * w0, Iw1 = I[1] * w1, Iw2 = I[2] * w2;
    const double t0 = I[0] * ld0 + (w1 * Iw2 - w2 * Iw1);
    const double t1 = I[1] * ld1 + (w2 * Iw0 - w0 * Iw2);
    const double t2 = I[2] * ld2 + (w0 * Iw1 - w1 * Iw0);
    g[0] = L00 * t0 + L10 * t1 + L20 * t2;
    g[1] = L01 * t0 + L11 * t1 + L21 * t2;
    g[2] = L02 * t0 + L12 * t1 + L22 * t2;
}

}  // namespace

void node_frames(const double* Y, int N, NodeFrames* frames) noexcept {
    for (int k = 0; k < N; ++k) {
        const double* A = Y + 6 * k + 3;
        NodeFrames& f = frames[k];
        const auto [sps, cps] = sin_cos(A[0]);
        const auto [sth, cth] = sin_cos(A[1]);
        const auto [sph, cph] = sin_cos(A[2]);
        rotation_and_partials_from_trig(cps, sps, cth, sth, cph, sph, f.R, f.dR[0], f.dR[1], f.dR[2]);
        body_rate_matrix(A, f.L);
    }
}

void apply_charts(const ChartedSpatialNode* nodes, int N, NodeFrames* frames) noexcept {
    for (int k = 0; k < N; ++k) {
        const double kind = nodes[k].chart_kind;
        NodeFrames& f = frames[k];
        if (kind == CHART_STORED) {
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) f.chart[a][b] = nodes[k].chart[3 * a + b];
        } else if (kind != CHART_OWN) {
            continue;
        }
        left_multiply(f.chart, f.R);
        for (int blk = 0; blk < 3; ++blk) left_multiply(f.chart, f.dR[blk]);
    }
}

void node_frames_charted(const double* Y, int N, const double* node_rows, int node_width,
                         NodeFrames* frames) noexcept {
    node_frames(Y, N, frames);
    if (node_width == SPATIAL_NODE_WIDTH_CHARTED)
        apply_charts(reinterpret_cast<const ChartedSpatialNode*>(node_rows), N, frames);
}

void node_rotational_terms(const double* A, const double* dA, const double* I, double* Wr, double* g) noexcept {
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    rotational_terms_from_trig(cth, sth, cph, sph, dA, I, Wr, g);
}

int node_terms(const double* Y, const double* dY, int N, const double* node_rows, int node_width,
               const double* gravity, const double* Y_ref, bool immobile, double* Wr, double* w) noexcept {
    double g3[3];
    const double zero[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < N; ++k) {
        const SpatialNode& node = *reinterpret_cast<const SpatialNode*>(node_rows + static_cast<long>(k) * node_width);
        double* wk = w + 6 * k;
        const double m = node.mass;
        for (int a = 0; a < 3; ++a) wk[a] = -m * gravity[a];
        if (immobile) {
            node_rotational_terms(Y_ref + 6 * k + 3, zero, node.inertia, Wr + 9 * k, g3);
            wk[3] = 0.0;
            wk[4] = 0.0;
            wk[5] = 0.0;
        } else {
            node_rotational_terms(Y + 6 * k + 3, dY + 6 * k + 3, node.inertia, Wr + 9 * k, g3);
            wk[3] = g3[0];
            wk[4] = g3[1];
            wk[5] = g3[2];
        }
    }
    return ELASTIC_OK;
}

void node_frames_terms(const double* Y, const double* dY, int N, const double* node_rows, int node_width,
                       const double* gravity, NodeFrames* frames, double* Wr, double* w) noexcept {
    for (int k = 0; k < N; ++k) {
        const double* A = Y + 6 * k + 3;
        const auto [sps, cps] = sin_cos(A[0]);
        const auto [sth, cth] = sin_cos(A[1]);
        const auto [sph, cph] = sin_cos(A[2]);
        NodeFrames& f = frames[k];
        rotation_and_partials_from_trig(cps, sps, cth, sth, cph, sph, f.R, f.dR[0], f.dR[1], f.dR[2]);
        f.L[0][0] = -sth; f.L[0][1] = 0.0; f.L[0][2] = 1.0;
        f.L[1][0] = sph * cth; f.L[1][1] = cph; f.L[1][2] = 0.0;
        f.L[2][0] = cph * cth; f.L[2][1] = -sph; f.L[2][2] = 0.0;
        const SpatialNode& node = *reinterpret_cast<const SpatialNode*>(node_rows + static_cast<long>(k) * node_width);
        const double m = node.mass;
        for (int a = 0; a < 3; ++a) w[6 * k + a] = -m * gravity[a];
        rotational_terms_from_trig(cth, sth, cph, sph, dY + 6 * k + 3, node.inertia, Wr + 9 * k, w + 6 * k + 3);
    }
    if (node_width == SPATIAL_NODE_WIDTH_CHARTED)
        apply_charts(reinterpret_cast<const ChartedSpatialNode*>(node_rows), N, frames);
}

bool solve_node_rotation(const double* A, const double* I, const double* b, double* out) noexcept {
    const auto [sth, cth] = sin_cos(A[1]);
    if (std::fabs(cth) < EULER_SINGULARITY_COS) return false;
    const auto [sph, cph] = sin_cos(A[2]);
    const double tth = sth / cth;
    // Linv rows: [0, sph/cth, cph/cth], [0, cph, -sph], [1, sph*tth, cph*tth]; y = Linv^T b
    const double y0 = b[2] / I[0];
    const double y1 = (sph / cth * b[0] + cph * b[1] + sph * tth * b[2]) / I[1];
    const double y2 = (cph / cth * b[0] - sph * b[1] + cph * tth * b[2]) / I[2];
    out[0] = sph / cth * y1 + cph / cth * y2;
    out[1] = cph * y1 - sph * y2;
    out[2] = y0 + sph * tth * y1 + cph * tth * y2;
    return true;
}

}  // namespace plants
