// The load-distribution QP's rows, filled in place: the one definition of each family, which
// LoadDistributionProblem (coopctrl/load_distribution/problem.py, whose docstring states the rows) and the tick call.
// They work on the stacked arrays M = [G; C] (rows 0..k-1 the wrench balance, then the inequality
// families), lo = [w_N; l], hi = [w_N; u]; matrices are row-major with a leading dimension ld (doubles per row).
#pragma once

#include <cstdint>

namespace coopctrl {

/// Moment-arm entries of G = M[:k] for the m contacts r (m, npos) [m] about r0 (npos) [m]: S(r_i - r0) spatial
/// (npos = 3, k = 6), (-d_z, d_x) planar (npos = 2, k = 3); the identity blocks are set once by the caller.
void fill_grasp_rows(double* M, int ldM, const double* r, int m, int npos, const double* r0, bool spatial) noexcept;

/// external (n) = W^{-1} G^T (G W^{-1} G^T)^{-1} w with G = M[:k], W^{-1} = diag(W_inv_diag) (n) [1/weight];
/// A (k, k, leading dimension ldA) and y (k) scratch. Returns false if G W^{-1} G^T is not positive definite.
bool pseudo_inverse_external(const double* M, int ldM, int k, const double* W_inv_diag, int n, const double* w,
                             double* external, double* A, int ldA, double* y) noexcept;

/// Virtual-linkage columns of E (k m, pairs; leading dimension ldE), pairs i < j in lexicographic order:
/// t_ij = (r_j - r_i) / |r_j - r_i| on contact i's force entries, -t_ij on j's. Returns false if two contacts
/// coincide (|r_j - r_i| < 1e-12 m).
bool fill_squeeze_basis(double* E, int ldE, const double* r, int m, int npos, int k) noexcept;

/// min_grip rows: row row0 + i holds the unit normal n_i (nrm row i, npos entries) on arm i's force entries.
void fill_grip_rows(double* M, int ldM, int row0, const double* nrm, int m, int npos, int k) noexcept;

/// friction rows (nf per contact): (cos phi_f t_1 + sin phi_f t_2 - mu_c n)^T f <= 0 spatial,
/// (+-t - mu_c n)^T f <= 0 planar (t = (-n_z, n_x)); mu_c = mu cos(pi / nf) [-]; nrm (m, ldn).
void fill_friction_rows(double* M, int ldM, int row0, const double* nrm, int ldn, int m, int k, int nf, double mu_c,
                        const double* cos_phi, const double* sin_phi, bool spatial) noexcept;

/// torque_limits rows: arm i's dofs[i] rows hold J_i^T (Jg + i * arm_stride, (k, ldJ): Jg_i[a, r]) on its
/// wrench entries, lo = -tau_qp - bias, hi = tau_qp - bias [N m] (tau_qp, bias stacked over the arms' joints).
void fill_torque_rows(double* M, double* lo, double* hi, int ldM, int row0, const double* Jg, long arm_stride,
                      int ldJ, const int64_t* dofs, int m, int k, const double* tau_qp, const double* bias) noexcept;

}  // namespace coopctrl
