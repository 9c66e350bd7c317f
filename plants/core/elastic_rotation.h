// Small rotation helpers of the elastic kernels (docs/model.md s.2-3), inline: the angle wrap, log on SO(3), and
// R(A) = Rz(psi) Ry(theta) Rx(phi) with its partials (plants/core/frames.h's), in plants::elastic_detail.
#pragma once

#include <cmath>

#include "plants/core/frames.h"

namespace plants::elastic_detail {

constexpr double PI = 3.141592653589793;

/// The ZYX Euler singularity: |cos theta| below this and L(A) is not invertible.
using plants::EULER_SINGULARITY_COS;
using plants::rotation_zyx_from_trig;
using plants::rotation_zyx_partials_from_trig;

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

/// R(A) and dR/dpsi, dR/dtheta, dR/dphi from the cosines and sines of A = (psi, theta, phi) (plants/core/frames.h's,
/// on the elastic kernels' 3 x 3 arrays).
inline void rotation_and_partials_from_trig(double cps, double sps, double cth, double sth, double cph, double sph,
                                            double R[3][3], double dpsi[3][3], double dth[3][3],
                                            double dph[3][3]) noexcept {
    rotation_zyx_from_trig(cps, sps, cth, sth, cph, sph, &R[0][0]);
    rotation_zyx_partials_from_trig(cps, sps, cth, sth, cph, sph, &dpsi[0][0], &dth[0][0], &dph[0][0]);
}

}  // namespace plants::elastic_detail
