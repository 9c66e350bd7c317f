#include "plants/core/cooperative_energy.h"

#include "plants/core/chain_arm.h"
#include "plants/core/elastic_planar.h"
#include "plants/core/elastic_spatial.h"
#include "plants/core/planar_arm.h"

namespace plants {

namespace {

/// T = 1/2 (sum_i dq_i^T H_i dq_i + sum_k dY_k^T W_k dY_k) over the serial arms (H (m, nmax, nmax)) and the N
/// nodes (dY (N, p), W (N, p, p), the whole blocks); Arm is a planar or spatial cooperative arm.
template <class Arm>
double kinetic(const Arm* arms, int m, int nmax, const double* x, int nz, const double* H, int N, int p,
               const double* dY, const double* W) noexcept {
    double T = 0.0;
    for (int i = 0; i < m; ++i) {
        if (arms[i].kind == ARM_CONTACT_POINT) continue;
        const int n = arms[i].dof, o = nz + arms[i].q_offset;
        const double* Hi = H + i * nmax * nmax;
        for (int r = 0; r < n; ++r) {
            double s = 0.0;
            for (int c = 0; c < n; ++c) s += Hi[r * nmax + c] * x[o + c];
            T += x[o + r] * s;
        }
    }
    for (int k = 0; k < N; ++k) {
        const double* Wk = W + k * p * p;
        const double* dYk = dY + k * p;
        for (int a = 0; a < p; ++a) {
            double s = 0.0;
            for (int b = 0; b < p; ++b) s += Wk[a * p + b] * dYk[b];
            T += dYk[a] * s;
        }
    }
    return 0.5 * T;
}

/// -sum_k m_k g . r_k [J]: Y (N, p), the positions its first g_count columns; mass(k) node k's mass.
template <class Mass>
double gravity_potential(const double* Y, int N, int p, const double* gravity, int g_count, Mass mass) noexcept {
    double U = 0.0;
    for (int k = 0; k < N; ++k) {
        double s = 0.0;
        for (int a = 0; a < g_count; ++a) s += Y[k * p + a] * gravity[a];
        U -= mass(k) * s;
    }
    return U;
}

}  // namespace

PlantEnergy spatial_plant_energy(const SpatialCooperativeModel& model, const double* x, int nx,
                                 SpatialCooperativeData& data, const SpatialControlTerms& terms,
                                 const EnergyScratch& scratch) noexcept {
    const int m = model.arm_count, N = m + 1;
    const double T = kinetic(model.arms, m, model.nmax, x, nx / 2, data.H, N, 6, data.dY, terms.W);
    for (int c = 0; c < N * 6; ++c) scratch.F[c] = 0.0;
    int status = ELASTIC_OK;
    double Pi;
    if (model.immobile) {
        Pi = spatial_linear_edges(model.interconnections, data.Y, scratch.dY_zero, model.Y_ref, scratch.F);
    } else {
        status = spatial_elastic_edges(model.interconnections, data.Y, data.frames, scratch.F, &Pi);
    }
    double U = 0.0;
    for (int i = 0; i < m; ++i) {
        const SpatialCooperativeArm& a = model.arms[i];
        if (a.kind != ARM_CONTACT_POINT)  // a serial arm, its node in the world or in its own chart
            U += chain_arm_potential(a.arm, x + a.q_offset, data.chain);
    }
    const double G = gravity_potential(data.Y, N, 6, model.gravity, 3, [&](int k) { return model.node(k).mass; });
    return PlantEnergy{T + Pi + G + U, T, status};
}

PlantEnergy planar_plant_energy(const PlanarCooperativeModel& model, const double* x, int nx,
                                const PlanarCooperativeData& data, const PlanarControlTerms& terms,
                                const EnergyScratch& scratch) noexcept {
    const int m = model.arm_count, N = m + 1;
    const double T = kinetic(model.arms, m, model.nmax, x, nx / 2, data.H, N, 3, data.dY, terms.W);
    for (int c = 0; c < N * 3; ++c) scratch.F[c] = 0.0;
    int status = ELASTIC_OK;
    double Pi;
    if (model.immobile) {
        Pi = planar_linear_edges(model.interconnections, data.Y, scratch.dY_zero, model.Y_ref, scratch.F);
    } else {
        status = planar_elastic_edges(model.interconnections, data.Y, scratch.F, &Pi);
    }
    double U = 0.0;
    for (int i = 0; i < m; ++i) {
        const PlanarCooperativeArm& a = model.arms[i];
        if (a.kind == ARM_SERIAL) U += planar_arm_potential(a.arm, x + a.q_offset);
    }
    const double G = gravity_potential(data.Y, N, 3, model.gravity, 2, [&](int k) { return model.nodes[k].mass; });
    return PlantEnergy{T + Pi + G + U, T, status};
}

}  // namespace plants
