#include "coopctrl/core/qp_tensions.h"

#include <cmath>
#include <limits>

namespace coopctrl {

void pair_tensions(const double* E, int R, int P, const double* F, int ldF, int npos, const double* desired,
                   double* W, double* V, double* sigma, double* out) noexcept {
    const int m = R / npos;
    const bool transposed = P > R;
    const int nr = transposed ? P : R;
    const int nc = transposed ? R : P;
    double fro = 0.0;
    for (int c = 0; c < R; ++c) {
        for (int e = 0; e < P; ++e) {
            const double v = E[c * P + e];
            fro += v * v;
            if (transposed)
                W[e * nc + c] = v;
            else
                W[c * nc + e] = v;
        }
    }
    for (int i = 0; i < nc; ++i)
        for (int j = 0; j < nc; ++j) V[i * nc + j] = i == j ? 1.0 : 0.0;
    const double small = TENSION_NEGLIGIBLE * TENSION_NEGLIGIBLE * fro;
    const double tol = TENSION_JACOBI_TOL * nr;
    for (int sweep = 0; sweep < TENSION_MAX_SWEEPS; ++sweep) {
        bool rotated = false;
        for (int i = 0; i < nc - 1; ++i) {
            for (int j = i + 1; j < nc; ++j) {
                double al = 0.0, be = 0.0, ga = 0.0;
                for (int c = 0; c < nr; ++c) {
                    const double wi = W[c * nc + i], wj = W[c * nc + j];
                    al += wi * wi;
                    be += wj * wj;
                    ga += wi * wj;
                }
                if (al <= small || be <= small || std::abs(ga) <= tol * std::sqrt(al * be)) continue;
                rotated = true;
                const double zeta = (be - al) / (2.0 * ga);
                const double t = std::copysign(1.0, zeta) / (std::abs(zeta) + std::sqrt(1.0 + zeta * zeta));
                const double cs = 1.0 / std::sqrt(1.0 + t * t);
                const double sn = cs * t;
                for (int c = 0; c < nr; ++c) {
                    const double wi = W[c * nc + i], wj = W[c * nc + j];
                    W[c * nc + i] = cs * wi - sn * wj;
                    W[c * nc + j] = sn * wi + cs * wj;
                }
                for (int c = 0; c < nc; ++c) {
                    const double vi = V[c * nc + i], vj = V[c * nc + j];
                    V[c * nc + i] = cs * vi - sn * vj;
                    V[c * nc + j] = sn * vi + cs * vj;
                }
            }
        }
        if (!rotated) break;
    }
    double smax = 0.0;
    for (int j = 0; j < nc; ++j) {
        double s = 0.0;
        for (int c = 0; c < nr; ++c) s += W[c * nc + j] * W[c * nc + j];
        sigma[j] = std::sqrt(s);
        if (sigma[j] > smax) smax = sigma[j];
    }
    bool ill = !(smax > 0.0);
    for (int j = 0; j < nc; ++j) {
        const double rel = smax > 0.0 ? sigma[j] / smax : 0.0;
        if (rel > PAIR_ZERO_RTOL && !(rel > PAIR_KEEP_RTOL)) ill = true;
    }
    if (ill) {
        for (int e = 0; e < P; ++e) out[e] = std::numeric_limits<double>::quiet_NaN();
        return;
    }
    for (int e = 0; e < P; ++e) out[e] = desired[e];
    for (int j = 0; j < nc; ++j) {
        if (!(sigma[j] / smax > PAIR_KEEP_RTOL)) continue;
        const double s2 = sigma[j] * sigma[j];
        if (transposed) {  // E = V W^T: s += w_j (v_j . f - w_j . s_des) / sigma_j^2
            double vf = 0.0;
            for (int i = 0; i < m; ++i)
                for (int a = 0; a < npos; ++a) vf += V[(npos * i + a) * nc + j] * F[i * ldF + a];
            double ws = 0.0;
            for (int e = 0; e < P; ++e) ws += W[e * nc + j] * desired[e];
            const double coef = (vf - ws) / s2;
            for (int e = 0; e < P; ++e) out[e] += W[e * nc + j] * coef;
        } else {  // E V = W: s += v_j (w_j . f / sigma_j^2 - v_j . s_des)
            double wf = 0.0;
            for (int i = 0; i < m; ++i)
                for (int a = 0; a < npos; ++a) wf += W[(npos * i + a) * nc + j] * F[i * ldF + a];
            double vs = 0.0;
            for (int e = 0; e < P; ++e) vs += V[e * nc + j] * desired[e];
            const double coef = wf / s2 - vs;
            for (int e = 0; e < P; ++e) out[e] += V[e * nc + j] * coef;
        }
    }
}

}  // namespace coopctrl
