#include "coopctrl/core/linear_algebra.h"

#include <algorithm>
#include <cmath>

namespace coopctrl {

bool lu_factor(const double* A, int lda, int n, double* M, int ldm, int64_t* piv) noexcept {
    double scale = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            const double v = A[i * lda + j];
            M[i * ldm + j] = v;
            scale = std::max(scale, std::abs(v));
        }
    }
    const double tiny = 1e-13 * (scale > 0 ? scale : 1.0);
    for (int c = 0; c < n; ++c) {
        int p = c;
        for (int r = c + 1; r < n; ++r)
            if (std::abs(M[r * ldm + c]) > std::abs(M[p * ldm + c])) p = r;
        piv[c] = p;
        if (std::abs(M[p * ldm + c]) <= tiny) return false;
        if (p != c)
            for (int j = 0; j < n; ++j) std::swap(M[c * ldm + j], M[p * ldm + j]);
        const double inv = 1.0 / M[c * ldm + c];
        M[c * ldm + c] = inv;
        for (int r = c + 1; r < n; ++r) {
            const double f = M[r * ldm + c] * inv;
            for (int j = c + 1; j < n; ++j) M[r * ldm + j] -= f * M[c * ldm + j];
            M[r * ldm + c] = f;
        }
    }
    return true;
}

void lu_solve_factored(const double* M, int ldm, const int64_t* piv, int n, const double* b, double* x) noexcept {
    for (int i = 0; i < n; ++i) x[i] = b[i];
    for (int c = 0; c < n; ++c) {
        const int64_t p = piv[c];
        if (p != c) std::swap(x[c], x[p]);
    }
    for (int c = 0; c < n; ++c) {
        const double xc = x[c];
        for (int r = c + 1; r < n; ++r) x[r] -= M[r * ldm + c] * xc;
    }
    for (int c = n - 1; c >= 0; --c) {
        double s = x[c];
        for (int j = c + 1; j < n; ++j) s -= M[c * ldm + j] * x[j];
        x[c] = s * M[c * ldm + c];
    }
}

bool lu_solve(const double* A, int lda, const double* b, int n, double* LU, int ldlu, int64_t* piv,
              double* x) noexcept {
    if (!lu_factor(A, lda, n, LU, ldlu, piv)) return false;
    lu_solve_factored(LU, ldlu, piv, n, b, x);
    return true;
}

bool consistent_acceleration(const double* W, int ldW, const double* H, int ldH, const double* J, int ldJ, int p,
                             const double* rhs, int n, double* wv, double* wm, int ldw, int64_t* piv,
                             double* qdd) noexcept {
    const long mat = static_cast<long>(ldw) * ldw;
    double* Nm = wm;
    double* X = wm + mat;
    double* A = wm + 2 * mat;
    double* LU = wm + 3 * mat;
    double* WJ = wm + 2 * mat;  // shares A's storage, as in the numba kernel
    for (int a = 0; a < p; ++a) {
        for (int c = 0; c < n; ++c) {
            double t = 0.0;
            for (int b = 0; b < p; ++b) t += W[a * ldW + b] * J[b * ldJ + c];
            WJ[a * ldw + c] = t;
        }
    }
    for (int r = 0; r < n; ++r) {
        for (int c = 0; c < r + 1; ++c) {  // J^T W J is symmetric: the lower triangle, mirrored
            double s = 0.0;
            for (int a = 0; a < p; ++a) s += J[a * ldJ + r] * WJ[a * ldw + c];
            Nm[r * ldw + c] = H[r * ldH + c] + s;
            Nm[c * ldw + r] = H[c * ldH + r] + s;
        }
    }
    double* col = wv + ldw;
    if (!lu_factor(Nm, ldw, n, LU, ldw, piv)) {
        for (int c = 0; c < n; ++c) qdd[c] = 0.0;
        return false;
    }
    for (int c = 0; c < p; ++c) {
        for (int r = 0; r < n; ++r) col[r] = J[c * ldJ + r];
        lu_solve_factored(LU, ldw, piv, n, col, col);
        for (int r = 0; r < n; ++r) X[r * ldw + c] = col[r];
    }
    for (int a = 0; a < p; ++a) {
        for (int c = 0; c < p; ++c) {
            double s = 0.0;
            for (int r = 0; r < n; ++r) s += J[a * ldJ + r] * X[r * ldw + c];
            A[a * ldw + c] = s;
        }
    }
    double* y = wv + 2 * ldw;
    if (!lu_factor(A, ldw, p, LU, ldw, piv)) {
        for (int c = 0; c < n; ++c) qdd[c] = 0.0;
        return false;
    }
    lu_solve_factored(LU, ldw, piv, p, rhs, y);
    for (int r = 0; r < n; ++r) {
        double s = 0.0;
        for (int c = 0; c < p; ++c) s += X[r * ldw + c] * y[c];
        qdd[r] = s;
    }
    return true;
}

}  // namespace coopctrl
