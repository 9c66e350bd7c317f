// Frames (docs/model.md s.2): ZYX Euler angles A = (psi, theta, phi) [rad], the rotation
//   R(A) = Rz(psi) Ry(theta) Rx(phi),
// the body-rate map omega_body = L(A) dA/dt with
//   L(A) = [[-s_theta, 0, 1], [s_phi c_theta, c_phi, 0], [c_phi c_theta, -s_phi, 0]],
// its time derivative and inverse (singular at cos(theta) = 0), and the planar rotation in the x-z plane.
// plants/frames.py's kernels ported line by line (the same expressions in the same order, so the same bits).
// Every 3x3 matrix is 9 doubles, row-major.
#pragma once

#include <cmath>

namespace plants {

/// The sine and cosine of one angle.
struct SinCos {
    double s;  ///< sin(a)
    double c;  ///< cos(a)
};

/// sin(a) and cos(a) [a in rad] in one call: glibc's sincos (the same bits as its sin and cos, in about the time of
/// one of them), elsewhere std::sin and std::cos.
inline SinCos sin_cos(double a) noexcept {
    SinCos r;
#if defined(__GLIBC__)
    ::sincos(a, &r.s, &r.c);
#else
    r.s = std::sin(a);
    r.c = std::cos(a);
#endif
    return r;
}

/// Smallest |cos(theta)| [-] at which L(A)^-1 is still evaluated (plants.frames.EULER_SINGULARITY_COS).
constexpr double EULER_SINGULARITY_COS = 1e-6;

/// The three partials dR/dpsi, dR/dtheta, dR/dphi of R(A) from the cosines and sines of A.
inline void rotation_zyx_partials_from_trig(double cps, double sps, double cth, double sth, double cph, double sph,
                                            double* dpsi, double* dth, double* dph) noexcept {
    dpsi[0] = -sps * cth;
    dpsi[1] = -sps * sth * sph - cps * cph;
    dpsi[2] = -sps * sth * cph + cps * sph;
    dpsi[3] = cps * cth;
    dpsi[4] = cps * sth * sph - sps * cph;
    dpsi[5] = cps * sth * cph + sps * sph;
    dpsi[6] = 0.0;
    dpsi[7] = 0.0;
    dpsi[8] = 0.0;
    dth[0] = -cps * sth;
    dth[1] = cps * cth * sph;
    dth[2] = cps * cth * cph;
    dth[3] = -sps * sth;
    dth[4] = sps * cth * sph;
    dth[5] = sps * cth * cph;
    dth[6] = -cth;
    dth[7] = -sth * sph;
    dth[8] = -sth * cph;
    dph[0] = 0.0;
    dph[3] = 0.0;
    dph[6] = 0.0;
    dph[1] = cps * sth * cph + sps * sph;
    dph[2] = -cps * sth * sph + sps * cph;
    dph[4] = sps * sth * cph - cps * sph;
    dph[5] = -sps * sth * sph - cps * cph;
    dph[7] = cth * cph;
    dph[8] = -cth * sph;
}

/// R(A) from the cosines and sines of A = (psi, theta, phi).
inline void rotation_zyx_from_trig(double cps, double sps, double cth, double sth, double cph, double sph,
                                   double* R) noexcept {
    R[0] = cps * cth;
    R[1] = cps * sth * sph - sps * cph;
    R[2] = cps * sth * cph + sps * sph;
    R[3] = sps * cth;
    R[4] = sps * sth * sph + cps * cph;
    R[5] = sps * sth * cph - cps * sph;
    R[6] = -sth;
    R[7] = cth * sph;
    R[8] = cth * cph;
}

/// R = R(A) = Rz(psi) Ry(theta) Rx(phi) for A = (psi, theta, phi) [rad].
inline void rotation_zyx(const double* A, double* R) noexcept {
    const auto [sps, cps] = sin_cos(A[0]);
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    rotation_zyx_from_trig(cps, sps, cth, sth, cph, sph, R);
}

/// (dR/dpsi, dR/dtheta, dR/dphi) of R(A), exact.
inline void rotation_zyx_partials(const double* A, double* dpsi, double* dth, double* dph) noexcept {
    const auto [sps, cps] = sin_cos(A[0]);
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    rotation_zyx_partials_from_trig(cps, sps, cth, sth, cph, sph, dpsi, dth, dph);
}

/// R(A) and its three partials (dR: 27 doubles, dR/dpsi, dR/dtheta, dR/dphi) from one evaluation of the six
/// sines and cosines.
inline void rotation_zyx_and_partials(const double* A, double* R, double* dR) noexcept {
    const auto [sps, cps] = sin_cos(A[0]);
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    rotation_zyx_from_trig(cps, sps, cth, sth, cph, sph, R);
    rotation_zyx_partials_from_trig(cps, sps, cth, sth, cph, sph, dR, dR + 9, dR + 18);
}

/// The ZYX Euler angles A = (psi, theta, phi) [rad] of a rotation matrix R, theta in [-pi/2, pi/2]:
/// psi = atan2(R10, R00), theta = atan2(-R20, sqrt(R21^2 + R22^2)), phi = atan2(R21, R22).
inline void euler_zyx_from_rotation(const double* R, double* A) noexcept {
    A[0] = std::atan2(R[3], R[0]);
    A[1] = std::atan2(-R[6], std::sqrt(R[7] * R[7] + R[8] * R[8]));
    A[2] = std::atan2(R[7], R[8]);
}

/// The rotation vector [rad] of the rotation matrix M into out (3): M's unit quaternion (w, v) (Shepperd's
/// choice of the largest of trace, M00, M11, M22), w >= 0, theta = 2 atan2(|v|, w), out = theta / sin(theta/2) v,
/// with theta / sin(theta/2) = 2 + theta^2/12 + 7 theta^4/2880 for theta <= 1e-3 (plants.frames.rotation_vector_into).
void rotation_vector(const double* M, double* out) noexcept;

/// L = L(A) with omega_body = L(A) dA/dt (105).
inline void body_rate_map(const double* A, double* L) noexcept {
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    for (int i = 0; i < 9; ++i) L[i] = 0.0;
    L[0] = -sth;
    L[2] = 1.0;
    L[3] = sph * cth;
    L[4] = cph;
    L[6] = cph * cth;
    L[7] = -sph;
}

/// Ld = dL/dt at the angles A [rad] and the Euler rates dA [rad/s].
inline void body_rate_map_dot(const double* A, const double* dA, double* Ld) noexcept {
    const auto [sth, cth] = sin_cos(A[1]);
    const auto [sph, cph] = sin_cos(A[2]);
    const double dth = dA[1], dph = dA[2];
    for (int i = 0; i < 9; ++i) Ld[i] = 0.0;
    Ld[0] = -cth * dth;
    Ld[3] = cph * cth * dph - sph * sth * dth;
    Ld[4] = -sph * dph;
    Ld[6] = -sph * cth * dph - cph * sth * dth;
    Ld[7] = -cph * dph;
}

/// Linv = L(A)^-1 = [[0, s_phi/c_theta, c_phi/c_theta], [0, c_phi, -s_phi], [1, s_phi t_theta, c_phi t_theta]];
/// returns false (Linv untouched) where |cos(theta)| < EULER_SINGULARITY_COS.
inline bool body_rate_map_inverse(const double* A, double* Linv) noexcept {
    const auto [sth, cth] = sin_cos(A[1]);
    if (std::abs(cth) < EULER_SINGULARITY_COS) return false;
    const auto [sph, cph] = sin_cos(A[2]);
    const double tth = sth / cth;
    Linv[0] = 0.0;
    Linv[1] = sph / cth;
    Linv[2] = cph / cth;
    Linv[3] = 0.0;
    Linv[4] = cph;
    Linv[5] = -sph;
    Linv[6] = 1.0;
    Linv[7] = sph * tth;
    Linv[8] = cph * tth;
    return true;
}

/// R (2x2, row-major) = the rotation by theta [rad] in the (x, z) plane, from +x towards +z.
inline void rotation_planar(double theta, double* R) noexcept {
    const auto [s, c] = sin_cos(theta);
    R[0] = c;
    R[1] = -s;
    R[2] = s;
    R[3] = c;
}

}  // namespace plants
