#include "plants/core/cooperative_planar.h"

#include <cmath>

#include "plants/core/cholesky.h"
#include "plants/core/elastic_planar.h"

namespace plants {

namespace {

/// The arm terms written straight into the stacked arrays and the node rows Y[1:], dY[1:].
void arm_pass(const PlanarCooperativeModel& model, const double* z, const double* dz,
              PlanarCooperativeData& d) noexcept {
    const int nmax = model.nmax;
    for (int i = 0; i < model.arm_count; ++i) {
        const PlanarCooperativeArm& a = model.arms[i];
        const int n = a.dof, o = a.q_offset;
        double* Yi = d.Y + (i + 1) * 3;
        double* dYi = d.dY + (i + 1) * 3;
        if (a.kind == ARM_SERIAL) {
            double* J = d.J + i * 3 * nmax;
            planar_arm_terms(a.arm, z + o, dz + o, d.H + i * nmax * nmax, nmax, d.h + i * nmax, Yi, J, nmax,
                             d.Jdq + i * 3, d.chain);
            for (int c = 0; c < 3; ++c) {
                double s = 0.0;
                for (int k = 0; k < n; ++k) s += J[c * nmax + k] * dz[o + k];
                dYi[c] = s;
            }
        } else {
            for (int c = 0; c < 3; ++c) {
                Yi[c] = z[o + c];
                dYi[c] = dz[o + c];
            }
        }
    }
}

}  // namespace

void planar_node_state(const PlanarCooperativeModel& model, const double* x, int nx, int64_t* status,
                       PlanarCooperativeData& data) noexcept {
    const int nz = nx / 2;
    status[0] = ELASTIC_OK;
    for (int a = 0; a < 3; ++a) {
        data.Y[a] = x[nz - 3 + a];
        data.dY[a] = x[2 * nz - 3 + a];
    }
    arm_pass(model, x, x + nz, data);
}

void planar_rhs(const PlanarCooperativeModel& model, const double* x, int nx, const double* tau, int64_t* status,
                PlanarCooperativeData& d, double* dx) noexcept {
    const int nz = nx / 2;
    const double* z = x;
    const double* dz = x + nz;
    const int m = model.arm_count, N = m + 1, nmax = model.nmax;
    status[0] = ELASTIC_OK;
    for (int a = 0; a < 3; ++a) {
        d.Y[a] = z[nz - 3 + a];
        d.dY[a] = dz[nz - 3 + a];
    }
    arm_pass(model, z, dz, d);
    for (int a = 0; a < nz; ++a) dx[a] = dz[a];
    double* w = d.w;
    for (int k = 0; k < N; ++k) {
        w[k * 3 + 0] = -model.nodes[k].mass * model.gravity[0];
        w[k * 3 + 1] = -model.nodes[k].mass * model.gravity[1];
        w[k * 3 + 2] = 0.0;
    }
    const int st = planar_interconnection_terms(model.interconnections, d.Y, d.dY, model.Y_ref, model.immobile, w);
    if (st != ELASTIC_OK) {
        status[0] = st;
        return;
    }
    for (int i = 0; i < m; ++i) {
        const PlanarCooperativeArm& arm = model.arms[i];
        const int n = arm.dof, o = arm.q_offset, k = i + 1;
        const double mk = model.nodes[k].mass, Ik = model.nodes[k].inertia;
        if (arm.kind == ARM_SERIAL) {
            const double* H = d.H + i * nmax * nmax;
            const double* h = d.h + i * nmax;
            const double* J = d.J + i * 3 * nmax;
            const double* Jdq = d.Jdq + i * 3;
            const double v0 = mk * Jdq[0] + w[k * 3 + 0];
            const double v1 = mk * Jdq[1] + w[k * 3 + 1];
            const double v2 = Ik * Jdq[2] + w[k * 3 + 2];
            for (int r = 0; r < n; ++r) {
                d.rhs[r] = tau[o + r] - h[r] - (J[0 * nmax + r] * v0 + J[1 * nmax + r] * v1 + J[2 * nmax + r] * v2);
                for (int c = r; c < n; ++c) {
                    const double s = (H[r * nmax + c] + mk * (J[0 * nmax + r] * J[0 * nmax + c] +
                                                              J[1 * nmax + r] * J[1 * nmax + c])) +
                                     Ik * J[2 * nmax + r] * J[2 * nmax + c];
                    d.Nm[r * nmax + c] = s;
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
            dx[nz + o] = (tau[o] - w[k * 3 + 0]) / mk;
            dx[nz + o + 1] = (tau[o + 1] - w[k * 3 + 1]) / mk;
            dx[nz + o + 2] = (tau[o + 2] - w[k * 3 + 2]) / Ik;
        }
    }
    dx[2 * nz - 3] = -w[0] / model.nodes[0].mass;
    dx[2 * nz - 2] = -w[1] / model.nodes[0].mass;
    dx[2 * nz - 1] = -w[2] / model.nodes[0].inertia;
}

void planar_interconnection_wrenches(const PlanarCooperativeModel& model, const PlanarCooperativeData& data,
                                     PlanarControlTerms& terms) noexcept {
    const int m = model.arm_count, N = m + 1;
    const Interconnections& ic = model.interconnections;
    const double* Y = data.Y;
    for (int c = 0; c < N * 3; ++c) terms.S[c] = 0.0;
    for (int c = 0; c < m * 3; ++c) terms.Fw[c] = 0.0;
    for (int e = 0; e < ic.count; ++e) {
        double* Fe = terms.Fe;
        for (int c = 0; c < N * 3; ++c) Fe[c] = 0.0;
        const Interconnections one{1, ic.edges + e, ic.params + static_cast<long>(e) * ic.width, ic.width};
        if (model.immobile) {
            planar_linear_edges(one, Y, data.dY, model.Y_ref, Fe);
        } else {
            double Pi = 0.0;
            planar_elastic_edges(one, Y, Fe, &Pi);
            planar_damping_edges(one, Y, data.dY, Fe);
        }
        for (int c = 0; c < N * 3; ++c) terms.S[c] += Fe[c];
        const int i = static_cast<int>(ic.edges[e].i), j = static_cast<int>(ic.edges[e].j);
        if (i == 0 || j == 0) {
            const int c = i == 0 ? j : i;
            const double f0 = -Fe[0], f1 = -Fe[1];
            const double d0 = Y[c * 3 + 0] - Y[0];
            const double d1 = Y[c * 3 + 1] - Y[1];
            terms.Fw[(c - 1) * 3 + 0] += f0;
            terms.Fw[(c - 1) * 3 + 1] += f1;
            terms.Fw[(c - 1) * 3 + 2] += -Fe[2] - (d0 * f1 - d1 * f0);
        }
    }
}

void planar_control_terms(const PlanarCooperativeModel& model, const double* x, int nx, int64_t* status,
                          PlanarCooperativeData& data, PlanarControlTerms& terms) noexcept {
    planar_node_state(model, x, nx, status, data);
    const int m = model.arm_count, N = m + 1;
    for (int k = 0; k < N; ++k) {
        double* W = terms.W + k * 9;
        W[0] = model.nodes[k].mass;
        W[4] = model.nodes[k].mass;
        W[8] = model.nodes[k].inertia;
        terms.w_free[k * 3 + 0] = -model.nodes[k].mass * model.gravity[0];
        terms.w_free[k * 3 + 1] = -model.nodes[k].mass * model.gravity[1];
        terms.w_free[k * 3 + 2] = 0.0;
    }
    planar_interconnection_wrenches(model, data, terms);
}

double planar_arm_potentials(const PlanarCooperativeModel& model, const double* x) noexcept {
    double U = 0.0;
    for (int i = 0; i < model.arm_count; ++i) {
        const PlanarCooperativeArm& a = model.arms[i];
        if (a.kind == ARM_SERIAL) U += planar_arm_potential(a.arm, x + a.q_offset);
    }
    return U;
}

}  // namespace plants
