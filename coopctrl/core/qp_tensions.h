// Pair tensions of an internal load on the virtual-linkage columns, which the tick's squeeze and
// coopctrl.load_distribution.grasp_matrix.pair_tensions (whose module docstring states the rank rules) run:
// s = s_des + E^+ (f - E s_des) by a one-sided Jacobi singular value decomposition of the columns E (R, P), W = E V
// with orthogonal columns of norms sigma_j (on E^T when P > R).
#pragma once

namespace coopctrl {

/// Sweeps of the one-sided Jacobi rotations at most.
constexpr int TENSION_MAX_SWEEPS = 60;
/// Columns rotated while |w_i . w_j| > TENSION_JACOBI_TOL * rows * |w_i| |w_j| (LAPACK dgesvj's rule).
constexpr double TENSION_JACOBI_TOL = 2.220446049250313e-16;
/// Columns of norm below this fraction of ||E||_F are not rotated.
constexpr double TENSION_NEGLIGIBLE = 1e-14;
/// Relative singular values at or below this are dropped (grasp_matrix.py's PAIR_ZERO_RTOL).
constexpr double PAIR_ZERO_RTOL = 1e-10;
/// Relative singular values above this are kept; in between the tensions are NaN (PAIR_KEEP_RTOL).
constexpr double PAIR_KEEP_RTOL = 1e-6;

/// The tensions s (P) [N] of the forces f on the pair columns E (R, P) into out: f_c = F[c / npos, c % npos]
/// (F (R / npos, ldF), ldF >= npos); desired (P) s_des [N]; W (max(R, P), min(R, P)), V (min, min) and sigma
/// (min) scratch. NaN where the columns are ill-conditioned. E is read, not changed.
void pair_tensions(const double* E, int R, int P, const double* F, int ldF, int npos, const double* desired,
                   double* W, double* V, double* sigma, double* out) noexcept;

}  // namespace coopctrl
