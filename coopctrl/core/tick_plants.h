// The plants a tick runs on, behind one interface: sense the control terms at a state (true or measured) and give
// them by name, the plant's energy at the sensed state, and serve the integrators as their Plant
// (explicit_schemes.h: rhs, first_rhs).
#pragma once

#include <cstdint>
#include <vector>

#include "plants/core/cooperative_energy.h"
#include "plants/core/cooperative_planar.h"
#include "plants/core/cooperative_planar_work.h"
#include "plants/core/cooperative_spatial.h"
#include "plants/core/cooperative_spatial_work.h"

namespace coopctrl {

/// Which of a tick's two sets of terms: at the true state, or at the measured one (noisy sensors).
enum TermsAt : int { TERMS_TRUE = 0, TERMS_MEASURED = 1 };

/// The control terms a tick senses at a state, by name: node rows (m + 1 nodes, row 0 the object) and arm rows.
struct SensedTerms {
    const double* Y;       ///< (m + 1, p) node poses [m, rad]
    const double* dY;      ///< (m + 1, p) node rates
    const double* H;       ///< (m, nmax, nmax) arm inertias [kg m^2]
    const double* h;       ///< (m, nmax) arm bias torques [N m]
    const double* J;       ///< (m, p, nmax) Jacobians
    const double* Jdq;     ///< (m, p) dJ/dt dq
    const double* W;       ///< (m + 1, p, p) node inertias
    const double* w_free;  ///< (m + 1, p) -m g (and the gyroscopic terms, spatial) [N, N m]
    const double* S;       ///< (m + 1, p) the interconnections' terms [N, N m]
    const double* Fw;      ///< (m, p) the wrench each contact applies to the object [N, N m]
    int nmax;              ///< the arms' row width
};

template <class Work>
SensedTerms sensed_terms(const Work& w) noexcept {
    return SensedTerms{w.Y.data(), w.dY.data(), w.H.data(), w.h.data(), w.J.data(), w.Jdq.data(),
                       w.W.data(), w.w_free.data(), w.S.data(), w.Fw.data(), w.nmax};
}

/// A planar cooperative plant (plants/core/cooperative_planar.h) with its workspaces: one per set of terms and one
/// for the integrators' right-hand sides.
class PlanarTickPlant {
public:
    PlanarTickPlant(const plants::PlanarCooperativeModel& model, int nx)
        : model_(model), nx_(nx), true_(model), measured_(model), rhs_(model),
          energy_F_((model.arm_count + 1) * 3, 0.0), energy_dY_zero_((model.arm_count + 1) * 3, 0.0) {}

    void sense(const double* x, int64_t* status, TermsAt at) noexcept {
        plants::PlanarWork& w = at == TERMS_TRUE ? true_ : measured_;
        plants::planar_control_terms(model_, x, nx_, status, w.data, w.terms);
    }
    SensedTerms terms(TermsAt at) const noexcept { return sensed_terms(at == TERMS_TRUE ? true_ : measured_); }
    /// The energy at x, whose true terms were just sensed: total and kinetic [J], status 0 or the elastic code.
    plants::PlantEnergy energy(const double* x) noexcept {
        const plants::EnergyScratch scratch{energy_F_.data(), energy_dY_zero_.data()};
        return plants::planar_plant_energy(model_, x, nx_, true_.data, true_.terms, scratch);
    }
    /// The integrators' Plant: dx = f(x, tau).
    void rhs(const double* x, const double* tau, double, double* dx, int64_t* status) noexcept {
        plants::planar_rhs(model_, x, nx_, tau, status, rhs_.data, dx);
    }
    /// The first right-hand side of a period: the planar plant evaluates it afresh (as the numba tick does).
    void first_rhs(const double* x, const double* tau, double t, double* dx, int64_t* status) noexcept {
        rhs(x, tau, t, dx, status);
    }

private:
    const plants::PlanarCooperativeModel& model_;
    int nx_;
    plants::PlanarWork true_, measured_, rhs_;
    std::vector<double> energy_F_, energy_dY_zero_;
};

/// A spatial cooperative plant (plants/core/cooperative_spatial.h) with its workspaces.
class SpatialTickPlant {
public:
    SpatialTickPlant(const plants::SpatialCooperativeModel& model, int nx)
        : model_(model), nx_(nx), true_(model), measured_(model), rhs_(model) {}

    void sense(const double* x, int64_t* status, TermsAt at) noexcept {
        plants::SpatialWork& w = at == TERMS_TRUE ? true_ : measured_;
        plants::spatial_control_terms(model_, x, nx_, status, w.data, w.terms);
    }
    SensedTerms terms(TermsAt at) const noexcept { return sensed_terms(at == TERMS_TRUE ? true_ : measured_); }
    plants::PlantEnergy energy(const double* x) noexcept {
        const plants::EnergyScratch scratch{true_.energy_F.data(), true_.energy_dY_zero.data()};
        return plants::spatial_plant_energy(model_, x, nx_, true_.data, true_.terms, scratch);
    }
    void rhs(const double* x, const double* tau, double, double* dx, int64_t* status) noexcept {
        plants::spatial_rhs(model_, x, nx_, tau, status, rhs_.data, dx);
    }
    /// The first right-hand side of a period, at the state whose true terms the tick has just sensed: finished
    /// from them (the same bits, one arm pass fewer).
    void first_rhs(const double* x, const double* tau, double, double* dx, int64_t* status) noexcept {
        plants::spatial_rhs_from_terms(model_, x, nx_, tau, status, true_.data, true_.terms, dx);
    }

private:
    const plants::SpatialCooperativeModel& model_;
    int nx_;
    plants::SpatialWork true_, measured_, rhs_;
};

}  // namespace coopctrl
