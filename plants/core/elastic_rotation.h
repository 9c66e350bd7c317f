// Small rotation helpers of the elastic kernels (docs/model.md s.2-3), inline: the angle wrap, log on SO(3), and
// R(A) = Rz(psi) Ry(theta) Rx(phi) with its partials, in plants::elastic_detail. The rotation and the Euler
// singularity's bound are private copies of plants/frames.py's (the arms' port brings plants/core/frames.h; the
// elastic kernels are to use it once both are on main).
#pragma once

#include <cmath>

namespace plants::elastic_detail {

constexpr double PI = 3.141592653589793;

/// The ZYX Euler singularity: |cos theta| below this and L(A) is not invertible (plants.frames.EULER_SINGULARITY_COS).
constexpr double EULER_SINGULARITY_COS = 1e-6;

/// An angle difference [rad] mapped into (-pi, pi].
inline double wrap_angle(double a) noexcept { return a - 2.0 * PI * std::floor((a + PI) / (2.0 * PI)); }

/// The rotation vector out = log(Q) [rad] of the rotation Q, and the coefficient c of the inverse right Jacobian
/// J_r^-1(out) = I + 1/2 [out]x + c [out]x^2; returns c. phi = atan2(|v|, tr Q - 1), v = vee(Q - Q^T) =
/// 2 sin(phi) u, log Q = phi v / |v|, c = 1/phi^2 - (1 + cos phi) / (2 phi sin phi); series near phi = 0.
inline double log_so3(const double Q[3][3], double out[3]) noexcept {
    const double v0 = Q[2][1] - Q[1][2];
    const double v1 = Q[0][2] - Q[2][0];
    const double v2 = Q[1][0] - Q[0][1];
    const double sv = std::sqrt(v0 * v0 + v1 * v1 + v2 * v2);  // 2 sin(phi)
    const double tr1 = Q[0][0] + Q[1][1] + Q[2][2] - 1.0;      // 2 cos(phi)
    const double ang = std::atan2(sv, tr1);
    const double fac = ang < 1e-4 ? 0.5 * (1.0 + ang * ang / 6.0) : ang / sv;
    out[0] = fac * v0;
    out[1] = fac * v1;
    out[2] = fac * v2;
    const double a2 = ang * ang;
    if (ang < 1e-3) return 1.0 / 12.0 + a2 / 720.0 + a2 * a2 / 30240.0;
    return 1.0 / a2 - (1.0 + 0.5 * tr1) / (ang * sv);
}

/// R(A) and dR/dpsi, dR/dtheta, dR/dphi from the cosines and sines of A = (psi, theta, phi).
inline void rotation_and_partials_from_trig(double cps, double sps, double cth, double sth, double cph, double sph,
                                            double R[3][3], double dpsi[3][3], double dth[3][3],
                                            double dph[3][3]) noexcept {
    R[0][0] = cps * cth;
    R[0][1] = cps * sth * sph - sps * cph;
    R[0][2] = cps * sth * cph + sps * sph;
    R[1][0] = sps * cth;
    R[1][1] = sps * sth * sph + cps * cph;
    R[1][2] = sps * sth * cph - cps * sph;
    R[2][0] = -sth;
    R[2][1] = cth * sph;
    R[2][2] = cth * cph;
    dpsi[0][0] = -sps * cth;
    dpsi[0][1] = -sps * sth * sph - cps * cph;
    dpsi[0][2] = -sps * sth * cph + cps * sph;
    dpsi[1][0] = cps * cth;
    dpsi[1][1] = cps * sth * sph - sps * cph;
    dpsi[1][2] = cps * sth * cph + sps * sph;
    dpsi[2][0] = 0.0;
    dpsi[2][1] = 0.0;
    dpsi[2][2] = 0.0;
    dth[0][0] = -cps * sth;
    dth[0][1] = cps * cth * sph;
    dth[0][2] = cps * cth * cph;
    dth[1][0] = -sps * sth;
    dth[1][1] = sps * cth * sph;
    dth[1][2] = sps * cth * cph;
    dth[2][0] = -cth;
    dth[2][1] = -sth * sph;
    dth[2][2] = -sth * cph;
    dph[0][0] = 0.0;
    dph[1][0] = 0.0;
    dph[2][0] = 0.0;
    dph[0][1] = cps * sth * cph + sps * sph;
    dph[0][2] = -cps * sth * sph + sps * cph;
    dph[1][1] = sps * sth * cph - cps * sph;
    dph[1][2] = -sps * sth * sph - cps * cph;
    dph[2][1] = cth * cph;
    dph[2][2] = -cth * sph;
}

}  // namespace plants::elastic_detail
