#include "plants/core/cholesky.h"

#include <cmath>

namespace plants {

bool cholesky_solve(double* A, int lda, const double* b, double* x, int n) noexcept {
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
