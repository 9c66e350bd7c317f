// The small dense solves the QP's assembly and the control laws share (ported line by line from the numba kernels
// they replaced: the same bits): the LU factorization and solves, and the redundant arm's dynamically consistent
// joint acceleration; the Cholesky solve is plants/core/cholesky.h's. Matrices are row-major with a leading
// dimension (doubles from one row to the next), so that the leading block of a larger array can be passed.
#pragma once

#include <cstdint>

namespace coopctrl {

/// Gaussian elimination with partial pivoting of A[:n, :n] into LU (multipliers below the diagonal, U above,
/// the reciprocals 1 / U_cc on it) and the row swaps piv[:n]. Returns false for a pivot <= 1e-13 max |A|.
bool lu_factor(const double* A, int lda, int n, double* LU, int ldlu, int64_t* piv) noexcept;

/// x[:n] = A^{-1} b from lu_factor's (LU, piv); b and x may alias.
void lu_solve_factored(const double* LU, int ldlu, const int64_t* piv, int n, const double* b, double* x) noexcept;

/// Solve A[:n, :n] x = b[:n] (LU, piv scratch); false (x unspecified) for a singular A.
bool lu_solve(const double* A, int lda, const double* b, int n, double* LU, int ldlu, int64_t* piv,
              double* x) noexcept;

/// qdd[:n] = J^# rhs, the inertia-weighted generalized inverse of a redundant arm: N = H + J^T W J,
/// X = N^{-1} J^T, A = J X, qdd = X A^{-1} rhs. W (p, p) [kg, kg m^2], H (n, n) [kg m^2], J (p, n);
/// wv: WORK_VECTORS rows of ldw doubles, wm: WORK_MATRICES (ldw, ldw) matrices (control_work's scratch).
/// Returns false (qdd zero) when N or A is singular.
bool consistent_acceleration(const double* W, int ldW, const double* H, int ldH, const double* J, int ldJ, int p,
                             const double* rhs, int n, double* wv, double* wm, int ldw, int64_t* piv,
                             double* qdd) noexcept;

/// Rows of the vector scratch and matrices of the matrix scratch consistent_acceleration uses (control_work).
constexpr int WORK_VECTORS = 8;
constexpr int WORK_MATRICES = 4;

}  // namespace coopctrl
