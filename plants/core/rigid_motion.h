// The nominal motion of the loaded state (148): the contact nodes carried rigidly by the object,
// r_j = r_0 + R_0 rho_0j, R_j = R(A_0) R(A_0j) (rotations composed, the ZYX angles extracted), with their rates and
// accelerations (plants/cooperative/loaded_state.py, expression for expression).
#pragma once

namespace plants {

/// The body angular velocity w = L(A) dA [rad/s] and acceleration dw = L(A) ddA + dL(A, dA) dA [rad/s^2] of the
/// ZYX angles A [rad] with rates dA and accelerations ddA (3 each).
void body_rates(const double* A, const double* dA, const double* ddA, double* w, double* dw) noexcept;

/// (Y, dY, ddY), each (m + 1, 6) row-major, of the object (row 0: Y0, dY0, ddY0) and its m contact nodes at the
/// grasps G (m, 6: the offset rho_0j [m] and the relative ZYX angles A_0j [rad]):
/// dr_j = dr_0 + omega x d, ddr_j = ddr_0 + alpha x d + omega x (omega x d), d = R_0 rho_0j, omega = R_0 L(A_0) dA_0,
/// alpha = R_0 (L ddA_0 + dL dA_0); dA_j = L(A_j)^-1 R_j^T omega, ddA_j = L(A_j)^-1 (R_j^T alpha - dL_j dA_j).
/// Returns the first node (1..m) whose frame is at the Euler singularity (its angle rates set to zero), or -1.
int spatial_motion(const double* Y0, const double* dY0, const double* ddY0, const double* G, int m, double* Y,
                   double* dY, double* ddY) noexcept;

/// The same in the x-z plane: Y0 = (x, z, theta), G (m, 3) = (dx, dz, dtheta) in the object frame; (m + 1, 3) each.
void planar_motion(const double* Y0, const double* dY0, const double* ddY0, const double* G, int m, double* Y,
                   double* dY, double* ddY) noexcept;

}  // namespace plants
