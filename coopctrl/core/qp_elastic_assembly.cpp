#include "coopctrl/core/qp_elastic_assembly.h"

#include <cmath>

#include "coopctrl/core/linear_algebra.h"
#include "plants/core/cholesky.h"
#include "plants/core/frames.h"

namespace coopctrl {

namespace {

/// P[o:o+p, o:o+p] = K[o:o+p, o:o+p]^{-1} by Gauss-Jordan with partial pivoting (K, P (n, n)); work (p, 2p).
/// Returns false if the block is singular.
bool invert_block(const double* K, double* P, int n, int o, int p, double* work) {
    const int w2 = 2 * p;
    for (int r = 0; r < p; ++r) {
        for (int c = 0; c < p; ++c) {
            work[r * w2 + c] = K[(o + r) * n + o + c];
            work[r * w2 + p + c] = r == c ? 1.0 : 0.0;
        }
    }
    for (int c = 0; c < p; ++c) {
        int piv = c;
        double big = std::abs(work[c * w2 + c]);
        for (int r = c + 1; r < p; ++r) {
            if (std::abs(work[r * w2 + c]) > big) {
                big = std::abs(work[r * w2 + c]);
                piv = r;
            }
        }
        if (!(big > 0.0)) return false;
        if (piv != c) {
            for (int j = 0; j < w2; ++j) {
                const double t = work[c * w2 + j];
                work[c * w2 + j] = work[piv * w2 + j];
                work[piv * w2 + j] = t;
            }
        }
        const double d = work[c * w2 + c];
        for (int j = 0; j < w2; ++j) work[c * w2 + j] /= d;
        for (int r = 0; r < p; ++r) {
            if (r != c) {
                const double f = work[r * w2 + c];
                if (f != 0.0)
                    for (int j = 0; j < w2; ++j) work[r * w2 + j] -= f * work[c * w2 + j];
            }
        }
    }
    for (int r = 0; r < p; ++r)
        for (int c = 0; c < p; ++c) P[(o + r) * n + o + c] = work[r * w2 + p + c];
    return true;
}

}  // namespace

int fill_elastic_split(ElasticSplit& e, bool spatial, bool* P_changed) noexcept {
    const int m = e.m, p = e.p, k = e.k;
    const int n = m * p;
    const int w2 = 2 * p;
    double* Rb = e.Rb;
    double* work = e.work;
    double* K = e.K;
    double* P = e.P;
    for (int r = 0; r < p; ++r)
        for (int c = 0; c < p; ++c) Rb[r * p + c] = 0.0;
    if (spatial) {
        double R0[9];
        plants::rotation_zyx(e.Y0 + 3, R0);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) Rb[r * p + c] = R0[r * 3 + c];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) Rb[(3 + r) * p + 3 + c] = Rb[r * p + c];
    } else {
        const auto [sn, cs] = plants::sin_cos(e.Y0[2]);
        Rb[0 * p + 0] = cs;
        Rb[0 * p + 1] = -sn;
        Rb[1 * p + 0] = sn;
        Rb[1 * p + 1] = cs;
        Rb[2 * p + 2] = 1.0;
    }
    bool changed = false;
    for (int i = 0; i < m; ++i) {
        const int o = i * p;
        const double* Ki = e.K_obj + static_cast<long>(i) * p * p;
        // Ki = Rb K_obj Rb^T into work[:, :p] (via work[:, p:] = K_obj Rb^T)
        for (int r = 0; r < p; ++r) {
            for (int c = 0; c < p; ++c) {
                double s = 0.0;
                for (int b = 0; b < p; ++b) s += Ki[r * p + b] * Rb[c * p + b];
                work[r * w2 + p + c] = s;
            }
        }
        for (int r = 0; r < p; ++r) {
            for (int c = 0; c < p; ++c) {
                double s = 0.0;
                for (int b = 0; b < p; ++b) s += Rb[r * p + b] * work[b * w2 + p + c];
                work[r * w2 + c] = s;
            }
        }
        for (int r = 0; r < p; ++r) {
            for (int c = 0; c < p; ++c) {
                const double v = 0.5 * (work[r * w2 + c] + work[c * w2 + r]);
                if (v != K[(o + r) * n + o + c]) changed = true;
            }
        }
        for (int r = 0; r < p; ++r) {
            for (int c = r; c < p; ++c) {
                const double v = 0.5 * (work[r * w2 + c] + work[c * w2 + r]);
                K[(o + r) * n + o + c] = v;
                K[(o + c) * n + o + r] = v;
            }
        }
    }
    *P_changed = changed;
    if (changed) {
        for (int r = 0; r < n; ++r)
            for (int c = 0; c < n; ++c) P[r * n + c] = 0.0;
        for (int i = 0; i < m; ++i)
            if (!invert_block(K, P, n, i * p, p, work)) return ELASTIC_SINGULAR_STIFFNESS;
        for (int r = 0; r < n; ++r) {
            for (int c = r + 1; c < n; ++c) {
                const double v = 0.5 * (P[r * n + c] + P[c * n + r]);
                P[r * n + c] = v;
                P[c * n + r] = v;
            }
        }
    }
    // KGt = K G^T (K block diagonal), A = G K G^T
    const double* M = e.M;
    for (int i = 0; i < m; ++i) {
        const int o = i * p;
        for (int a = 0; a < p; ++a) {
            for (int r = 0; r < k; ++r) {
                double s = 0.0;
                for (int b = 0; b < p; ++b) s += K[(o + a) * n + o + b] * M[r * e.ldM + o + b];
                e.KGt[(o + a) * e.ldKGt + r] = s;
            }
        }
    }
    for (int a = 0; a < k; ++a) {
        for (int b = 0; b < k; ++b) {
            double s = 0.0;
            for (int c = 0; c < n; ++c) s += M[a * e.ldM + c] * e.KGt[c * e.ldKGt + b];
            e.A[a * e.ldA + b] = s;
        }
    }
    for (int a = 0; a < k; ++a) {
        for (int b = a + 1; b < k; ++b) {
            const double v = 0.5 * (e.A[a * e.ldA + b] + e.A[b * e.ldA + a]);
            e.A[a * e.ldA + b] = v;
            e.A[b * e.ldA + a] = v;
        }
    }
    if (!plants::cholesky_solve(e.A, e.ldA, e.w, e.y, k)) return ELASTIC_DEGENERATE_GRASP;
    for (int c = 0; c < n; ++c) {
        double s = 0.0;
        for (int a = 0; a < k; ++a) s += e.KGt[c * e.ldKGt + a] * e.y[a];
        e.external[c] = s;
    }
    return ELASTIC_OK;
}

}  // namespace coopctrl
