#include "plants/core/elastic_matrix.h"

#include <cmath>

#include "plants/core/elastic_rotation.h"

namespace plants {

using elastic_detail::log_so3;
using elastic_detail::wrap_angle;

double spatial_matrix_element(const SpatialMatrixElement& m, int i, int j, const double* Y, const double* dY,
                              const NodeFrames* frames, double* F, bool rates) noexcept {
    const double(&Ri)[3][3] = frames[i].R;
    const double(&Rj)[3][3] = frames[j].R;
    const double(&Li)[3][3] = frames[i].L;
    const double(&Lj)[3][3] = frames[j].L;
    const double* M = m.frame_in_i;
    const double* N = m.frame_in_j;
    const double* Yi = Y + 6 * i;
    const double* Yj = Y + 6 * j;
    double Re[3][3], Q[3][3];
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) Re[a][b] = (Ri[a][0] * M[b] + Ri[a][1] * M[3 + b] + Ri[a][2] * M[6 + b]);
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double acc = 0.0;
            for (int k = 0; k < 3; ++k) acc += Re[k][a] * (Rj[k][0] * N[b] + Rj[k][1] * N[3 + b] + Rj[k][2] * N[6 + b]);
            Q[a][b] = acc;
        }
    double pv[3], th[3];
    for (int a = 0; a < 3; ++a)
        pv[a] = (Re[0][a] * (Yj[0] - Yi[0]) + Re[1][a] * (Yj[1] - Yi[1]) + Re[2][a] * (Yj[2] - Yi[2]));
    const double c = log_so3(Q, th);  // theta = log(Q); J_r^-1 = I + 1/2 [th]x + c [th]x^2
    double d[3], x[3], dd[3], dth[3];
    const double* base;
    if (rates) {
        const double* dYi = dY + 6 * i;
        const double* dYj = dY + 6 * j;
        // omega_i in the element frame: M^T L_i dA_i; omega_j: N^T L_j dA_j
        double wi[3], wj[3], du[3];
        for (int a = 0; a < 3; ++a) {
            const double oi0 = Li[0][0] * dYi[3] + Li[0][1] * dYi[4] + Li[0][2] * dYi[5];
            const double oi1 = Li[1][0] * dYi[3] + Li[1][1] * dYi[4] + Li[1][2] * dYi[5];
            const double oi2 = Li[2][0] * dYi[3] + Li[2][1] * dYi[4] + Li[2][2] * dYi[5];
            const double oj0 = Lj[0][0] * dYj[3] + Lj[0][1] * dYj[4] + Lj[0][2] * dYj[5];
            const double oj1 = Lj[1][0] * dYj[3] + Lj[1][1] * dYj[4] + Lj[1][2] * dYj[5];
            const double oj2 = Lj[2][0] * dYj[3] + Lj[2][1] * dYj[4] + Lj[2][2] * dYj[5];
            wi[a] = M[a] * oi0 + M[3 + a] * oi1 + M[6 + a] * oi2;
            wj[a] = N[a] * oj0 + N[3 + a] * oj1 + N[6 + a] * oj2;
        }
        // u_dot = R_e^T (dr_j - dr_i) + p x w_i
        for (int a = 0; a < 3; ++a)
            du[a] = (Re[0][a] * (dYj[0] - dYi[0]) + Re[1][a] * (dYj[1] - dYi[1]) + Re[2][a] * (dYj[2] - dYi[2]));
        du[0] += pv[1] * wi[2] - pv[2] * wi[1];
        du[1] += pv[2] * wi[0] - pv[0] * wi[2];
        du[2] += pv[0] * wi[1] - pv[1] * wi[0];
        // theta_dot = J_r^-1 (w_j - Q^T w_i)
        for (int a = 0; a < 3; ++a) x[a] = wj[a] - (Q[0][a] * wi[0] + Q[1][a] * wi[1] + Q[2][a] * wi[2]);
        const double t0 = th[1] * x[2] - th[2] * x[1];
        const double t1 = th[2] * x[0] - th[0] * x[2];
        const double t2 = th[0] * x[1] - th[1] * x[0];
        const double s0 = th[1] * t2 - th[2] * t1;
        const double s1 = th[2] * t0 - th[0] * t2;
        const double s2 = th[0] * t1 - th[1] * t0;
        dd[0] = du[0];
        dd[1] = du[1];
        dd[2] = du[2];
        dth[0] = x[0] + 0.5 * t0 + c * s0;
        dth[1] = x[1] + 0.5 * t1 + c * s1;
        dth[2] = x[2] + 0.5 * t2 + c * s2;
        base = m.damping_jj;
    } else {
        for (int a = 0; a < 3; ++a) {
            dd[a] = pv[a] - m.rest_offset[a];
            dth[a] = th[a];
        }
        base = m.stiffness_jj;
    }
    double gu[3], gt[3];
    double E = 0.0;
    for (int a = 0; a < 3; ++a) {
        double su = 0.0, st = 0.0;
        for (int b = 0; b < 3; ++b) {
            su += base[6 * a + b] * dd[b] + base[6 * a + 3 + b] * dth[b];
            st += base[6 * (3 + a) + b] * dd[b] + base[6 * (3 + a) + 3 + b] * dth[b];
        }
        gu[a] = su;
        gt[a] = st;
        E += 0.5 * (dd[a] * su + dth[a] * st);
    }
    // h = J_r^-T g_theta = g - 1/2 th x g + c th x (th x g)
    const double t0 = th[1] * gt[2] - th[2] * gt[1];
    const double t1 = th[2] * gt[0] - th[0] * gt[2];
    const double t2 = th[0] * gt[1] - th[1] * gt[0];
    double h[3];
    h[0] = gt[0] - 0.5 * t0 + c * (th[1] * t2 - th[2] * t1);
    h[1] = gt[1] - 0.5 * t1 + c * (th[2] * t0 - th[0] * t2);
    h[2] = gt[2] - 0.5 * t2 + c * (th[0] * t1 - th[1] * t0);
    double* Fi = F + 6 * i;
    double* Fj = F + 6 * j;
    for (int a = 0; a < 3; ++a) {
        const double f = Re[a][0] * gu[0] + Re[a][1] * gu[1] + Re[a][2] * gu[2];
        Fj[a] += f;
        Fi[a] -= f;
    }
    // tau_e = g_u x p - Q h (element frame), tau_i = M tau_e, tau_j = N h
    d[0] = gu[1] * pv[2] - gu[2] * pv[1] - (Q[0][0] * h[0] + Q[0][1] * h[1] + Q[0][2] * h[2]);
    d[1] = gu[2] * pv[0] - gu[0] * pv[2] - (Q[1][0] * h[0] + Q[1][1] * h[1] + Q[1][2] * h[2]);
    d[2] = gu[0] * pv[1] - gu[1] * pv[0] - (Q[2][0] * h[0] + Q[2][1] * h[1] + Q[2][2] * h[2]);
    for (int a = 0; a < 3; ++a) x[a] = M[3 * a] * d[0] + M[3 * a + 1] * d[1] + M[3 * a + 2] * d[2];
    for (int a = 0; a < 3; ++a) Fi[3 + a] += Li[0][a] * x[0] + Li[1][a] * x[1] + Li[2][a] * x[2];
    for (int a = 0; a < 3; ++a) x[a] = N[3 * a] * h[0] + N[3 * a + 1] * h[1] + N[3 * a + 2] * h[2];
    for (int a = 0; a < 3; ++a) Fj[3 + a] += Lj[0][a] * x[0] + Lj[1][a] * x[1] + Lj[2][a] * x[2];
    return E;
}

double planar_matrix_element(const PlanarMatrixElement& m, int i, int j, const double* Y, const double* dY,
                             double* F, bool rates) noexcept {
    const double* Yi = Y + 3 * i;
    const double* Yj = Y + 3 * j;
    const double te = Yi[2] + m.frame_angle;
    const auto [s, c] = sin_cos(te);
    const double rx = Yj[0] - Yi[0];
    const double rz = Yj[1] - Yi[1];
    const double p0 = c * rx + s * rz;
    const double p1 = -s * rx + c * rz;
    double d0, d1, d2;
    const double* base;
    if (rates) {
        const double vx = dY[3 * j] - dY[3 * i];
        const double vz = dY[3 * j + 1] - dY[3 * i + 1];
        const double w = dY[3 * i + 2];
        d0 = c * vx + s * vz + w * p1;
        d1 = -s * vx + c * vz - w * p0;
        d2 = dY[3 * j + 2] - dY[3 * i + 2];
        base = m.damping_jj;
    } else {
        d0 = p0 - m.rest_offset[0];
        d1 = p1 - m.rest_offset[1];
        d2 = wrap_angle(Yj[2] - Yi[2] - m.rest_angle);
        base = m.stiffness_jj;
    }
    const double g0 = base[0] * d0 + base[1] * d1 + base[2] * d2;
    const double g1 = base[3] * d0 + base[4] * d1 + base[5] * d2;
    const double g2 = base[6] * d0 + base[7] * d1 + base[8] * d2;
    const double fx = c * g0 - s * g1;
    const double fz = s * g0 + c * g1;
    double* Fi = F + 3 * i;
    double* Fj = F + 3 * j;
    Fj[0] += fx;
    Fj[1] += fz;
    Fi[0] -= fx;
    Fi[1] -= fz;
    Fi[2] += g0 * p1 - g1 * p0 - g2;
    Fj[2] += g2;
    return 0.5 * (d0 * g0 + d1 * g1 + d2 * g2);
}

double linear_matrix_element(const double* K_lin, const double* D_lin, int n, int angles_from, int i, int j,
                             const double* Y, const double* dY, const double* Y_ref, double* F) noexcept {
    const int m = 2 * n;
    double E = 0.0;
    for (int a = 0; a < m; ++a) {
        const int na = a < n ? i : j;
        const int ka = a % n;
        double fa = 0.0;
        double ya = Y[n * na + ka] - Y_ref[n * na + ka];
        if (ka >= angles_from) ya = wrap_angle(ya);
        for (int b = 0; b < m; ++b) {
            const int nb = b < n ? i : j;
            const int kb = b % n;
            double yb = Y[n * nb + kb] - Y_ref[n * nb + kb];
            if (kb >= angles_from) yb = wrap_angle(yb);
            fa += K_lin[a * m + b] * yb + D_lin[a * m + b] * dY[n * nb + kb];
            E += 0.5 * ya * K_lin[a * m + b] * yb;
        }
        F[n * na + ka] += fa;
    }
    return E;
}

}  // namespace plants
