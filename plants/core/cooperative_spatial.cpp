#include "plants/core/cooperative_spatial.h"

#include "plants/core/cholesky.h"
#include "plants/core/elastic_nodes.h"
#include "plants/core/elastic_spatial.h"
#include "plants/core/frames.h"

namespace plants {

namespace {

/// Kinematics and dynamics of every arm, into the stacked arrays (H_i, h_i, J_i, Jdq_i rows of nmax) and the
/// node rows Y[1:], dY[1:] with dY_i = J_i dq_i; an arm of kind ARM_SERIAL_OWN_CHART writes its node's chart
/// into frames[i + 1].chart. Stops at the first tip at an Euler singularity (status ELASTIC_EULER_SINGULAR, i + 1).
void arm_pass(const SpatialCooperativeModel& model, const double* z, const double* dz, int64_t* status,
              SpatialCooperativeData& d) noexcept {
    const int nmax = model.nmax;
    for (int i = 0; i < model.arm_count; ++i) {
        const SpatialCooperativeArm& a = model.arms[i];
        const int n = a.dof, o = a.q_offset;
        double* Yi = d.Y + (i + 1) * 6;
        double* dYi = d.dY + (i + 1) * 6;
        if (a.kind != ARM_CONTACT_POINT) {
            double* H = d.H + i * nmax * nmax;
            double* J = d.J + i * 6 * nmax;
            const int st = chain_arm_terms(a.arm, z + o, dz + o, d.arm_H, d.h + i * nmax, Yi, d.arm_J,
                                           d.Jdq + i * 6, d.chain, a.kind == ARM_SERIAL_OWN_CHART,
                                           &d.frames[i + 1].chart[0][0]);
            // the chain kernel's dense n x n and 6 x n blocks into the rows of nmax (a copy: the same bits)
            for (int r = 0; r < n; ++r)
                for (int c = 0; c < n; ++c) H[r * nmax + c] = d.arm_H[r * n + c];
            for (int r = 0; r < 6; ++r)
                for (int c = 0; c < n; ++c) J[r * nmax + c] = d.arm_J[r * n + c];
            if (st != 0) {
                status[0] = ELASTIC_EULER_SINGULAR;
                status[1] = i + 1;
                return;
            }
            for (int c = 0; c < 6; ++c) {
                double s = 0.0;
                for (int k = 0; k < n; ++k) s += J[c * nmax + k] * dz[o + k];
                dYi[c] = s;
            }
        } else {
            for (int c = 0; c < 6; ++c) {
                Yi[c] = z[o + c];
                dYi[c] = dz[o + c];
            }
        }
    }
}

/// The accelerations dx[nz:] from the terms in d (Y, H, h, J, Jdq, Wr and w with every interconnection): each
/// arm's (H + J^T W J) ddq = tau - h - J^T (W Jdq + w) by Cholesky, each contact point's and the object's
/// Newton-Euler equations m ddr = f - w_r, (L^T I L) ddA = n - w_A.
void accelerations(const SpatialCooperativeModel& model, int nz, const double* tau, int64_t* status,
                   SpatialCooperativeData& d, double* dx) noexcept {
    const int nmax = model.nmax;
    const double* w = d.w;
    double b3[3], o3[3];
    for (int i = 0; i < model.arm_count; ++i) {
        const SpatialCooperativeArm& arm = model.arms[i];
        const int n = arm.dof, o = arm.q_offset, k = i + 1;
        const double mk = model.node(k).mass;
        if (arm.kind != ARM_CONTACT_POINT) {
            const double* Ji = d.J + i * 6 * nmax;
            const double* Hi = d.H + i * nmax * nmax;
            const double* Jdq = d.Jdq + i * 6;
            const double* Wk = d.Wr + k * 9;
            const double* wk = w + k * 6;
            // v = W Jdq + w at the node
            double v[6];
            for (int a = 0; a < 3; ++a) v[a] = mk * Jdq[a] + wk[a];
            for (int a = 0; a < 3; ++a) {
                double s = wk[3 + a];
                for (int c = 0; c < 3; ++c) s += Wk[a * 3 + c] * Jdq[3 + c];
                v[3 + a] = s;
            }
            // WJ = Wr J_rot (3 x n), once per arm
            double* WJ = d.WJ;
            for (int a = 0; a < 3; ++a)
                for (int c = 0; c < n; ++c) {
                    double t = 0.0;
                    for (int e = 0; e < 3; ++e) t += Wk[a * 3 + e] * Ji[(3 + e) * nmax + c];
                    WJ[a * nmax + c] = t;
                }
            for (int r = 0; r < n; ++r) {
                const double j0 = Ji[0 * nmax + r], j1 = Ji[1 * nmax + r], j2 = Ji[2 * nmax + r];
                const double j3 = Ji[3 * nmax + r], j4 = Ji[4 * nmax + r], j5 = Ji[5 * nmax + r];
                double s = 0.0;
                s += j0 * v[0];
                s += j1 * v[1];
                s += j2 * v[2];
                s += j3 * v[3];
                s += j4 * v[4];
                s += j5 * v[5];
                d.rhs[r] = tau[o + r] - d.h[i * nmax + r] - s;
                // the lower triangle only: cholesky_solve reads no entry above the diagonal
                for (int c = r; c < n; ++c) {
                    s = Hi[r * nmax + c];
                    s += mk * j0 * Ji[0 * nmax + c];
                    s += mk * j1 * Ji[1 * nmax + c];
                    s += mk * j2 * Ji[2 * nmax + c];
                    s += j3 * WJ[0 * nmax + c];
                    s += j4 * WJ[1 * nmax + c];
                    s += j5 * WJ[2 * nmax + c];
                    d.Nm[c * nmax + r] = s;
                }
            }
            if (!cholesky_solve(d.Nm, nmax, d.rhs, d.qdd, n)) {
                status[0] = ELASTIC_SINGULAR_MASS;
                status[1] = k;
                return;
            }
            for (int r = 0; r < n; ++r) dx[nz + o + r] = d.qdd[r];
        } else {
            for (int a = 0; a < 3; ++a) {
                dx[nz + o + a] = (tau[o + a] - w[k * 6 + a]) / mk;
                b3[a] = tau[o + 3 + a] - w[k * 6 + 3 + a];
            }
            const double* A = (model.immobile ? model.Y_ref : d.Y) + k * 6 + 3;
            if (!solve_node_rotation(A, model.node(k).inertia, b3, o3)) {
                status[0] = ELASTIC_EULER_SINGULAR;
                status[1] = k;
                return;
            }
            for (int a = 0; a < 3; ++a) dx[nz + o + 3 + a] = o3[a];
        }
    }
    const double m0 = model.node(0).mass;
    for (int a = 0; a < 3; ++a) {
        dx[2 * nz - 6 + a] = -w[a] / m0;
        b3[a] = -w[3 + a];
    }
    const double* A = (model.immobile ? model.Y_ref : d.Y) + 3;
    if (!solve_node_rotation(A, model.node(0).inertia, b3, o3)) {
        status[0] = ELASTIC_EULER_SINGULAR;
        status[1] = 0;
        return;
    }
    for (int a = 0; a < 3; ++a) dx[2 * nz - 3 + a] = o3[a];
}

/// Add every interconnection's forces into w (N, 6) on the node frames already in d.frames (mobile model), or
/// the immobile model's K y + D dy; returns a status.
int add_interconnections(const SpatialCooperativeModel& model, SpatialCooperativeData& d, double* w) noexcept {
    const Interconnections& ic = model.interconnections;
    if (model.immobile) {
        spatial_linear_edges(ic, d.Y, d.dY, model.Y_ref, w);
        return ELASTIC_OK;
    }
    double Pi;
    const int st = spatial_elastic_edges(ic, d.Y, d.frames, w, &Pi);
    if (st != ELASTIC_OK) return st;
    spatial_damping_edges(ic, d.Y, d.dY, d.frames, w);
    return ELASTIC_OK;
}


}  // namespace

bool spatial_interconnection_wrenches(const SpatialCooperativeModel& model, const SpatialCooperativeData& d,
                                      SpatialControlTerms& t, bool charted) noexcept {
    const Interconnections& ic = model.interconnections;
    const int m = model.arm_count, N = m + 1;
    const double* Y = d.Y;
    for (int c = 0; c < N * 6; ++c) t.S[c] = 0.0;
    for (int c = 0; c < m * 6; ++c) t.Fw[c] = 0.0;
    double Linv[9], R0[9];
    const bool ok = body_rate_map_inverse(Y + 3, Linv);
    if (charted) {
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) R0[a * 3 + b] = d.frames[0].R[a][b];
    } else {
        rotation_zyx(Y + 3, R0);
    }
    double* Fe = t.Fe;
    for (int e = 0; e < ic.count; ++e) {
        for (int c = 0; c < N * 6; ++c) Fe[c] = 0.0;
        const Interconnections one{1, ic.edges + e, ic.params + static_cast<long>(e) * ic.width, ic.width};
        if (model.immobile) {
            spatial_linear_edges(one, Y, d.dY, model.Y_ref, Fe);
        } else {
            double Pi = 0.0;
            spatial_elastic_edges(one, Y, d.frames, Fe, &Pi);
            spatial_damping_edges(one, Y, d.dY, d.frames, Fe);
        }
        for (int c = 0; c < N * 6; ++c) t.S[c] += Fe[c];
        const int i = static_cast<int>(ic.edges[e].i), j = static_cast<int>(ic.edges[e].j);
        if ((i == 0 || j == 0) && ok) {
            const int c = i == 0 ? j : i;
            double* Fwc = t.Fw + (c - 1) * 6;
            const double f0 = -Fe[0], f1 = -Fe[1], f2 = -Fe[2];
            // body torque = Linv^T Q_A; world torque = R0 tb
            const double tb0 = -(Linv[0 * 3 + 0] * Fe[3] + Linv[1 * 3 + 0] * Fe[4] + Linv[2 * 3 + 0] * Fe[5]);
            const double tb1 = -(Linv[0 * 3 + 1] * Fe[3] + Linv[1 * 3 + 1] * Fe[4] + Linv[2 * 3 + 1] * Fe[5]);
            const double tb2 = -(Linv[0 * 3 + 2] * Fe[3] + Linv[1 * 3 + 2] * Fe[4] + Linv[2 * 3 + 2] * Fe[5]);
            const double d0 = Y[c * 6 + 0] - Y[0];
            const double d1 = Y[c * 6 + 1] - Y[1];
            const double d2 = Y[c * 6 + 2] - Y[2];
            Fwc[0] += f0;
            Fwc[1] += f1;
            Fwc[2] += f2;
            for (int a = 0; a < 3; ++a) {
                const double tw = R0[a * 3 + 0] * tb0 + R0[a * 3 + 1] * tb1 + R0[a * 3 + 2] * tb2;
                Fwc[3 + a] += tw;
            }
            Fwc[3] -= d1 * f2 - d2 * f1;
            Fwc[4] -= d2 * f0 - d0 * f2;
            Fwc[5] -= d0 * f1 - d1 * f0;
        }
    }
    return ok;
}

void spatial_node_state(const SpatialCooperativeModel& model, const double* x, int nx, int64_t* status,
                        SpatialCooperativeData& data) noexcept {
    const int nz = nx / 2;
    status[0] = ELASTIC_OK;
    for (int a = 0; a < 6; ++a) {
        data.Y[a] = x[nz - 6 + a];
        data.dY[a] = x[2 * nz - 6 + a];
    }
    arm_pass(model, x, x + nz, status, data);
}

void spatial_rhs(const SpatialCooperativeModel& model, const double* x, int nx, const double* tau, int64_t* status,
                 SpatialCooperativeData& d, double* dx) noexcept {
    const int nz = nx / 2;
    const int N = model.arm_count + 1;
    const double* dz = x + nz;
    status[0] = ELASTIC_OK;
    for (int a = 0; a < 6; ++a) {
        d.Y[a] = x[nz - 6 + a];
        d.dY[a] = dz[nz - 6 + a];
    }
    arm_pass(model, x, dz, status, d);
    for (int a = 0; a < nz; ++a) dx[a] = dz[a];
    if (status[0] != ELASTIC_OK) return;
    // node terms: Wr and w = gyroscopic - gravity (+ the interconnections below)
    if (model.immobile) {
        node_terms(d.Y, d.dY, N, model.node_rows, model.node_width, model.gravity, model.Y_ref, true, d.Wr, d.w);
    } else {  // node_terms and every node's frames, each node's sines and cosines evaluated once
        node_frames_terms(d.Y, d.dY, N, model.node_rows, model.node_width, model.gravity, d.frames, d.Wr, d.w);
    }
    const int st = add_interconnections(model, d, d.w);
    if (st != ELASTIC_OK) {
        status[0] = st;
        return;
    }
    accelerations(model, nz, tau, status, d, dx);
}

void spatial_control_terms(const SpatialCooperativeModel& model, const double* x, int nx, int64_t* status,
                           SpatialCooperativeData& d, SpatialControlTerms& terms) noexcept {
    spatial_node_state(model, x, nx, status, d);
    if (status[0] != ELASTIC_OK) return;
    const int N = model.arm_count + 1;
    if (model.immobile) {
        node_terms(d.Y, d.dY, N, model.node_rows, model.node_width, model.gravity, model.Y_ref, true, d.Wr,
                   terms.w_free);
    } else {  // node_terms and every node's frames, each node's sines and cosines evaluated once
        node_frames_terms(d.Y, d.dY, N, model.node_rows, model.node_width, model.gravity, d.frames, d.Wr,
                          terms.w_free);
    }
    for (int k = 0; k < N; ++k) {
        double* W = terms.W + k * 36;
        for (int a = 0; a < 3; ++a) {
            W[a * 6 + a] = model.node(k).mass;
            for (int b = 0; b < 3; ++b) W[(3 + a) * 6 + 3 + b] = d.Wr[k * 9 + a * 3 + b];
        }
    }
    if (!spatial_interconnection_wrenches(model, d, terms, model.charted())) {
        status[0] = ELASTIC_EULER_SINGULAR;
        status[1] = 0;
    }
}

void spatial_rhs_from_terms(const SpatialCooperativeModel& model, const double* x, int nx, const double* tau,
                            int64_t* status, SpatialCooperativeData& d, const SpatialControlTerms& terms,
                            double* dx) noexcept {
    const int nz = nx / 2;
    const int N = model.arm_count + 1;
    status[0] = ELASTIC_OK;
    for (int a = 0; a < nz; ++a) dx[a] = x[nz + a];
    for (int c = 0; c < N * 6; ++c) d.w[c] = terms.w_free[c];
    const int st = add_interconnections(model, d, d.w);
    if (st != ELASTIC_OK) {
        status[0] = st;
        return;
    }
    accelerations(model, nz, tau, status, d, dx);
}

double spatial_arm_potentials(const SpatialCooperativeModel& model, const double* x, ChainBody* work) noexcept {
    double U = 0.0;
    for (int i = 0; i < model.arm_count; ++i) {
        const SpatialCooperativeArm& a = model.arms[i];
        if (a.kind != ARM_CONTACT_POINT) U += chain_arm_potential(a.arm, x + a.q_offset, work);
    }
    return U;
}

}  // namespace plants
