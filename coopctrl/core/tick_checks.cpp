#include "coopctrl/core/tick_checks.h"

#include <cmath>

#include "plants/core/frames.h"
#include "plants/core/rigid_motion.h"

namespace coopctrl {

void required_wrench(bool spatial, double mass, const double* inertia, const double* gravity, const double* Y0,
                     const double* dY0, const double* ddY0, double* out) noexcept {
    if (!spatial) {
        out[0] = mass * (ddY0[0] - gravity[0]);
        out[1] = mass * (ddY0[1] - gravity[1]);
        out[2] = inertia[0] * ddY0[2];
        return;
    }
    double w[3], dw[3], tb[3], R[9];
    plants::body_rates(Y0 + 3, dY0 + 3, ddY0 + 3, w, dw);
    const double Iw0 = inertia[0] * w[0], Iw1 = inertia[1] * w[1], Iw2 = inertia[2] * w[2];
    tb[0] = inertia[0] * dw[0] + (w[1] * Iw2 - w[2] * Iw1);
    tb[1] = inertia[1] * dw[1] + (w[2] * Iw0 - w[0] * Iw2);
    tb[2] = inertia[2] * dw[2] + (w[0] * Iw1 - w[1] * Iw0);
    plants::rotation_zyx(Y0 + 3, R);
    for (int a = 0; a < 3; ++a) {
        out[a] = mass * (ddY0[a] - gravity[a]);
        out[3 + a] = R[a * 3 + 0] * tb[0] + R[a * 3 + 1] * tb[1] + R[a * 3 + 2] * tb[2];
    }
}

int guards(bool spatial, const double* x, int nx, const double* Y, int m, const double* rho, double band,
           double max_deformation, int* contact, double* deformation) noexcept {
    const int p = spatial ? 6 : 3;
    const int npos = spatial ? 3 : 2;
    for (int c = 0; c < nx; ++c)
        if (!std::isfinite(x[c])) return GUARD_NONFINITE;
    if (spatial) {
        double cmin = 2.0;
        for (int j = 0; j <= m; ++j) {
            const double c = std::fabs(std::cos(Y[j * p + 4]));
            if (c < cmin) cmin = c;
        }
        if (cmin < band) return GUARD_NEAR_SINGULARITY;
    }
    double worst = 0.0;
    int which = 0;
    double R0[9], d[3];
    if (spatial) plants::rotation_zyx(Y + 3, R0);
    for (int i = 0; i < m; ++i) {
        const double* Yi = Y + (i + 1) * p;
        if (spatial) {
            for (int a = 0; a < 3; ++a) {
                double s = 0.0;
                for (int b = 0; b < 3; ++b) s += R0[b * 3 + a] * (Yi[b] - Y[b]);
                d[a] = s - rho[i * npos + a];
            }
        } else {
            const auto [s0, c0] = plants::sin_cos(Y[2]);
            const double e0 = Yi[0] - Y[0], e1 = Yi[1] - Y[1];
            d[0] = c0 * e0 + s0 * e1 - rho[i * npos + 0];
            d[1] = -s0 * e0 + c0 * e1 - rho[i * npos + 1];
        }
        double s = 0.0;
        for (int a = 0; a < npos; ++a) s += d[a] * d[a];
        const double v = std::sqrt(s);
        if (!(v <= worst)) {
            worst = v;
            which = i;
        }
    }
    if (worst > max_deformation) {
        *contact = which;
        *deformation = worst;
        return GUARD_DEFORMATION;
    }
    return GUARD_OK;
}

}  // namespace coopctrl
