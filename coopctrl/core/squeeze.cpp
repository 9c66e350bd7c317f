#include "coopctrl/core/squeeze.h"

#include <cmath>
#include <limits>

#include "coopctrl/core/qp_assembly.h"
#include "coopctrl/core/qp_tensions.h"

namespace coopctrl {

void pair_squeeze(const double* r, int m, int npos, const double* F, int p, SqueezeWork& work,
                  double* out) noexcept {
    const int P = m * (m - 1) / 2;
    if (P == 0) return;
    const int R = m * npos;
    bool ok = true;
    for (int i = 0; i < m; ++i) {
        for (int a = 0; a < npos; ++a)
            if (!std::isfinite(r[i * npos + a])) ok = false;
        for (int a = 0; a < p; ++a)
            if (!std::isfinite(F[i * p + a])) ok = false;
    }
    if (ok) {
        for (int c = 0; c < R * P; ++c) work.E[c] = 0.0;
        ok = fill_squeeze_basis(work.E, P, r, m, npos, npos);
    }
    if (!ok) {
        for (int e = 0; e < P; ++e) out[e] = std::numeric_limits<double>::quiet_NaN();
        return;
    }
    pair_tensions(work.E, R, P, F, p, npos, work.desired, work.W, work.V, work.sigma, out);
}

}  // namespace coopctrl
