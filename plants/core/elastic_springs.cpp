#include "plants/core/elastic_springs.h"

#include <cmath>

#include "plants/core/elastic_rotation.h"

namespace plants {

using elastic_detail::log_so3;
using elastic_detail::wrap_angle;

int central_spring(const SpatialSpring& s, int i, int j, const double* Y, const NodeFrames* frames, double* F,
                   double& Pi) noexcept {
    const double* Yi = Y + 6 * i;
    const double* Yj = Y + 6 * j;
    const double d0 = Yi[0] - Yj[0];
    const double d1 = Yi[1] - Yj[1];
    const double d2 = Yi[2] - Yj[2];
    const double Q = s.stiffness[0] * d0 * d0 + s.stiffness[1] * d1 * d1 + s.stiffness[2] * d2 * d2;
    const double l = s.rest_length;
    double a, g2;
    if (l > 0.0) {
        const double dist = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
        if (dist < COINCIDENT_FRACTION * l) return ELASTIC_COINCIDENT_NODES;
        const double g = 1.0 - l / dist;
        a = g * l * Q / (dist * dist * dist);
        g2 = g * g;
    } else {
        a = 0.0;
        g2 = 1.0;
    }
    Pi += 0.5 * g2 * Q;
    const double f0 = a * d0 + g2 * s.stiffness[0] * d0;
    const double f1 = a * d1 + g2 * s.stiffness[1] * d1;
    const double f2 = a * d2 + g2 * s.stiffness[2] * d2;
    double* Fi = F + 6 * i;
    double* Fj = F + 6 * j;
    Fi[0] += f0;
    Fi[1] += f1;
    Fi[2] += f2;
    Fj[0] -= f0;
    Fj[1] -= f1;
    Fj[2] -= f2;
    if (s.rotation_form != ROTATION_BOOK) {
        if (s.torsion[0] != 0.0 || s.torsion[1] != 0.0 || s.torsion[2] != 0.0)
            Pi += geodesic_rotation(s, i, j, frames, F);
        return ELASTIC_OK;
    }
    for (int k = 0; k < 3; ++k) {
        const double cA = s.torsion[k];
        if (cA != 0.0) {
            const double dl = wrap_angle(Yi[3 + k] - Yj[3 + k] - s.rest_angles[k]);
            Pi += 0.5 * cA * dl * dl;
            Fi[3 + k] += cA * dl;
            Fj[3 + k] -= cA * dl;
        }
    }
    return ELASTIC_OK;
}

void offset_spring(const SpatialSpring& s, int i, int j, const double* Y, const NodeFrames* frames, double* F,
                   double& Pi) noexcept {
    const double(&Ri)[3][3] = frames[i].R;
    const double(&dRi)[3][3][3] = frames[i].dR;
    double* Fi = F + 6 * i;
    double* Fj = F + 6 * j;
    double d[3], Ce[3];
    for (int k = 0; k < 3; ++k) d[k] = Y[6 * j + k] - Y[6 * i + k];
    for (int k = 0; k < 3; ++k) {
        const double ek = Ri[0][k] * d[0] + Ri[1][k] * d[1] + Ri[2][k] * d[2] - s.rest_offset[k];
        Pi += 0.5 * s.stiffness[k] * ek * ek;
        Ce[k] = s.stiffness[k] * ek;
    }
    for (int l = 0; l < 3; ++l) {
        const double f = Ri[l][0] * Ce[0] + Ri[l][1] * Ce[1] + Ri[l][2] * Ce[2];
        Fj[l] += f;
        Fi[l] -= f;
    }
    for (int a = 0; a < 3; ++a) {
        double acc = 0.0;
        for (int k = 0; k < 3; ++k)
            for (int l = 0; l < 3; ++l) acc += Ce[k] * dRi[a][l][k] * d[l];
        Fi[3 + a] += acc;
    }
    if (s.rotation_form != ROTATION_BOOK) {
        if (s.torsion[0] != 0.0 || s.torsion[1] != 0.0 || s.torsion[2] != 0.0)
            Pi += geodesic_rotation(s, i, j, frames, F);
    } else if (s.kappa[0] != 0.0 || s.kappa[1] != 0.0 || s.kappa[2] != 0.0) {
        const double(&Rj)[3][3] = frames[j].R;
        const double(&dRj)[3][3][3] = frames[j].dR;
        const double* R0 = s.rest_rotation;
        // P = R_j R0^T; QR = (R_i Kd) R0
        double P[3][3], QR[3][3];
        for (int l = 0; l < 3; ++l)
            for (int k = 0; k < 3; ++k) {
                double s1 = 0.0, s2 = 0.0;
                for (int n = 0; n < 3; ++n) {
                    s1 += Rj[l][n] * R0[3 * k + n];
                    s2 += Ri[l][n] * s.kappa[n] * R0[3 * n + k];
                }
                P[l][k] = s1;
                QR[l][k] = s2;
            }
        for (int k = 0; k < 3; ++k) {
            const double Mkk = Ri[0][k] * P[0][k] + Ri[1][k] * P[1][k] + Ri[2][k] * P[2][k];
            Pi += s.kappa[k] * (1.0 - Mkk);
        }
        for (int a = 0; a < 3; ++a) {
            double gi = 0.0, gj = 0.0;
            for (int l = 0; l < 3; ++l)
                for (int k = 0; k < 3; ++k) {
                    gi += s.kappa[k] * dRi[a][l][k] * P[l][k];
                    gj += dRj[a][l][k] * QR[l][k];
                }
            Fi[3 + a] -= gi;
            Fj[3 + a] -= gj;
        }
    }
}

double geodesic_rotation(const SpatialSpring& s, int i, int j, const NodeFrames* frames, double* F) noexcept {
    const double(&Ri)[3][3] = frames[i].R;
    const double(&Rj)[3][3] = frames[j].R;
    const double(&Li)[3][3] = frames[i].L;
    const double(&Lj)[3][3] = frames[j].L;
    const double* R0 = s.rest_rotation;
    double P[3][3], Dl[3][3];
    for (int l = 0; l < 3; ++l)
        for (int k = 0; k < 3; ++k)
            P[l][k] = Rj[l][0] * R0[3 * k] + Rj[l][1] * R0[3 * k + 1] + Rj[l][2] * R0[3 * k + 2];
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) Dl[a][b] = Ri[0][a] * P[0][b] + Ri[1][a] * P[1][b] + Ri[2][a] * P[2][b];
    double e[3];
    const double c = log_so3(Dl, e);  // e = log(Delta); J_r^-1 = I + 1/2 [e]x + c [e]x^2
    const double g0 = s.torsion[2] * e[0];
    const double g1 = s.torsion[1] * e[1];
    const double g2 = s.torsion[0] * e[2];
    const double E = 0.5 * (e[0] * g0 + e[1] * g1 + e[2] * g2);
    // h = J_r^-T g = g - 1/2 e x g + c e x (e x g)
    const double t0 = e[1] * g2 - e[2] * g1;
    const double t1 = e[2] * g0 - e[0] * g2;
    const double t2 = e[0] * g1 - e[1] * g0;
    double h[3], tq[3];
    h[0] = g0 - 0.5 * t0 + c * (e[1] * t2 - e[2] * t1);
    h[1] = g1 - 0.5 * t1 + c * (e[2] * t0 - e[0] * t2);
    h[2] = g2 - 0.5 * t2 + c * (e[0] * t1 - e[1] * t0);
    for (int a = 0; a < 3; ++a) tq[a] = R0[a] * h[0] + R0[3 + a] * h[1] + R0[6 + a] * h[2];  // tau_j = R0^T h
    for (int a = 0; a < 3; ++a) F[6 * j + 3 + a] += Lj[0][a] * tq[0] + Lj[1][a] * tq[1] + Lj[2][a] * tq[2];
    for (int a = 0; a < 3; ++a) tq[a] = -(Dl[a][0] * h[0] + Dl[a][1] * h[1] + Dl[a][2] * h[2]);  // tau_i = -Delta h
    for (int a = 0; a < 3; ++a) F[6 * i + 3 + a] += Li[0][a] * tq[0] + Li[1][a] * tq[1] + Li[2][a] * tq[2];
    return E;
}

void spring_dampers(const SpatialSpring& s, const ElasticEdge& edge, const double* Y, const double* dY,
                    const NodeFrames* frames, double* F, double& D) noexcept {
    const int i = static_cast<int>(edge.i), j = static_cast<int>(edge.j);
    const bool book = edge.damping_form == DAMPING_BOOK;
    const bool central = edge.kind == ELEMENT_CENTRAL;
    const double dd = s.damping;
    const double dA = s.torsion_damping;
    const double(&Ri)[3][3] = frames[i].R;
    const double(&Li)[3][3] = frames[i].L;
    const double* Yi = Y + 6 * i;
    const double* Yj = Y + 6 * j;
    const double* dYi = dY + 6 * i;
    const double* dYj = dY + 6 * j;
    double* Fi = F + 6 * i;
    double* Fj = F + 6 * j;
    if (dd != 0.0) {
        const double v0 = dYi[0] - dYj[0];
        const double v1 = dYi[1] - dYj[1];
        const double v2 = dYi[2] - dYj[2];
        const double d0 = Yi[0] - Yj[0];
        const double d1 = Yi[1] - Yj[1];
        const double d2 = Yi[2] - Yj[2];
        const double dist = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
        double f0, f1, f2;
        if (central && dist > 1e-12) {
            const double vu = (v0 * d0 + v1 * d1 + v2 * d2) / dist;
            D += 0.5 * dd * vu * vu;
            const double f = dd * vu / dist;
            f0 = f * d0;
            f1 = f * d1;
            f2 = f * d2;
        } else if (central || book) {
            D += 0.5 * dd * (v0 * v0 + v1 * v1 + v2 * v2);
            f0 = dd * v0;
            f1 = dd * v1;
            f2 = dd * v2;
        } else {
            // rho = R_i^T (r_j - r_i), omega_i = L_i dA_i, e_dot = R_i^T (dr_j - dr_i) + rho x omega_i
            double rho[3], om[3], g[3];
            for (int k = 0; k < 3; ++k) {
                rho[k] = -(Ri[0][k] * d0 + Ri[1][k] * d1 + Ri[2][k] * d2);
                om[k] = Li[k][0] * dYi[3] + Li[k][1] * dYi[4] + Li[k][2] * dYi[5];
            }
            for (int k = 0; k < 3; ++k) g[k] = -(Ri[0][k] * v0 + Ri[1][k] * v1 + Ri[2][k] * v2);
            g[0] += rho[1] * om[2] - rho[2] * om[1];
            g[1] += rho[2] * om[0] - rho[0] * om[2];
            g[2] += rho[0] * om[1] - rho[1] * om[0];
            D += 0.5 * dd * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            for (int k = 0; k < 3; ++k) g[k] *= dd;
            // force on node i: -(R_i g); node j gets its opposite below
            f0 = -(Ri[0][0] * g[0] + Ri[0][1] * g[1] + Ri[0][2] * g[2]);
            f1 = -(Ri[1][0] * g[0] + Ri[1][1] * g[1] + Ri[1][2] * g[2]);
            f2 = -(Ri[2][0] * g[0] + Ri[2][1] * g[1] + Ri[2][2] * g[2]);
            // d(rho x omega)/d omega = S(rho): generalized force L_i^T (g x rho)
            const double c0 = g[1] * rho[2] - g[2] * rho[1];
            const double c1 = g[2] * rho[0] - g[0] * rho[2];
            const double c2 = g[0] * rho[1] - g[1] * rho[0];
            for (int a = 0; a < 3; ++a) Fi[3 + a] += Li[0][a] * c0 + Li[1][a] * c1 + Li[2][a] * c2;
        }
        Fi[0] += f0;
        Fi[1] += f1;
        Fi[2] += f2;
        Fj[0] -= f0;
        Fj[1] -= f1;
        Fj[2] -= f2;
    }
    if (dA != 0.0) {
        if (book) {
            for (int k = 0; k < 3; ++k) {
                const double v = dYi[3 + k] - dYj[3 + k];
                D += 0.5 * dA * v * v;
                Fi[3 + k] += dA * v;
                Fj[3 + k] -= dA * v;
            }
        } else {
            const double(&Rj)[3][3] = frames[j].R;
            const double(&Lj)[3][3] = frames[j].L;
            // world angular velocities, their difference in node j's frame
            double wi[3], wj[3], Wd[3], h[3], Hw[3], Hi[3];
            for (int k = 0; k < 3; ++k) {
                wi[k] = Li[k][0] * dYi[3] + Li[k][1] * dYi[4] + Li[k][2] * dYi[5];
                wj[k] = Lj[k][0] * dYj[3] + Lj[k][1] * dYj[4] + Lj[k][2] * dYj[5];
            }
            for (int l = 0; l < 3; ++l)
                Wd[l] = (Rj[l][0] * wj[0] + Rj[l][1] * wj[1] + Rj[l][2] * wj[2] - Ri[l][0] * wi[0] - Ri[l][1] * wi[1]
                         - Ri[l][2] * wi[2]);
            for (int k = 0; k < 3; ++k) {  // dA omega_rel, omega_rel = R_j^T (omega_j^w - omega_i^w)
                h[k] = Rj[0][k] * Wd[0] + Rj[1][k] * Wd[1] + Rj[2][k] * Wd[2];
                D += 0.5 * dA * h[k] * h[k];
            }
            for (int k = 0; k < 3; ++k) h[k] *= dA;
            // node j: L_j^T h; node i: -L_i^T R_i^T R_j h
            for (int l = 0; l < 3; ++l) Hw[l] = Rj[l][0] * h[0] + Rj[l][1] * h[1] + Rj[l][2] * h[2];
            for (int k = 0; k < 3; ++k) Hi[k] = Ri[0][k] * Hw[0] + Ri[1][k] * Hw[1] + Ri[2][k] * Hw[2];
            for (int a = 0; a < 3; ++a) {
                Fj[3 + a] += Lj[0][a] * h[0] + Lj[1][a] * h[1] + Lj[2][a] * h[2];
                Fi[3 + a] -= Li[0][a] * Hi[0] + Li[1][a] * Hi[1] + Li[2][a] * Hi[2];
            }
        }
    }
}

void linear_spring(const SpatialSpring& s, int i, int j, const double* Y, const double* dY, const double* Y_ref,
                   double* F, double& Pi) noexcept {
    for (int k = 0; k < 6; ++k) {
        double diff = (Y[6 * i + k] - Y_ref[6 * i + k]) - (Y[6 * j + k] - Y_ref[6 * j + k]);
        double kk, dk;
        if (k >= 3) {
            kk = s.torsion[k - 3];
            diff = wrap_angle(diff);  // a common rotation is a zero mode, also across +-pi
            dk = s.torsion_damping;
        } else {
            kk = s.stiffness[k];
            dk = s.damping;
        }
        Pi += 0.5 * kk * diff * diff;
        const double f = kk * diff + dk * (dY[6 * i + k] - dY[6 * j + k]);
        F[6 * i + k] += f;
        F[6 * j + k] -= f;
    }
}

}  // namespace plants
