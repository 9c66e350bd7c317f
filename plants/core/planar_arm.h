// A planar serial arm in the vertical x-z plane (docs/model.md s.2 and s.4): H(q) qdd + h(q, dq) = tau,
// Y = Phi(q) = (x, z, theta), dY = J dq, ddY = J qdd + dJ dq, equations (166)-(172) with L = 1.
#pragma once

namespace plants {

/// One link of a planar arm, base to tip (the same 7 doubles, in this order, as a row of
/// ``PlanarArm.link_array()`` on the Python side).
struct PlanarLink {
    double length;         ///< [m] from joint k to joint k+1 along the link's x axis
    double mass;           ///< [kg]
    double rc_x;           ///< [m] the centre of mass in the link frame, along the link
    double rc_y;           ///< [m] the centre of mass in the link frame, perpendicular towards +theta
    double Izz;            ///< [kg m^2] inertia about the centre of mass
    double motor_inertia;  ///< [kg m^2] added to H's diagonal
    double viscous;        ///< [N m s/rad] adds viscous * dq to h
};

/// The constants of one planar arm.
struct PlanarArmModel {
    int dof;                  ///< number of joints n
    const PlanarLink* links;  ///< n links, base to tip
    double base[3];           ///< (x [m], z [m], theta [rad]) of joint 1's frame at q = 0
    double tool[3];           ///< (dx [m], dz [m], dtheta [rad]) of the node frame in the last link frame
    double gravity[2];        ///< (gx, gz) [m/s^2]
};

/// Doubles of planar_arm_terms's work array per row; it needs n + 1 rows.
constexpr int PLANAR_WORK_WIDTH = 10;

/// Fill H (n x n, row-major with ldH doubles a row) [kg m^2], h (n) [N m], Y (3), J (3 x n, row-major with ldJ
/// doubles a row), Jdq (3) in place at the joint angles q [rad] and rates dq [rad/s] (ldH, ldJ >= n: the arm's
/// block of arrays sized for the largest arm); work holds (n + 1) * PLANAR_WORK_WIDTH doubles, overwritten.
/// Allocates nothing; returns 0.
int planar_arm_terms(const PlanarArmModel& arm, const double* q, const double* dq, double* H, int ldH, double* h,
                     double* Y, double* J, int ldJ, double* Jdq, double* work) noexcept;

/// The gravitational potential energy U = -sum_k m_k g . p_com_k [J] at the joint angles q [rad].
double planar_arm_potential(const PlanarArmModel& arm, const double* q) noexcept;

}  // namespace plants
