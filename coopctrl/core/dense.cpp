#include "coopctrl/core/dense.h"

#include <cmath>
#include <limits>

namespace coopctrl {

double max_abs(const double* v, int n) noexcept {
    double m = 0.0;
    for (int c = 0; c < n; ++c) {
        const double a = std::fabs(v[c]);
        if (a > m || a != a) {
            m = a;
            if (a != a) return a;
        }
    }
    return m;
}

bool invert_into(const double* A, int n, double* LU, double* M) noexcept {
    for (int r = 0; r < n; ++r) {
        for (int c = 0; c < n; ++c) {
            LU[r * n + c] = A[r * n + c];
            M[r * n + c] = 0.0;
        }
        M[r * n + r] = 1.0;
    }
    for (int j = 0; j < n; ++j) {
        int p = j;
        double best = std::fabs(LU[j * n + j]);
        for (int r = j + 1; r < n; ++r) {
            const double v = std::fabs(LU[r * n + j]);
            if (v > best) {
                best = v;
                p = r;
            }
        }
        if (LU[p * n + j] == 0.0) return false;
        if (p != j) {  // swap the rows of the factors and of the right-hand side P I
            for (int c = 0; c < n; ++c) {
                double t = LU[j * n + c];
                LU[j * n + c] = LU[p * n + c];
                LU[p * n + c] = t;
                t = M[j * n + c];
                M[j * n + c] = M[p * n + c];
                M[p * n + c] = t;
            }
        }
        const double piv = LU[j * n + j];
        for (int r = j + 1; r < n; ++r) {
            const double lrj = LU[r * n + j] / piv;
            LU[r * n + j] = lrj;
            if (lrj != 0.0) {
                for (int c = j + 1; c < n; ++c) LU[r * n + c] -= lrj * LU[j * n + c];
                for (int c = 0; c < n; ++c) M[r * n + c] -= lrj * M[j * n + c];
            }
        }
    }
    for (int r = n - 1; r >= 0; --r) {  // back substitution U X = L^-1 P I, all columns at once
        for (int j = r + 1; j < n; ++j) {
            const double u = LU[r * n + j];
            if (u != 0.0)
                for (int c = 0; c < n; ++c) M[r * n + c] -= u * M[j * n + c];
        }
        const double d = LU[r * n + r];
        for (int c = 0; c < n; ++c) M[r * n + c] /= d;
    }
    return true;
}

void pinv_into(const double* A, int n, double* M, double* work) noexcept {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (int i = 0; i < n * n; ++i) {
        if (!std::isfinite(A[i])) {
            for (int j = 0; j < n * n; ++j) M[j] = nan;
            return;
        }
    }
    // One-sided Jacobi: rotate the columns of U = A (V accumulates the rotations) until they are orthogonal;
    // then A = U diag(1/s) ... with s_j = |U_j|, and pinv(A) = V diag(1/s_j) (U_j / s_j)^T.
    double* U = work;          // n x n, column j = U[r * n + j]
    double* V = work + n * n;  // n x n
    double* s = V + n * n;     // n
    for (int i = 0; i < n * n; ++i) {
        U[i] = A[i];
        V[i] = 0.0;
    }
    for (int i = 0; i < n; ++i) V[i * n + i] = 1.0;
    const double eps = std::numeric_limits<double>::epsilon();
    for (int sweep = 0; sweep < 60; ++sweep) {
        bool rotated = false;
        for (int p = 0; p < n - 1; ++p) {
            for (int q = p + 1; q < n; ++q) {
                double alpha = 0.0, beta = 0.0, gamma = 0.0;
                for (int r = 0; r < n; ++r) {
                    const double up = U[r * n + p], uq = U[r * n + q];
                    alpha += up * up;
                    beta += uq * uq;
                    gamma += up * uq;
                }
                if (gamma == 0.0 || std::fabs(gamma) <= eps * std::sqrt(alpha * beta)) continue;
                rotated = true;
                const double zeta = (beta - alpha) / (2.0 * gamma);
                const double t = (zeta >= 0.0 ? 1.0 : -1.0) / (std::fabs(zeta) + std::sqrt(1.0 + zeta * zeta));
                const double c = 1.0 / std::sqrt(1.0 + t * t), sn = c * t;
                for (int r = 0; r < n; ++r) {
                    const double up = U[r * n + p], uq = U[r * n + q];
                    U[r * n + p] = c * up - sn * uq;
                    U[r * n + q] = sn * up + c * uq;
                    const double vp = V[r * n + p], vq = V[r * n + q];
                    V[r * n + p] = c * vp - sn * vq;
                    V[r * n + q] = sn * vp + c * vq;
                }
            }
        }
        if (!rotated) break;
    }
    double largest = 0.0;
    for (int j = 0; j < n; ++j) {
        double ss = 0.0;
        for (int r = 0; r < n; ++r) ss += U[r * n + j] * U[r * n + j];
        s[j] = std::sqrt(ss);
        if (s[j] > largest) largest = s[j];
    }
    const double cutoff = 1e-15 * largest;
    for (int i = 0; i < n * n; ++i) M[i] = 0.0;
    for (int j = 0; j < n; ++j) {
        if (!(s[j] > cutoff)) continue;
        const double inv2 = 1.0 / (s[j] * s[j]);  // V_j / s_j times (U_j / s_j)^T
        for (int r = 0; r < n; ++r) {
            const double v = V[r * n + j] * inv2;
            if (v == 0.0) continue;
            for (int c = 0; c < n; ++c) M[r * n + c] += v * U[c * n + j];
        }
    }
}

}  // namespace coopctrl
