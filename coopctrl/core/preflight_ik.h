// Pre-flight's warm-started inverse kinematics (coopctrl/analysis/preflight_ik.py calls it; ported expression for
// expression from the numba kernels it replaced), on plants/core's forward kinematics (dh_arm_tip, chain_arm_tip,
// planar_arm_terms):
// damped least squares from the seed q,
//     dq = J_e^T (J_e J_e^T + lambda I)^-1 e,   q <- clip(q + dq, q_lower, q_upper),
// kept when |e|^2 falls (then lambda <- max(0.3 lambda, 1e-12), else lambda <- 5 lambda, given up above 1e6), from
// lambda = 1e-2, at most IK_MAX_ITERATIONS iterations, until the position residual |e_p| [m] and the rotation
// residual |e_r| [rad] are both at most the tolerance. Spatial: e_p = p_target - p(q), e_r the rotation vector of
// R_target R(q)^T, J_e the geometric Jacobian; planar: e = Y_target - Y(q) with its angle wrapped to [-pi, pi),
// J_e the analytic Jacobian. A redundant spatial arm is then moved along its self-motion manifold toward its rest
// posture (spatial_refine_posture), with the pseudo-inverse numba's np.linalg.pinv computes: the same LAPACK and
// BLAS routines (DenseRoutines), called as numba calls them.
// And square_joint_rates: the joint rates J_i dq_i = dY_i of arms whose Jacobians are all square.
// Matrices are row-major unless said otherwise.
#pragma once

#include <cstdint>

#include "plants/core/chain_arm.h"
#include "plants/core/dh_arm.h"
#include "plants/core/planar_arm.h"

namespace coopctrl {

/// Iteration budget of one damped least-squares solve (plants.arms._dls_ik.damped_least_squares's).
constexpr int IK_MAX_ITERATIONS = 200;

/// Fortran LAPACK/BLAS routines, as scipy.linalg.cython_lapack and cython_blas export them.
using DgesddRoutine = void(char* jobz, int* m, int* n, double* a, int* lda, double* s, double* u, int* ldu,
                           double* vt, int* ldvt, double* work, int* lwork, int* iwork, int* info);
using DgemmRoutine = void(char* transa, char* transb, int* m, int* n, int* k, double* alpha, double* a, int* lda,
                          double* b, int* ldb, double* beta, double* c, int* ldc);
using DgemvRoutine = void(char* trans, int* m, int* n, double* alpha, double* a, int* lda, double* x, int* incx,
                          double* beta, double* y, int* incy);

/// The routines numba's np.linalg.pinv and its matrix products call (scipy's), handed in by the caller so that
/// the posture refinement has numba's bits.
struct DenseRoutines {
    DgesddRoutine* gesdd;
    DgemmRoutine* gemm;
    DgemvRoutine* gemv;
};

/// The kinds of spatial arm the IK solves (preflight_ik.KIND_DH, KIND_CHAIN).
enum SpatialIKKind : int { IK_KIND_DH = 0, IK_KIND_CHAIN = 1 };

/// A spatial arm and its joint limits (n = the model's dof).
struct SpatialIKArm {
    SpatialIKKind kind;
    plants::DHArmModel dh;        ///< read when kind == IK_KIND_DH (gravity unused)
    plants::ChainArmModel chain;  ///< read when kind == IK_KIND_CHAIN (gravity unused)
    const double* lower;          ///< (n,) joint limits [rad or m]
    const double* upper;          ///< (n,)
    int dof() const noexcept { return kind == IK_KIND_DH ? dh.dof : chain.dof; }
};

/// A planar arm and its joint limits.
struct PlanarIKArm {
    plants::PlanarArmModel arm;
    const double* lower;  ///< (n,) [rad]
    const double* upper;  ///< (n,)
};

/// The convergence and posture settings (plants.arms.spatial_ik's IK_TOLERANCE, POSTURE_ITERATIONS, POSTURE_STEP).
struct IKSettings {
    double tolerance;        ///< [m] and [rad]: both residuals at most this
    int posture_iterations;  ///< trials of the posture refinement
    double posture_step;     ///< its first step [-]
};

/// What spatial_refine_posture reports besides its answer.
enum PostureStatus : int {
    POSTURE_OK = 0,
    POSTURE_NOT_FINITE = 1,     ///< a Jacobian was not finite (numba's pinv raises LinAlgError)
    POSTURE_SVD_FAILED = 2,     ///< LAPACK's SVD did not converge (numba's pinv raises ValueError)
};

/// Damped least squares from q (n,) toward the node pose target (6,): position [m], ZYX Euler angles [rad]; q gets
/// the answer. Returns whether it converged.
bool spatial_ik(const SpatialIKArm& arm, const IKSettings& settings, const double* target, double* q);

/// Move the answer q of spatial_ik for a redundant arm along its self-motion manifold toward posture (n,):
/// q <- q + s (I - J_g^+ J_g)(posture - q) from s = posture_step, each trial pulled back onto the target by the
/// damped least squares and kept if it converged and reduced the null-space residual (then s <- min(1, 2 s), else
/// s <- s / 2, given up below 1e-3), at most posture_iterations trials, until that residual is at most 1e-10.
PostureStatus spatial_refine_posture(const SpatialIKArm& arm, const IKSettings& settings, const DenseRoutines& dense,
                                     const double* posture, const double* target, double* q);

/// spatial_ik of a planar arm toward target = (x, z, theta) [m, m, rad]; q gets the answer.
bool planar_ik(const PlanarIKArm& arm, const IKSettings& settings, const double* target, double* q);

/// Each arm's joint rates out[i, :p] (m arms, row i of ldout doubles) solving J[i] dq_i = dY[i + 1, :p] (J (m, p,
/// ldJ) row-major, dY rows of lddY doubles) by LU with partial pivoting where every arm's Jacobian is square
/// (dofs[i] == p <= 6) and regular; returns false (out then undefined) if one is not.
bool square_joint_rates(const double* J, int m, int p, int ldJ, const double* dY, int lddY, const int64_t* dofs,
                        double* out, int ldout) noexcept;

}  // namespace coopctrl
