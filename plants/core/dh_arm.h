// A spatial serial arm with revolute standard-DH joints (docs/model.md s.4): frame k follows frame k-1 by
// Rz(q_k + offset_k) Tz(d_k) Tx(a_k) Rx(alpha_k), joint k turns about z_{k-1}; then H(q) qdd + h(q, dq) = tau,
// Y = Phi(q) (position [m], ZYX Euler angles [rad], docs/model.md s.2), J = dY/dq and dJ dq, equations
// (166)-(172). plants/arms/_spatial_kernels.py ported line by line (the same expressions in the same order, so the
// same bits).
//
// Algorithm (world coordinates): forward kinematics and the recursive Newton-Euler forward pass with qdd = 0 and
// the base accelerating with -g (gravity in h); the backward pass gives h (moments about o_{k-1}); the
// composite-rigid-body algorithm for H, composites about the joint axis point with their first moment (no division
// by a composite mass: links may be massless); the geometric Jacobian from the joint axes, mapped to Euler rates
// dA = L(A)^-1 R^T omega_world; Jdq from the tip acceleration of the qdd = 0 pass with gravity removed,
// ddA = L^-1 (R^T alpha_world - dL/dt dA). The tip pose is chain_arm.h's tip_pose.
// Every 3x3 rotation is 9 doubles, row-major; every 4x4 pose is 16 doubles, row-major.
#pragma once

namespace plants {

/// One revolute joint and the link it moves, standard DH as Corke's toolbox (the same 16 doubles, in this order,
/// as a row of ``SerialArm.dh_array()``, ``DHLink.row()`` on the Python side).
struct DHLink {
    double a;              ///< [m] link length
    double alpha;          ///< [rad] link twist
    double d;              ///< [m] link offset along z_{k-1}
    double offset;         ///< [rad] joint angle offset
    double mass;           ///< [kg]
    double com[3];         ///< [m] the centre of mass in frame k
    double inertia[6];     ///< [kg m^2] about the centre of mass in frame k: Ixx, Iyy, Izz, Ixy, Iyz, Ixz
    double motor_inertia;  ///< [kg m^2] added to H[k, k]
    double viscous;        ///< [N m s/rad] adds viscous * dq_k to h_k
};
static_assert(sizeof(DHLink) == 16 * sizeof(double), "a DH link row is 16 doubles");

/// The constants of one DH arm.
struct DHArmModel {
    int dof;              ///< number of joints n
    const DHLink* links;  ///< n links, base to tip
    double base[16];      ///< [m] world pose of frame 0, 4x4 row-major
    double tool[16];      ///< [m] the node frame in the last DH frame, 4x4 row-major
    double gravity[3];    ///< [m/s^2] gravity acceleration in the world, e.g. (0, 0, -9.81)
};

/// One frame's row of dh_arm_terms's work array (frame 0 = the base, frame k = link k); overwritten by every call.
struct DHFrame {
    double R[9];              ///< world rotation of frame k (row-major)
    double o[3];              ///< [m] world origin of frame k
    double w[3];              ///< [rad/s] angular velocity of body k
    double alpha[3];          ///< [rad/s^2] angular acceleration of body k (qdd = 0)
    double a[3];              ///< [m/s^2] linear acceleration of o_k as a point of body k (with -g)
    double com[3];            ///< [m] world centre of mass of link k
    double inertia_world[6];  ///< [kg m^2] world inertia of link k about its COM: xx, yy, zz, xy, yz, xz
    double force[3];          ///< [N] inertial force of link k
    double moment[3];         ///< [N m] inertial moment of link k about its COM
};
static_assert(sizeof(DHFrame) == 36 * sizeof(double), "a DH work row is 36 doubles");

/// Fill H (n x n, row-major) [kg m^2], h (n) [N m], Y (6), J (6 x n, row-major; rows 0-2 [m/rad], rows 3-5 Euler
/// rates per joint rate) and Jdq (6) [m/s^2, rad/s^2] at the joint angles q [rad] and rates dq [rad/s].
/// work: n + 1 rows, overwritten. Returns 0, or 1 where the tip's Euler angles are at the singularity of L
/// (cos theta < EULER_SINGULARITY_COS): then the angular rows of J and Jdq are zero, everything else is valid.
/// Allocates nothing.
int dh_arm_terms(const DHArmModel& arm, const double* q, const double* dq, double* H, double* h, double* Y,
                 double* J, double* Jdq, DHFrame* work) noexcept;

/// The gravitational potential energy U = -sum_k m_k g . p_com_k [J] at the joint angles q [rad].
double dh_arm_potential(const DHArmModel& arm, const double* q) noexcept;

/// The node frame's world pose T (4x4, row-major) and the world geometric Jacobian Jg (6 x n, row-major:
/// v; omega), defined everywhere (no Euler angles). axes and points: 3 n doubles each, overwritten (joint k's
/// world axis z_{k-1} and point o_{k-1}).
void dh_arm_tip(const DHArmModel& arm, const double* q, double* axes, double* points, double* T,
                double* Jg) noexcept;

}  // namespace plants
