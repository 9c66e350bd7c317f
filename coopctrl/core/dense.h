// Small dense linear algebra of the loop's stages, on row-major arrays, allocation-free.
#pragma once

namespace coopctrl {

/// max_c |v_c|, NaN if an entry is NaN (as float(np.abs(v).max())).
double max_abs(const double* v, int n) noexcept;

/// M = A^-1 (n x n) by LU factorization with partial pivoting (LU receives the factors). Returns false, M
/// undefined, when a pivot is exactly zero (where LAPACK's getrf reports a singular matrix).
bool invert_into(const double* A, int n, double* LU, double* M) noexcept;

/// M = pinv(A) (n x n), the Moore-Penrose pseudo-inverse: the singular values below 1e-15 times the largest are
/// dropped (numpy's default). By one-sided Jacobi rotations; work holds 2 n^2 + n doubles. M is NaN when A is
/// not finite.
void pinv_into(const double* A, int n, double* M, double* work) noexcept;

}  // namespace coopctrl
