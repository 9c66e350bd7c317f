// The Goldfarb-Idnani dual active-set QP solver, warm started (coopctrl/load_distribution/goldfarb_idnani.py,
// whose module docstring derives the method): min 1/2 x^T H x + g^T x s.t. M[:n_eq] x = lo[:n_eq] and
// lo <= M x <= hi on the rows n_eq.. (ported line by line from the numba kernel it replaced: the same bits).
#pragma once

#include <cstdint>

namespace coopctrl {

/// Status of a solve (goldfarb_idnani.py's SOLVED, INFEASIBLE, MAX_ITER, NOT_CONVEX).
enum GIStatus : int {
    GI_SOLVED = 0,      ///< optimal; x and z hold the answer
    GI_INFEASIBLE = 1,  ///< inconsistent constraints (a dependent violated row with no blocking multiplier)
    GI_MAX_ITER = 2,    ///< the iteration limit was reached; x is the last dual feasible iterate
    GI_NOT_CONVEX = 3,  ///< H not positive definite, or a non-finite entry of g or M, or a NaN bound
};

/// Relative size |d_2| / |d| below which a constraint is taken as dependent on the active set.
constexpr double GI_DEP_TOL = 1e-12;
/// The fast path gives up when a pivot of its Gram matrix falls below this fraction of its diagonal entry.
constexpr double GI_GRAM_TOL = 1e-14;

/// The QP, read only: the loop's QPArrays (coopctrl/loop/data.py) name the same arrays M, lo, hi, H, g.
struct QP {
    int n;              ///< number of variables (the contact wrenches F: 6 m spatial, 3 m planar)
    int n_rows;         ///< rows of M
    int n_eq;           ///< the first n_eq rows are equalities (lo = hi: the object's wrench balance G F = w_N)
    const double* H;    ///< (n, n) row-major, symmetric positive definite Hessian (read when factorised)
    const double* g;    ///< (n) linear term
    const double* M;    ///< (n_rows, n) row-major constraint rows [G; C]
    const double* lo;   ///< (n_rows) lower bounds (-inf allowed on an inequality) [N, N m]
    const double* hi;   ///< (n_rows) upper bounds (+inf allowed on an inequality) [N, N m]
};

/// The scalar state of the warm start: the first 4 int64 of the workspace's `ints` array, in this order.
struct GIWarmState {
    int64_t active;        ///< q, the number of active constraints (0: the next solve starts cold)
    int64_t factor_valid;  ///< 1 if Linv holds the inverse Cholesky factor of the current H (0: refactorise)
    int64_t fast_path;     ///< 1 if the last solve was answered by the fast path (no iteration)
    int64_t H_diagonal;    ///< 1 if that H is diagonal (Linv diagonal)
};

/// The solver's workspace and warm start, by name: views into the numpy arrays (mats, vecs, rowv, ints) of
/// gi_workspace (layout in goldfarb_idnani.py), which Python allocates once per run.
/// Everything a solve needs is here: nothing is allocated per solve.
struct GIWorkspace {
    int n;                 ///< variables
    int n_rows;            ///< rows of M
    GIWarmState* state;    ///< ints[0:4]
    int64_t* act;          ///< (n) ints[4:4+n]: active codes (2 r lower side of row r, 2 r + 1 upper), order of R
    int64_t* prev;         ///< (n) the previous solve's codes (scratch)
    int64_t* sup_lo;       ///< (n) first non-zero column of each row of Y (fast path, scratch)
    int64_t* sup_hi;       ///< (n) one past its last non-zero column (fast path, scratch)
    int64_t* mark;         ///< (n_rows) 1 if the row is active
    int64_t* rfirst;       ///< (n_rows) first column of the row's non-zero entries
    int64_t* rend;         ///< (n_rows) one past its last non-zero column
    double* JT;            ///< (n, n) J^T (row i is column i of J); Y^T in the fast path; L during a factorisation
    double* R;             ///< (n, n) upper triangle of the leading q x q block; the Gram factor in the fast path
    double* Linv;          ///< (n, n) L^{-1}, the inverse Cholesky factor of H (lower triangular)
    double* d;             ///< (n + 1) J^T a of the constraint being added
    double* zz;            ///< (n + 1) primal step direction J_2 d_2
    double* r;             ///< (n + 1) dual step direction R^{-1} d_1
    double* u;             ///< (n + 1) multipliers of the active set (entry q: the constraint being added)
    double* x0;            ///< (n + 1) unconstrained minimiser -H^{-1} g
    double* v;             ///< (n + 1) scratch
    double* t;             ///< (n + 1) scratch (fast path)
    double* rownorm;       ///< (n_rows) Euclidean norm of each row of M
};

/// Doubles and int64 the workspace's arrays hold: mats (3, n, n), vecs (8, n + 1), rowv (2, n_rows), ints.
inline long gi_ints_length(int n, int n_rows) { return 4L + 4L * n + 3L * n_rows; }

/// The named views of the workspace arrays mats (3, n, n), vecs (8, n + 1), rowv (2, n_rows) and
/// ints (4 + 4 n + 3 n_rows), C-contiguous, as gi_workspace allocates them.
GIWorkspace gi_workspace_view(int n, int n_rows, double* mats, double* vecs, double* rowv, int64_t* ints) noexcept;

/// Solve qp warm started from ws's active set; write x (n) and z (n_rows, proxsuite's sign convention:
/// H x + g + M^T z = 0, z > 0 at an upper bound). new_H: H changed since the last solve with ws; tol: the
/// primal feasibility tolerance (violation / row norm) [N]; max_iter: additions and drops at most.
/// Returns the status (GIStatus); *iterations receives the additions and drops after the warm start.
int gi_solve(const QP& qp, double* x, double* z, GIWorkspace& ws, bool new_H, double tol, int64_t max_iter,
             int64_t* iterations) noexcept;

/// Number of inequality rows (rows >= n_eq) in the active set the last gi_solve with ws left.
int64_t gi_active_inequalities(const GIWorkspace& ws, int n_eq) noexcept;

}  // namespace coopctrl
