// The check of a QP answer and its binding families (the rule: coopctrl/load_distribution/answer_check.py's
// docstring; docs/model.md section 6). M (rows, ldM) row-major = [G; C], k balance rows.
#pragma once

#include <cstdint>

namespace coopctrl {

/// Bits of the binding-families mask (answer_check.py's FAMILY_*), in the row order of the problem.
constexpr int64_t FAMILY_MIN_GRIP = 1;
constexpr int64_t FAMILY_FRICTION = 2;
constexpr int64_t FAMILY_TORQUE = 4;

/// The largest violation *viol of lo <= M x <= hi (balance rows included) and the scale *scale = max |M x|
/// [N, N m] of the answer x[:n].
void answer_violation(const double* M, int ldM, int rows, const double* lo, const double* hi, const double* x, int n,
                      double* viol, double* scale) noexcept;

/// tol [N, N m] for an answer of violation viol and scale scale: 100 eps_abs (1 + scale), capped by rho L
/// (L = max(1, |w_N|_inf, finite |l|, |u|)) when viol exceeds min(that, rho).
double answer_tolerance(const double* lo, const double* hi, int rows, int k, double viol, double scale,
                        double eps_abs, double rho) noexcept;

/// Whether x[:n] is finite and within answer_tolerance of lo <= M x <= hi.
bool answer_ok(const double* M, int ldM, int rows, const double* lo, const double* hi, const double* x, int n, int k,
               double eps_abs, double rho) noexcept;

/// The mask of the families with |z[z0 + r]| > 1e-7 (1 + max |g[:n]|) on an inequality row r < n_in: rows
/// row_grip .. + m min_grip, row_fric .. + m n_fric friction, row_tau .. torque_limits (-1: the family is off).
int64_t binding_families(const double* g, const double* z, int z0, int n, int n_in, int m, int64_t row_grip,
                         int64_t row_fric, int64_t n_fric, int64_t row_tau) noexcept;

}  // namespace coopctrl
