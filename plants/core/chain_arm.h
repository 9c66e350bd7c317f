// A spatial serial chain with general joints, URDF-style (docs/model.md s.4): link frame k is
//   0T_k = 0T_{k-1} origin_k M_k(q_k),   M_k = Rot(axis_k, q_k) (revolute) or Trans(axis_k q_k) (prismatic),
// and H(q) qdd + h(q, dq) = tau, Y = Phi(q) (position [m], ZYX Euler angles [rad], docs/model.md s.2),
// J = dY/dq (analytic: dA = L(A)^-1 R^T omega_world) and dJ dq, equations (166)-(172).
// plants/arms/_chain_kernels.py ported line by line (the same expressions in the same order, so the same bits).
//
// Algorithm (world coordinates; reference point of body k = the origin o_k of link frame k):
// - forward kinematics and the recursive Newton-Euler forward pass with qdd = 0 and the base accelerating with
//   -g (gravity in h): a(o_k) = a(o_{k-1}) + alpha_{k-1} x d + w_{k-1} x (w_{k-1} x d), d = o_k - o_{k-1}, plus
//   the Coriolis term 2 w_{k-1} x u_k dq_k of a prismatic joint;
// - backward pass: the subtree wrench about o_k; h_k = u_k . M (revolute) or u_k . F (prismatic), plus
//   viscous_k dq_k and the smoothed Coulomb friction coulomb_k tanh(dq_k / COULOMB_SMOOTHING);
// - composite rigid bodies for H, composites about o_i with their first moment; motor_inertia on H's diagonal;
// - the geometric Jacobian (u x (p - o_k); u) or (u; 0), mapped to Euler rates; Jdq from the tip acceleration of
//   the qdd = 0 pass with gravity removed.
// Every 3x3 rotation is 9 doubles, row-major; every 4x4 pose is 16 doubles, row-major.
#pragma once

namespace plants {

/// The kinds of a chain joint (ChainJointRow::type).
enum ChainJointType : int {
    JOINT_REVOLUTE_Z = 0,  ///< revolute about +z of the joint frame (the fast path)
    JOINT_REVOLUTE = 1,    ///< revolute about ``axis``
    JOINT_PRISMATIC = 2,   ///< prismatic along ``axis``
};

/// Velocity scale [rad/s or m/s] of the smoothed Coulomb friction coulomb * tanh(dq / COULOMB_SMOOTHING).
constexpr double COULOMB_SMOOTHING = 1e-2;

/// One moving joint of a chain and the link it carries (the same 32 doubles, in this order, as a row of
/// ``ChainArm.kernel_table()``, ``ChainJoint.row()`` on the Python side).
struct ChainJointRow {
    double type;            ///< a ChainJointType, stored as a double
    double origin[3];       ///< [m] the joint frame's origin in the parent link frame
    double rotation[9];     ///< the joint frame's rotation in the parent link frame (row-major)
    double axis[3];         ///< unit joint axis in the joint frame (read for JOINT_REVOLUTE and JOINT_PRISMATIC)
    double mass;            ///< [kg]
    double com[3];          ///< [m] the centre of mass in link frame k (after the joint motion)
    double inertia[6];      ///< [kg m^2] about the centre of mass in link frame k: Ixx, Iyy, Izz, Ixy, Iyz, Ixz
    double motor_inertia;   ///< [kg m^2 or kg] added to H[k, k]
    double viscous;         ///< [N m s/rad or N s/m] adds viscous * dq_k to h_k
    double coulomb;         ///< [N m or N] adds coulomb * tanh(dq_k / COULOMB_SMOOTHING) to h_k
    double unused[3];       ///< zero
};
static_assert(sizeof(ChainJointRow) == 32 * sizeof(double), "a chain joint row is 32 doubles");

/// The constants of one chain arm.
struct ChainArmModel {
    int dof;                      ///< number of moving joints n
    const ChainJointRow* joints;  ///< n joints, base to tip
    double base[16];              ///< [m] world pose of the base frame, 4x4 row-major
    double tool[16];              ///< [m] the node frame in the last link frame, 4x4 row-major
    double gravity[3];            ///< [m/s^2] gravity acceleration in the world, e.g. (0, 0, -9.81)
};

/// One body's row of the work array (body 0 = the base, body k = link k); overwritten by every call.
struct ChainBody {
    double R[9];              ///< world rotation of link frame k (row-major)
    double o[3];              ///< [m] world origin of link frame k
    double u[3];              ///< world axis of joint k
    double w[3];              ///< [rad/s] angular velocity of body k
    double alpha[3];          ///< [rad/s^2] angular acceleration of body k (qdd = 0)
    double a[3];              ///< [m/s^2] linear acceleration of o_k as a point of body k (with -g)
    double com[3];            ///< [m] world centre of mass of link k
    double inertia_world[6];  ///< [kg m^2] world inertia of link k about its COM: xx, yy, zz, xy, yz, xz
    double force[3];          ///< [N] inertial force of link k
    double moment[3];         ///< [N m] inertial moment of link k about its COM
};
static_assert(sizeof(ChainBody) == 39 * sizeof(double), "a chain work row is 39 doubles");

/// The node pose of tip_pose and the quantities its callers reuse.
struct TipPose {
    double p[3];       ///< [m] world position of the node frame
    double R[9];       ///< world rotation R_tip = R_n tool_R of the node frame (row-major)
    double cos_theta;  ///< cos of the Euler angle theta = sqrt(R_21^2 + R_22^2) (1 in the node's own chart)
    double sin_theta;  ///< sin theta = -R_20 (0 in the node's own chart)
};

/// The node pose Y (6) from the last frame's world rotation Rn (9) and origin on (3) and the tool (4x4):
/// R_tip = Rn tool_R, p_tip = on + Rn tool_p; Y = (p_tip, ZYX Euler angles of R_tip), or (p_tip, 0) in the node's
/// own chart. The one tip computation of the chain and DH kernels.
TipPose tip_pose(const double* Rn, const double* on, const double* tool, bool own_chart, double* Y) noexcept;

/// Link frame k (R, o) and the world joint axis u into c, from the parent's frame p and the joint angle or
/// offset qk [rad or m]: R_k = R_{k-1} (R_origin M(q)), o_k = o_{k-1} + R_{k-1} p_origin (+ u q if prismatic).
void chain_link_frame(const ChainBody& p, const ChainJointRow& joint, double qk, ChainBody& c) noexcept;

/// Fill H (n x n, row-major), h (n), Y (6), J (6 x n, row-major) and Jdq (6) at the joint positions q
/// [rad or m] and rates dq [rad/s or m/s]. work: n + 1 rows, overwritten. own_chart false: the node's angles are
/// the world ZYX Euler angles of R_tip; true: they are taken in the node's own chart (A = 0, chart (3x3) receives
/// C = R_tip(q); untouched otherwise). Returns 0, or 1 where the tip's Euler angles are at the singularity of L
/// (cos theta < EULER_SINGULARITY_COS): then the angular rows of J and Jdq are zero, everything else is valid.
/// Allocates nothing.
int chain_arm_terms(const ChainArmModel& arm, const double* q, const double* dq, double* H, double* h, double* Y,
                    double* J, double* Jdq, ChainBody* work, bool own_chart, double* chart) noexcept;

/// The node pose Y (6) of chain_arm_terms alone, bit for bit (forward kinematics only); the same return value.
/// work: n + 1 rows, overwritten (only R, o and u).
int chain_arm_pose(const ChainArmModel& arm, const double* q, bool own_chart, ChainBody* work, double* Y) noexcept;

/// The gravitational potential energy U = -sum_k m_k g . p_com_k [J]. work: n + 1 rows, overwritten.
double chain_arm_potential(const ChainArmModel& arm, const double* q, ChainBody* work) noexcept;

/// The node frame's world pose T (4x4, row-major) and the world geometric Jacobian Jg (6 x n, row-major:
/// v; omega), defined everywhere (no Euler angles). work: n + 1 rows, overwritten.
void chain_arm_tip(const ChainArmModel& arm, const double* q, ChainBody* work, double* T, double* Jg) noexcept;

}  // namespace plants
