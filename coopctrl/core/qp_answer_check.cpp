#include "coopctrl/core/qp_answer_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace coopctrl {

void answer_violation(const double* M, int ldM, int rows, const double* lo, const double* hi, const double* x, int n,
                      double* viol_out, double* scale_out) noexcept {
    double viol = -std::numeric_limits<double>::infinity();
    double scale = 0.0;
    for (int r = 0; r < rows; ++r) {
        double s = 0.0;
        for (int c = 0; c < n; ++c) s += M[static_cast<long>(r) * ldM + c] * x[c];
        const double v = std::max(lo[r] - s, s - hi[r]);
        if (v > viol) viol = v;
        if (std::abs(s) > scale) scale = std::abs(s);
    }
    *viol_out = viol;
    *scale_out = scale;
}

double answer_tolerance(const double* lo, const double* hi, int rows, int k, double viol, double scale,
                        double eps_abs, double rho) noexcept {
    double tol = 100.0 * eps_abs * (1.0 + scale);
    if (!(viol <= std::min(tol, rho))) {
        double load = 1.0;
        for (int r = 0; r < rows; ++r) {
            if (r < k || std::isfinite(lo[r])) load = std::max(load, std::abs(lo[r]));
            if (r >= k && std::isfinite(hi[r])) load = std::max(load, std::abs(hi[r]));
        }
        tol = std::min(tol, rho * load);
    }
    return tol;
}

bool answer_ok(const double* M, int ldM, int rows, const double* lo, const double* hi, const double* x, int n, int k,
               double eps_abs, double rho) noexcept {
    for (int c = 0; c < n; ++c)
        if (!std::isfinite(x[c])) return false;
    double viol, scale;
    answer_violation(M, ldM, rows, lo, hi, x, n, &viol, &scale);
    return viol <= answer_tolerance(lo, hi, rows, k, viol, scale, eps_abs, rho);
}

int64_t binding_families(const double* g, const double* z, int z0, int n, int n_in, int m, int64_t row_grip,
                         int64_t row_fric, int64_t n_fric, int64_t row_tau) noexcept {
    int64_t qb = 0;
    if (n_in > 0) {
        double gmax = 0.0;
        for (int c = 0; c < n; ++c)
            if (std::abs(g[c]) > gmax) gmax = std::abs(g[c]);
        const double thr = 1e-7 * (1.0 + gmax);
        for (int64_t r = 0; r < n_in; ++r) {
            if (std::abs(z[z0 + r]) > thr) {
                if (row_grip >= 0 && row_grip <= r && r < row_grip + m)
                    qb |= FAMILY_MIN_GRIP;
                else if (row_fric >= 0 && row_fric <= r && r < row_fric + m * n_fric)
                    qb |= FAMILY_FRICTION;
                else if (row_tau >= 0 && r >= row_tau)
                    qb |= FAMILY_TORQUE;
            }
        }
    }
    return qb;
}

}  // namespace coopctrl
