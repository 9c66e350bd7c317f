// The planar cooperative system (docs/model.md s.5, planar reduction): the right-hand side x' = f(x, tau) of
// Gamma(z) z'' + phi(z, z') = (tau, 0) with x = (z, z'), z = (q_1..q_m, Y_0), and the control terms the tick
// senses (plants/cooperative/_planar_kernel.py, expression for expression):
//     N_i = H_i + J_i^T W_i J_i,  n_i = h_i + J_i^T (W_i dJ_i dq_i + w_i),  W_0 ddY_0 = -w_0,
// W_i = diag(m_i, m_i, I_i) constant, no gyroscopic terms.
#pragma once

#include <cstdint>

#include "plants/core/elastic_model.h"
#include "plants/core/planar_arm.h"

namespace plants {

/// How an arm drives its node.
enum ArmKind : std::int64_t {
    ARM_SERIAL = 0,          ///< a serial arm: its joints, H, h, J, dJ dq
    ARM_CONTACT_POINT = 1,   ///< an actuated node without arm dynamics: its coordinates are the node pose
    ARM_SERIAL_OWN_CHART = 2 ///< (spatial) a serial arm whose node's angles are taken in its own chart
};

/// One arm of a planar cooperative plant.
struct PlanarCooperativeArm {
    ArmKind kind;
    int dof;             ///< joints (3 for a contact point)
    int q_offset;        ///< where its coordinates start in z
    PlanarArmModel arm;  ///< a serial arm's links, base, tool and gravity
};

/// The constants of a planar cooperative plant: m arms, N = m + 1 nodes (node 0 the object).
struct PlanarCooperativeModel {
    int arm_count;                      ///< m
    const PlanarCooperativeArm* arms;   ///< m arms
    const PlanarNode* nodes;            ///< N nodes: mass [kg], inertia [kg m^2]
    Interconnections interconnections;  ///< the springs and dampers
    double gravity[2];                  ///< (g_x, g_z) [m/s^2]
    const double* Y_ref;                ///< (N, 3) the unloaded poses of the immobile model [m, rad]
    bool immobile;                      ///< the object is held (the immobile model (4.5))
    int nmax;                           ///< max(3, the largest arm dof): the row length of the arm arrays
};

/// What the right-hand side and the control terms write (a plant's workspace, made once per run).
struct PlanarCooperativeData {
    double* Y;      ///< (N, 3) node poses (x, z [m], theta [rad]); row 0 the object
    double* dY;     ///< (N, 3) node rates
    double* H;      ///< (m, nmax, nmax) arm inertias [kg m^2]
    double* h;      ///< (m, nmax) arm bias torques [N m]
    double* J;      ///< (m, 3, nmax) Jacobians
    double* Jdq;    ///< (m, 3) dJ/dt dq
    double* w;      ///< (N, 3) node terms w_i: -m g + interconnections [N, N m]
    double* Nm;     ///< (nmax, nmax) one arm's block N_i, then its Cholesky factor
    double* rhs;    ///< (nmax,) one arm's right-hand side
    double* qdd;    ///< (nmax,) one arm's joint accelerations
    double* chain;  ///< ((nmax + 1) * PLANAR_WORK_WIDTH) the arm kernel's work rows
};

/// The control terms the tick reads besides the node state (arrays of (N, ...) rows).
struct PlanarControlTerms {
    double* W;       ///< (N, 3, 3) node inertias diag(m_i, m_i, I_i)
    double* w_free;  ///< (N, 3) -m_i g
    double* S;       ///< (N, 3) the interconnections' terms
    double* Fw;      ///< (m, 3) the wrench each contact's edges apply to the object (f_x, f_z [N], n [N m])
    double* Fe;      ///< (N, 3) work
};

/// dx = f(x, tau) (nx = 2 nz). status[0] = ELASTIC_OK, or a failure (status[1] the node).
void planar_rhs(const PlanarCooperativeModel& model, const double* x, int nx, const double* tau, int64_t* status,
                PlanarCooperativeData& data, double* dx) noexcept;

/// The node poses and rates and the arm terms at x into data.
void planar_node_state(const PlanarCooperativeModel& model, const double* x, int nx, int64_t* status,
                       PlanarCooperativeData& data) noexcept;

/// The node state and the control terms at x (the tick's sensors).
void planar_control_terms(const PlanarCooperativeModel& model, const double* x, int nx, int64_t* status,
                          PlanarCooperativeData& data, PlanarControlTerms& terms) noexcept;

/// S (N, 3) and Fw (m, 3) from the node poses and rates in data, every edge on its own: its share of S, and its
/// wrench on the object (f_x, f_z at the contact node, couple about the object's mass centre) when it joins a
/// contact to it (the interconnections of planar_control_terms; interconnection_into of the numba kernels).
void planar_interconnection_wrenches(const PlanarCooperativeModel& model, const PlanarCooperativeData& data,
                                     PlanarControlTerms& terms) noexcept;

/// The gravitational potential energy of the arms' links [J].
double planar_arm_potentials(const PlanarCooperativeModel& model, const double* x) noexcept;

}  // namespace plants
