// The ZYX Euler rotation and body-rate map the QP's inputs use, ported line by line from plants/frames.py
// (rotation_zyx_into) and plants/cooperative/loaded_state.py (body_rate_map_into): the same bits. R, L are 3 x 3
// row-major; A = (psi, theta, phi) [rad].
#pragma once

#include <cmath>

namespace coopctrl {

/// R(A) = Rz(psi) Ry(theta) Rx(phi).
inline void rotation_zyx(const double* A, double* R) noexcept {
    const double cps = std::cos(A[0]), sps = std::sin(A[0]);
    const double cth = std::cos(A[1]), sth = std::sin(A[1]);
    const double cph = std::cos(A[2]), sph = std::sin(A[2]);
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

/// L(A), the body-rate map: omega_body = L(A) dA/dt.
inline void body_rate_map(const double* A, double* L) noexcept {
    const double cth = std::cos(A[1]), sth = std::sin(A[1]);
    const double cph = std::cos(A[2]), sph = std::sin(A[2]);
    L[0] = -sth;
    L[1] = 0.0;
    L[2] = 1.0;
    L[3] = sph * cth;
    L[4] = cph;
    L[5] = 0.0;
    L[6] = cph * cth;
    L[7] = -sph;
    L[8] = 0.0;
}

}  // namespace coopctrl
