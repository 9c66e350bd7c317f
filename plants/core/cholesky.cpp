#include "plants/core/cholesky.h"

#include <cmath>

namespace plants {

namespace {

/// The factor and both triangular solves for n <= N, the diagonal kept in a local array.
template <int N>
bool cholesky_solve_small(double* A, int lda, const double* b, double* x, int n) noexcept {
    double diag[N];
    for (int j = 0; j < n; ++j) {
        double* Aj = A + j * lda;
        double s = Aj[j];
        for (int k = 0; k < j; ++k) s -= Aj[k] * Aj[k];
        if (!(s > 0.0)) return false;
        const double d = std::sqrt(s);
        Aj[j] = d;
        diag[j] = d;
        for (int i = j + 1; i < n; ++i) {
            double* Ai = A + i * lda;
            double t = Ai[j];
            for (int k = 0; k < j; ++k) t -= Ai[k] * Aj[k];
            Ai[j] = t / d;
        }
    }
    for (int i = 0; i < n; ++i) {
        const double* Ai = A + i * lda;
        double s = b[i];
        for (int k = 0; k < i; ++k) s -= Ai[k] * x[k];
        x[i] = s / diag[i];
    }
    for (int i = n - 1; i >= 0; --i) {
        double s = x[i];
        for (int k = i + 1; k < n; ++k) s -= A[k * lda + i] * x[k];
        x[i] = s / diag[i];
    }
    return true;
}

}  // namespace

bool cholesky_solve(double* A, int lda, const double* b, double* x, int n) noexcept {
    if (n <= 8) return cholesky_solve_small<8>(A, lda, b, x, n);
    if (n <= 64) return cholesky_solve_small<64>(A, lda, b, x, n);
    for (int j = 0; j < n; ++j) {
        double s = A[j * lda + j];
        for (int k = 0; k < j; ++k) s -= A[j * lda + k] * A[j * lda + k];
        if (!(s > 0.0)) return false;
        const double d = std::sqrt(s);
        A[j * lda + j] = d;
        for (int i = j + 1; i < n; ++i) {
            double t = A[i * lda + j];
            for (int k = 0; k < j; ++k) t -= A[i * lda + k] * A[j * lda + k];
            A[i * lda + j] = t / d;
        }
    }
    for (int i = 0; i < n; ++i) {
        double s = b[i];
        for (int k = 0; k < i; ++k) s -= A[i * lda + k] * x[k];
        x[i] = s / A[i * lda + i];
    }
    for (int i = n - 1; i >= 0; --i) {
        double s = x[i];
        for (int k = i + 1; k < n; ++k) s -= A[k * lda + i] * x[k];
        x[i] = s / A[i * lda + i];
    }
    return true;
}

}  // namespace plants
