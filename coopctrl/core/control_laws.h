// The control laws of one tick (docs/model.md s.4-6), the one definition the tick and the Python controllers
// (coopctrl.controllers, through bind_control_laws.cpp) run; ported expression for expression from the numba laws
// they replaced (the same bits, which the golden records keep). Node poses Y are (position [m], angles [rad]):
// npos = 3 positions then 3 ZYX Euler angles (spatial, p = 6) or 2 positions then 1 angle (planar, p = 3).
// Matrices are row-major with a leading dimension (ld: the doubles between two rows), so that an arm's n x n block
// can sit in a larger array.
#pragma once

#include <cstdint>

#include "coopctrl/core/linear_algebra.h"

namespace coopctrl {

/// Work arrays of the laws for arms of up to nmax joints (nmax >= p), allocated by the caller once per run.
struct ControlWork {
    int nmax;         ///< the largest dof of an arm, and at least p
    double* vectors;  ///< (WORK_VECTORS, nmax) (linear_algebra.h)
    double* matrices; ///< (WORK_MATRICES, nmax, nmax)
    int64_t* piv;     ///< (nmax,) row swaps of the LU factorizations
    double* posture;  ///< (nmax,) the posture torque tau_0 [N m]
    double R[27];     ///< three 3 x 3 rotations of the pose increment
    double v[18];     ///< three 6-vectors of the pose increment

    double* vector(int k) const { return vectors + k * nmax; }
    double* matrix(int k) const { return matrices + k * nmax * nmax; }
};

/// The computed torque of a square arm, tau[:n] = H J^-1 (a_cmd - Jdq) + h + J^T F with the node wrench
/// F = W a_cmd + w_free + S [N m] (tau[:p] = F for a contact point, contact_point); W (p x p, ld p), H (ld ldH),
/// J (p x n, ld ldJ). Returns false (qdd taken as zero) where J is singular.
bool node_torque(const double* W, const double* w_free, const double* S, const double* H, int ldH, const double* h,
                 const double* J, int ldJ, const double* Jdq, const double* a_cmd, bool contact_point, int n, int p,
                 ControlWork& work, double* tau) noexcept;
/// The computed torque of a redundant arm (n > p) with the dynamically consistent inverse, plus the null-space
/// torque (I - J^T J^#T) tau_posture [N m]. Returns false (tau zero) where N or J N^-1 J^T is singular.
bool node_torque_redundant(const double* W, const double* w_free, const double* S, const double* H, int ldH,
                           const double* h, const double* J, int ldJ, const double* Jdq, const double* a_cmd,
                           const double* tau_posture, int n, int p, ControlWork& work, double* tau) noexcept;
/// out = target - Y with the angles (a >= npos) wrapped into [-pi, pi): e = (e + pi) mod 2 pi - pi [m, rad].
void pose_error(const double* target, const double* Y, int p, int npos, double* out) noexcept;
/// a_cmd = ddY_ref + Kd (dY_ref - dY) + Kp err [m/s^2, rad/s^2]; Kp [1/s^2], Kd [1/s].
void acceleration_from_error(const double* err, const double* dY_ref, const double* dY, const double* ddY_ref,
                             double Kp, double Kd, int p, double* a_cmd) noexcept;
/// The computed-torque motion loop: err = pose_error(target, Y), then acceleration_from_error.
void tracking_acceleration(const double* target, const double* Y, const double* dY_ref, const double* dY,
                           const double* ddY_ref, double Kp, double Kd, int p, int npos, double* err,
                           double* a_cmd) noexcept;
/// The leader's node target out = (Y_nominal + increment) + offset [m, rad].
void leader_target(const double* Y_nominal, const double* increment, const double* offset, int p,
                   double* out) noexcept;
/// The followers' force PI in wrench units: e = F_cmd - F_seen, integral <- clip(integral + e T, -limit, limit)
/// [N s, N m s], corr = F_cmd + kp e + ki integral [N, N m]; corr = F_cmd (integral untouched) with the loop open.
void follower_correction(const double* F_cmd, const double* F_seen, double* integral, double T, double kp,
                         double ki, double integral_limit, bool force_loop, int p, double* corr) noexcept;
/// The node pose increment [m, rad] that changes the node's wrench on the object by F [N, N m] through the grasp
/// compliance C (p x p, object frame): d = C R0^T F, position R0 d[:3], angles L(A_i)^-1 R_i^T R0 d[3:] (spatial,
/// R0 the object's rotation at Y0, A_i = Yi[3:6]); planar d = C R(theta0)^T F, the position rotated back. Returns
/// false (angles zero) where L(A_i) is singular.
bool pose_increment(bool spatial, const double* C, const double* F, const double* Y0, const double* Yi,
                    ControlWork& work, double* out) noexcept;
/// The follower's commanded node acceleration: target = pose_increment(corr) + Y_rigid, then
/// tracking_acceleration toward it. Returns false (a_cmd not written) where the body-rate map is singular.
bool follower_acceleration(bool spatial, const double* C, const double* corr, const double* Y0,
                           const double* Y_rigid, const double* Y, const double* dY_ref, const double* dY,
                           const double* ddY_ref, double Kp, double Kd, int p, int npos, ControlWork& work,
                           double* target, double* err, double* a_cmd) noexcept;
/// The damped null-space posture torque tau_0 = m_bar (Kp (q_rest - q) - Kd dq), m_bar = tr(H) / n [N m].
void posture_torque(const double* H, int ldH, const double* q, const double* dq, const double* q_rest, int n,
                    double Kp, double Kd, double* out) noexcept;
/// The joint torques tau[:n] [N m] that give the node a_cmd on the full model:
/// tau = H qdd + h + J^T (W a_cmd + w_free + S) [+ P^T tau_0], qdd = J^-1 (a_cmd - Jdq) (square arm) or the
/// dynamically consistent J^# (a_cmd - Jdq) (redundant arm, n > p, with the posture torque through the projector
/// P^T = I - J^T J^#T; posture_gain = (Kp [1/s^2], Kd [1/s])); a contact point (contact) gets tau[:p] = the node
/// wrench W a + w_free + S. W (p x p, ld p); H (ld ldH), J (p x n, ld ldJ). Returns false where J (or J N^-1 J^T)
/// is singular.
bool arm_torque(bool contact, int n, int p, const double* W, const double* w_free, const double* S,
                const double* H, int ldH, const double* h, const double* J, int ldJ, const double* Jdq,
                const double* a_cmd, const double* q, const double* dq, const double* q_rest,
                const double* posture_gain, ControlWork& work, double* tau) noexcept;

}  // namespace coopctrl
