#include "plants/core/rigid_motion.h"

#include <cmath>

#include "plants/core/frames.h"

namespace plants {

namespace {
void cross(const double* a, const double* b, double* out) noexcept {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
}  // namespace

void body_rates(const double* A, const double* dA, const double* ddA, double* w, double* dw) noexcept {
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    const double dth = dA[1], dph = dA[2];
    w[0] = -sth * dA[0] + dA[2];
    w[1] = sph * cth * dA[0] + cph * dA[1];
    w[2] = cph * cth * dA[0] - sph * dA[1];
    // L ddA + dL dA, row by row (dL: body_rate_map_dot)
    dw[0] = (-sth * ddA[0] + ddA[2]) + (-cth * dth) * dA[0];
    dw[1] = (sph * cth * ddA[0] + cph * ddA[1]) + ((cph * cth * dph - sph * sth * dth) * dA[0] + (-sph * dph) * dA[1]);
    dw[2] = (cph * cth * ddA[0] - sph * ddA[1]) + ((-sph * cth * dph - cph * sth * dth) * dA[0] + (-cph * dph) * dA[1]);
}

int spatial_motion(const double* Y0, const double* dY0, const double* ddY0, const double* G, int m, double* Y,
                   double* dY, double* ddY) noexcept {
    for (int a = 0; a < 6; ++a) {
        Y[a] = Y0[a];
        dY[a] = dY0[a];
        ddY[a] = ddY0[a];
    }
    double R0[9], Rg[9], Rj[9], Linv[9];
    double wb[3], dwb[3], omega[3], alpha[3], d[3], Aj[3], t[3], u[3];
    rotation_zyx(Y0 + 3, R0);
    body_rates(Y0 + 3, dY0 + 3, ddY0 + 3, wb, dwb);
    for (int a = 0; a < 3; ++a) {
        omega[a] = R0[a * 3 + 0] * wb[0] + R0[a * 3 + 1] * wb[1] + R0[a * 3 + 2] * wb[2];
        alpha[a] = R0[a * 3 + 0] * dwb[0] + R0[a * 3 + 1] * dwb[1] + R0[a * 3 + 2] * dwb[2];
    }
    int bad = -1;
    for (int j = 0; j < m; ++j) {
        const double* g = G + j * 6;
        double* Yj = Y + (j + 1) * 6;
        double* dYj = dY + (j + 1) * 6;
        double* ddYj = ddY + (j + 1) * 6;
        rotation_zyx(g + 3, Rg);
        for (int a = 0; a < 3; ++a) {
            d[a] = R0[a * 3 + 0] * g[0] + R0[a * 3 + 1] * g[1] + R0[a * 3 + 2] * g[2];
            for (int b = 0; b < 3; ++b)
                Rj[a * 3 + b] = R0[a * 3 + 0] * Rg[0 * 3 + b] + R0[a * 3 + 1] * Rg[1 * 3 + b] +
                                R0[a * 3 + 2] * Rg[2 * 3 + b];
        }
        Aj[0] = std::atan2(Rj[1 * 3 + 0], Rj[0 * 3 + 0]);
        Aj[1] = std::atan2(-Rj[2 * 3 + 0], std::sqrt(Rj[2 * 3 + 1] * Rj[2 * 3 + 1] + Rj[2 * 3 + 2] * Rj[2 * 3 + 2]));
        Aj[2] = std::atan2(Rj[2 * 3 + 1], Rj[2 * 3 + 2]);
        cross(omega, d, t);  // omega x d
        cross(omega, t, u);  // omega x (omega x d)
        for (int a = 0; a < 3; ++a) {
            Yj[a] = Y0[a] + d[a];
            Yj[3 + a] = Aj[a];
            dYj[a] = dY0[a] + t[a];
        }
        cross(alpha, d, t);  // alpha x d
        for (int a = 0; a < 3; ++a) ddYj[a] = ddY0[a] + (t[a] + u[a]);
        if (!body_rate_map_inverse(Aj, Linv)) {
            bad = j + 1;
            for (int a = 0; a < 3; ++a) {
                dYj[3 + a] = 0.0;
                ddYj[3 + a] = 0.0;
            }
            continue;
        }
        // dA_j = L^-1 R_j^T omega;  ddA_j = L^-1 (R_j^T alpha - dL_j dA_j)
        for (int a = 0; a < 3; ++a) {
            t[a] = Rj[0 * 3 + a] * omega[0] + Rj[1 * 3 + a] * omega[1] + Rj[2 * 3 + a] * omega[2];
            u[a] = Rj[0 * 3 + a] * alpha[0] + Rj[1 * 3 + a] * alpha[1] + Rj[2 * 3 + a] * alpha[2];
        }
        for (int a = 0; a < 3; ++a)
            d[a] = Linv[a * 3 + 0] * t[0] + Linv[a * 3 + 1] * t[1] + Linv[a * 3 + 2] * t[2];  // dA_j
        const auto [sth, cth] = sin_cos(Aj[1]);
        const auto [sph, cph] = sin_cos(Aj[2]);
        const double dth = d[1], dph = d[2];
        u[0] -= (-cth * dth) * d[0];
        u[1] -= (cph * cth * dph - sph * sth * dth) * d[0] + (-sph * dph) * d[1];
        u[2] -= (-sph * cth * dph - cph * sth * dth) * d[0] + (-cph * dph) * d[1];
        for (int a = 0; a < 3; ++a) {
            dYj[3 + a] = d[a];
            ddYj[3 + a] = Linv[a * 3 + 0] * u[0] + Linv[a * 3 + 1] * u[1] + Linv[a * 3 + 2] * u[2];
        }
    }
    return bad;
}

void planar_motion(const double* Y0, const double* dY0, const double* ddY0, const double* G, int m, double* Y,
                   double* dY, double* ddY) noexcept {
    for (int a = 0; a < 3; ++a) {
        Y[a] = Y0[a];
        dY[a] = dY0[a];
        ddY[a] = ddY0[a];
    }
    const double th = Y0[2], w = dY0[2], al = ddY0[2];
    const auto [s, c] = sin_cos(th);
    for (int j = 0; j < m; ++j) {
        const double* g = G + j * 3;
        double* Yj = Y + (j + 1) * 3;
        double* dYj = dY + (j + 1) * 3;
        double* ddYj = ddY + (j + 1) * 3;
        const double d0 = c * g[0] - s * g[1];
        const double d1 = s * g[0] + c * g[1];
        Yj[0] = Y0[0] + d0;
        Yj[1] = Y0[1] + d1;
        Yj[2] = th + g[2];
        dYj[0] = dY0[0] - w * d1;
        dYj[1] = dY0[1] + w * d0;
        dYj[2] = w;
        ddYj[0] = ddY0[0] - al * d1 - w * w * d0;
        ddYj[1] = ddY0[1] + al * d0 - w * w * d1;
        ddYj[2] = al;
    }
}

}  // namespace plants
