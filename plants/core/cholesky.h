// The Cholesky solve of the small symmetric positive-definite blocks (an arm's N_i, the QP's grasp blocks), written
// as plain loops (the small blocks gain nothing from a library call).
#pragma once

namespace plants {

/// Solve A x = b for the symmetric positive-definite leading n x n block of A (row length lda; its lower
/// triangle, diagonal included, read and overwritten by the factor L, A = L L^T). Returns false (x undefined)
/// if A is not positive definite.
bool cholesky_solve(double* A, int lda, const double* b, double* x, int n) noexcept;

}  // namespace plants
