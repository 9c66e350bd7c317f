// The plant's energy from the control terms the tick already has (docs/model.md s.3; coopctrl/loop/energy.py's
// plant_energy, expression for expression, so the same bits):
//     T = 1/2 sum_i dq_i^T H_i dq_i + 1/2 sum_{k=0}^{m} dY_k^T W_k dY_k,
//     E = T + Pi(Y) - sum_k m_k g . r_k + U_arms(q),
// (dq_i^T N_i dq_i = dq_i^T H_i dq_i + dY_i^T W_i dY_i with dY_i = J_i dq_i: the kinetic energy 1/2 z'^T Gamma z';
// a contact point has H = 0). Every term is the same in any rotation chart (dY^T W dY is the node's kinetic
// energy), so an arm of kind ARM_SERIAL_OWN_CHART counts as a serial arm. The data and terms are those the
// control terms filled at x; the mobile spatial model reads their node frames, the immobile model's potential is
// Pi = 1/2 y^T K y on y = Y - Y_ref.
#pragma once

#include "plants/core/cooperative_planar.h"
#include "plants/core/cooperative_spatial.h"

namespace plants {

/// The plant's energy at x: total E [J], kinetic T [J] and the elastic potential's status (ELASTIC_OK, or
/// ELASTIC_COINCIDENT_NODES where it is undefined; then E holds the partial sum of Pi).
struct PlantEnergy {
    double total;
    double kinetic;
    int status;
};

/// The energy's scratch: F (N, p) receives the elastic gradient (discarded), dY_zero (N, p) zeros (the immobile
/// model's springs are evaluated at zero rates); p = 6 spatial, 3 planar.
struct EnergyScratch {
    double* F;
    const double* dY_zero;
};

/// The spatial plant's energy; data and terms filled at x by spatial_control_terms (Y, dY, H, W, frames), the
/// arm potentials use data.chain as work.
PlantEnergy spatial_plant_energy(const SpatialCooperativeModel& model, const double* x, int nx,
                                 SpatialCooperativeData& data, const SpatialControlTerms& terms,
                                 const EnergyScratch& scratch) noexcept;

/// The planar plant's energy; data and terms filled at x by planar_control_terms (Y, dY, H, W).
PlantEnergy planar_plant_energy(const PlanarCooperativeModel& model, const double* x, int nx,
                                const PlanarCooperativeData& data, const PlanarControlTerms& terms,
                                const EnergyScratch& scratch) noexcept;

}  // namespace plants
