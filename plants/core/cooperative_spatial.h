// The spatial cooperative system (docs/model.md s.5): the right-hand side x' = f(x, tau) of
//     Gamma(z) z'' + phi(z, z') = (tau, 0),  x = (z, z'),  z = (q_1..q_m, Y_0),
//     Gamma = blockdiag(N_1, ..., N_m, W_0),  N_i = H_i + J_i^T W_i J_i,  n_i = h_i + J_i^T (W_i dJ_i dq_i + w_i),
// and the control terms the tick senses (plants/cooperative/_spatial_kernel.py, expression for expression, so the
// same bits). Gamma is block diagonal: each arm's block is factored on its own (Cholesky), a contact point's and the
// object's W_k = blockdiag(m_k I, L^T I_k L) are solved in closed form, so the cost is linear in m. Every serial arm
// (DH or URDF) is a general chain (chain_arm.h: a DH arm's table is its chain table). An arm of kind
// ARM_CONTACT_POINT is an actuated node without arm dynamics: its coordinates are the node pose (J = I, H = h = 0).
// Node rows wider than SPATIAL_NODE_WIDTH carry rotation charts (docs/model.md s.2), applied to the node frames
// after they are evaluated; an arm of kind ARM_SERIAL_OWN_CHART writes its node's chart C = R_tip(q) itself.
#pragma once

#include <cstdint>

#include "plants/core/chain_arm.h"
#include "plants/core/cooperative_planar.h"  // ArmKind, shared by both spaces
#include "plants/core/elastic_model.h"

namespace plants {

/// One arm of a spatial cooperative plant.
struct SpatialCooperativeArm {
    ArmKind kind;
    int dof;           ///< joints n_i (6 for a contact point)
    int q_offset;      ///< where its coordinates start in z
    ChainArmModel arm; ///< a serial arm's joints, base, tool and gravity (unused for a contact point)
};

/// The constants of a spatial cooperative plant: m arms, N = m + 1 nodes (node 0 the object).
struct SpatialCooperativeModel {
    int arm_count;                      ///< m
    const SpatialCooperativeArm* arms;  ///< m arms
    const double* node_rows;            ///< N rows of node_width doubles: SpatialNode, or ChartedSpatialNode
    int node_width;                     ///< SPATIAL_NODE_WIDTH, or SPATIAL_NODE_WIDTH_CHARTED (rows with charts)
    Interconnections interconnections;  ///< the springs, dampers and matrix elements (SPATIAL_EDGE_WIDTH rows)
    double gravity[3];                  ///< [m/s^2]
    const double* Y_ref;                ///< (N, 6) the unloaded poses of the immobile model [m, rad]
    bool immobile;                      ///< the object is held (the immobile model (4.5))
    int nmax;                           ///< max(6, the largest arm dof): the row length of the arm arrays

    /// Node k's mass and principal inertia (the first columns of its row).
    const SpatialNode& node(int k) const noexcept {
        return *reinterpret_cast<const SpatialNode*>(node_rows + static_cast<long>(k) * node_width);
    }
    /// The node rows carry charts (the kernel's node_params.shape[1] > NODE_CHART_KIND).
    bool charted() const noexcept { return node_width > SPATIAL_NODE_WIDTH; }
};

/// What the right-hand side and the control terms write (a plant's workspace, made once per run; zero-filled at
/// first, and the zero padding of J and Jdq past an arm's dof and of a contact point's rows is never written).
/// After a successful call Y, dY, H, h, J, Jdq, Wr and w hold the terms of the state.
struct SpatialCooperativeData {
    double* Y;          ///< (N, 6) node poses (r [m], ZYX Euler angles [rad]); row 0 the object
    double* dY;         ///< (N, 6) node rates [m/s, rad/s]
    double* H;          ///< (m, nmax, nmax) arm inertias H_i [kg m^2], block [:n_i, :n_i]
    double* h;          ///< (m, nmax) arm bias torques h_i [N m]
    double* J;          ///< (m, 6, nmax) analytic Jacobians J_i, columns [:n_i]
    double* Jdq;        ///< (m, 6) dJ_i/dt dq_i [m/s^2, rad/s^2]
    double* Wr;         ///< (N, 3, 3) rotational inertia blocks L^T I L [kg m^2]
    double* w;          ///< (N, 6) node terms w_k: -m g + gyroscopic + interconnections [N, N m]
    double* Nm;         ///< (nmax, nmax) one arm's block N_i (lower triangle), then its Cholesky factor
    double* rhs;        ///< (nmax,) one arm's right-hand side tau_i - n_i
    double* qdd;        ///< (nmax,) one arm's joint accelerations
    double* WJ;         ///< (3, nmax) Wr_i J_i,rot of one arm
    double* arm_H;      ///< (nmax * nmax) one arm's H as the chain kernel writes it (n_i x n_i), copied into H
    double* arm_J;      ///< (6 * nmax) one arm's J as the chain kernel writes it (6 x n_i), copied into J
    ChainBody* chain;   ///< (nmax + 1) the chain kernel's work rows
    NodeFrames* frames; ///< (N) every node's R, dR/dA, L and chart
};

/// The control terms the tick reads besides the node state (plants.cooperative.ControlTerms).
struct SpatialControlTerms {
    double* W;       ///< (N, 6, 6) node inertias W_k = blockdiag(m_k I, L^T I_k L) (off-blocks stay 0)
    double* w_free;  ///< (N, 6) the gyroscopic and gravity terms of w (no interconnections)
    double* S;       ///< (N, 6) the interconnections' terms S_k = dPi/dY_k + dD/d(dY_k)
    double* Fw;      ///< (m, 6) the wrench (f [N], couple [N m], world) each contact's edges apply to the object
    double* Fe;      ///< (N, 6) work: one edge's forces
};

/// dx = f(x, tau) (nx = 2 nz); tau (nz - 6) the joint torques, or a contact point's node forces. status[0] =
/// ELASTIC_OK, or a failure with status[1] the node (dx then partly written). The kernel's rhs_into_packed.
void spatial_rhs(const SpatialCooperativeModel& model, const double* x, int nx, const double* tau, int64_t* status,
                 SpatialCooperativeData& data, double* dx) noexcept;

/// The node poses Y and rates dY and the arm terms H, h, J, Jdq at x into data (status as spatial_rhs: an arm's
/// tip at an Euler singularity).
void spatial_node_state(const SpatialCooperativeModel& model, const double* x, int nx, int64_t* status,
                        SpatialCooperativeData& data) noexcept;

/// The node state, Wr, the node frames and the control terms at x (the tick's sensors; control_terms_packed).
/// status[0] = ELASTIC_EULER_SINGULAR with status[1] the node at an Euler singularity of an arm's tip (node i), or
/// of the object (node 0: then S is valid and Fw is not).
void spatial_control_terms(const SpatialCooperativeModel& model, const double* x, int nx, int64_t* status,
                           SpatialCooperativeData& data, SpatialControlTerms& terms) noexcept;

/// S (N, 6) and Fw (m, 6) edge by edge from the node poses and rates in data (and, in the mobile model, every
/// node's frames): S_k sums every edge's forces on node k; an edge between the object and contact c adds its
/// wrench on the object to Fw[c - 1]: force f = -F_0,r at the contact node, couple R_0 L_0^-T (-F_0,A) +
/// (r_c - r_0) x f about the object's mass centre (world). The object's world rotation is frames[0].R when
/// charted (C_0 R(A_0)), else R(A_0). Returns false at an Euler singularity of the object (S valid, Fw zero).
/// The interconnections of spatial_control_terms (interconnection_into of the numba kernels).
bool spatial_interconnection_wrenches(const SpatialCooperativeModel& model, const SpatialCooperativeData& data,
                                      SpatialControlTerms& terms, bool charted) noexcept;

/// dx = f(x, tau) from the terms spatial_control_terms left in data and terms for the same x (H, h, J, Jdq, the
/// node frames, Wr and w_free): only the interconnections' forces and the accelerations are evaluated, in the
/// order of spatial_rhs, so the same bits (rhs_from_terms_into).
void spatial_rhs_from_terms(const SpatialCooperativeModel& model, const double* x, int nx, const double* tau,
                            int64_t* status, SpatialCooperativeData& data, const SpatialControlTerms& terms,
                            double* dx) noexcept;

/// The gravitational potential energy of the arms' links U = -sum m_link g . p_com [J]; work: nmax + 1 rows.
double spatial_arm_potentials(const SpatialCooperativeModel& model, const double* x, ChainBody* work) noexcept;

}  // namespace plants
