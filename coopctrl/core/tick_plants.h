// The plants a tick runs on, behind one interface: sense the control terms at a state (true or measured), give them
// by name, and serve the integrators as their Plant (explicit_schemes.h: rhs, first_rhs).
#pragma once

#include <cstdint>
#include <vector>

#include "plants/core/cooperative_planar.h"

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

/// A planar cooperative plant (plants/core/cooperative_planar.h) with its workspaces: one per set of terms and one
/// for the integrators' right-hand sides.
class PlanarTickPlant {
public:
    PlanarTickPlant(const plants::PlanarCooperativeModel& model, int nx)
        : model_(model), nx_(nx), work_{Work(model), Work(model)}, rhs_work_(model) {}

    void sense(const double* x, int64_t* status, TermsAt at) noexcept {
        Work& w = work_[at];
        plants::planar_control_terms(model_, x, nx_, status, w.data, w.terms);
    }
    SensedTerms terms(TermsAt at) const noexcept {
        const Work& w = work_[at];
        return SensedTerms{w.Y.data(), w.dY.data(), w.H.data(), w.h.data(), w.J.data(), w.Jdq.data(),
                           w.W.data(), w.w_free.data(), w.S.data(), w.Fw.data(), model_.nmax};
    }
    /// The integrators' Plant: dx = f(x, tau).
    void rhs(const double* x, const double* tau, double, double* dx, int64_t* status) noexcept {
        plants::planar_rhs(model_, x, nx_, tau, status, rhs_work_.data, dx);
    }
    /// The first right-hand side of a period: the planar plant evaluates it afresh (as the numba tick does).
    void first_rhs(const double* x, const double* tau, double t, double* dx, int64_t* status) noexcept {
        rhs(x, tau, t, dx, status);
    }

private:
    struct Work {
        std::vector<double> Y, dY, H, h, J, Jdq, w, Nm, rhs, qdd, chain, W, w_free, S, Fw, Fe;
        plants::PlanarCooperativeData data{};
        plants::PlanarControlTerms terms{};
        explicit Work(const plants::PlanarCooperativeModel& model) {
            const int N = model.arm_count + 1, m = model.arm_count, n = model.nmax;
            Y.assign(N * 3, 0.0), dY.assign(N * 3, 0.0), H.assign(m * n * n, 0.0), h.assign(m * n, 0.0);
            J.assign(m * 3 * n, 0.0), Jdq.assign(m * 3, 0.0), w.assign(N * 3, 0.0), Nm.assign(n * n, 0.0);
            rhs.assign(n, 0.0), qdd.assign(n, 0.0), chain.assign((n + 1) * plants::PLANAR_WORK_WIDTH, 0.0);
            W.assign(N * 9, 0.0), w_free.assign(N * 3, 0.0), S.assign(N * 3, 0.0), Fw.assign(m * 3, 0.0);
            Fe.assign(N * 3, 0.0);
            bind();
        }
        Work(const Work& other) : Y(other.Y), dY(other.dY), H(other.H), h(other.h), J(other.J), Jdq(other.Jdq),
              w(other.w), Nm(other.Nm), rhs(other.rhs), qdd(other.qdd), chain(other.chain), W(other.W),
              w_free(other.w_free), S(other.S), Fw(other.Fw), Fe(other.Fe) { bind(); }
        void bind() {
            data = plants::PlanarCooperativeData{Y.data(), dY.data(), H.data(), h.data(), J.data(), Jdq.data(),
                                                 w.data(), Nm.data(), rhs.data(), qdd.data(), chain.data()};
            terms = plants::PlanarControlTerms{W.data(), w_free.data(), S.data(), Fw.data(), Fe.data()};
        }
    };
    const plants::PlanarCooperativeModel& model_;
    int nx_;
    Work work_[2];
    Work rhs_work_;
};

}  // namespace coopctrl
