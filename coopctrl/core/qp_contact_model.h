// The load-distribution QP's contact inputs from the plant's control terms, which the tick and
// coopctrl/loop/qp_inputs.py call: the contacts' unit normals and the torque model of every arm,
//     tau_i = Jg_i^T F_i + bias_i,   bias_i = H_i ddq_i + h_i + J_i^T (W_k ddYn_k + w_free_k),
// at the nominal node accelerations ddYn; ddq_i tracks them, J_i ddq_i = ddYn_k - Jdq_i: J_i^-1 (ddYn_k - Jdq_i) for
// a square arm (LU solve), J^# (ddYn_k - Jdq_i) with J^# = N^-1 J^T (J N^-1 J^T)^-1, N = H_i + J_i^T W_k J_i for a
// redundant arm, and 0 where that solve is singular (a pivot <= 1e-13 of the matrix's largest entry). Jg_i maps the
// joint rates to the node's world twist: J_i with, spatial, its angular rows R(A_k) L(A_k) J_i[3:] (L the body-rate
// map). A contact point carries the wrench directly: Jg_i = I, bias_i = W_k ddYn_k + w_free_k. Node k = i + 1 is
// contact i's.
#pragma once

#include <cstdint>

namespace coopctrl {

/// The inward unit normals n_i, the node frames' approach (x) axes, of the m contacts into nrm (m, ldn): spatial
/// R(A_k) e_x / |.| (3 entries), planar (cos th_k, sin th_k) / |.| (2 entries); Y (m + 1, ldY) node poses
/// [m, rad]; R 9 doubles of scratch.
void contact_normals(const double* Y, int ldY, bool spatial, double* nrm, int ldn, int m, double* R) noexcept;

/// The terms the torque model reads, all row-major: p = 6 spatial, 3 planar; nmax joints per arm at most.
struct TorqueModelInputs {
    int m;                    ///< arms
    int p;                    ///< pose components per node
    int nmax;                 ///< joints per arm at most (the last dimension of H, h, J)
    const double* Y;          ///< (m + 1, p) node poses [m, rad]
    const double* ddYn;       ///< (m + 1, p) nominal node accelerations [m/s^2, rad/s^2]
    const double* W;          ///< (m + 1, p, p) node inertias [kg, kg m^2]
    const double* w_free;     ///< (m + 1, p) node gyroscopic-minus-gravity terms [N, N m]
    const double* H;          ///< (m, nmax, nmax) arm inertias [kg m^2]
    const double* h;          ///< (m, nmax) arm bias torques [N m]
    const double* J;          ///< (m, p, nmax) analytic Jacobians
    const double* Jdq;        ///< (m, p) dJ/dt dq [m/s^2, rad/s^2]
    const int64_t* arm_kind;  ///< (m) nonzero: a contact point (Jg_i = I)
    const int64_t* arm_dof;   ///< (m) joints n_i of each arm
};

/// The torque model's outputs: Jg (m, p, Jg_cols), arm i's Jg_i in Jg[i, :, :n_i]; bias (sum n_i) [N m].
struct TorqueModel {
    double* Jg;
    int Jg_cols;  ///< >= max(p, nmax)
    double* bias;
};

/// Scratch of the torque model: Wa, rhs_t (p); qdd, piv (>= nmax); wv (WORK_VECTORS, ldw), wm (WORK_MATRICES,
/// ldw, ldw) with ldw >= nmax >= p (control_work); R3 (>= 3, 3, 3).
struct TorqueModelWork {
    double* Wa;
    double* rhs_t;
    double* qdd;
    int64_t* piv;
    double* wv;
    double* wm;
    int ldw;
    double* R3;
};

/// Write tau_i = Jg_i^T F_i + bias_i of every arm (the torque model above).
void torque_model(bool spatial, const TorqueModelInputs& in, TorqueModel& out, TorqueModelWork& work) noexcept;

}  // namespace coopctrl
