// The explicit fixed-step schemes over one control period, the inputs held (zero-order hold): Euler, symplectic
// Euler and RK4, as coopctrl/integrators/compiled.py's docstring states them, expression for expression.
//
// A Plant is any type with
//     void rhs(const double* x, const double* tau, double t, double* dx, int64_t* status);
//     void first_rhs(const double* x, const double* tau, double t, double* dx, int64_t* status);
// that writes dx = f(t, x, tau) and status[0] = 0, or status[0] != 0 (and status[1] a detail) where it fails.
// first_rhs is the first evaluation of a period, at the state whose control terms the tick has just evaluated
// (a plant may finish the right-hand side from them: the same bits, one arm pass fewer).
#pragma once

#include <cstdint>

#include "coopctrl/core/integration_plan.h"

namespace coopctrl {

/// After one right-hand-side evaluation at y: count it, and tell whether the plant failed there (y kept in
/// x_fail, the plant's status in the report).
inline bool stage_failed(const double* y, int nx, const int64_t* status, double* x_fail,
                         AdvanceReport& report) noexcept {
    report.rhs_evaluations += 1;
    if (status[0] != 0) {
        for (int c = 0; c < nx; ++c) x_fail[c] = y[c];
        report.plant_status[0] = status[0];
        report.plant_status[1] = status[1];
        return true;
    }
    return false;
}

/// One step h [s] of plan.method from t [s], x advanced in place:
/// - euler: x' = x + h f(t, x);
/// - symplectic_euler: dz' = dz + h ddz(t, x), then z' = z + h dz';
/// - rk4: k1 = f(t, x), k2 = f(t + h/2, x + h/2 k1), k3 = f(t + h/2, x + h/2 k2), k4 = f(t + h, x + h k3),
///   x' = x + h/6 ((k2 + k3) 2 + k1 + k4).
template <class Plant>
int explicit_step(const ExplicitPlan& plan, double* x, int nx, const double* tau, Plant& plant, int64_t* status,
                  bool first, double t, double hs, double* x_fail, AdvanceReport& report) noexcept {
    double *k1 = plan.k1, *k2 = plan.k2, *k3 = plan.k3, *k4 = plan.k4, *y = plan.y;
    const int nz = nx / 2;
    if (first)
        plant.first_rhs(x, tau, t, k1, status);
    else
        plant.rhs(x, tau, t, k1, status);
    if (stage_failed(x, nx, status, x_fail, report)) return STEP_PLANT_ERROR;
    if (plan.method == METHOD_RK4) {
        const double h2 = 0.5 * hs;
        for (int c = 0; c < nx; ++c) y[c] = k1[c] * h2 + x[c];
        plant.rhs(y, tau, t + h2, k2, status);
        if (stage_failed(y, nx, status, x_fail, report)) return STEP_PLANT_ERROR;
        for (int c = 0; c < nx; ++c) y[c] = k2[c] * h2 + x[c];
        plant.rhs(y, tau, t + h2, k3, status);
        if (stage_failed(y, nx, status, x_fail, report)) return STEP_PLANT_ERROR;
        for (int c = 0; c < nx; ++c) y[c] = k3[c] * hs + x[c];
        plant.rhs(y, tau, t + hs, k4, status);
        if (stage_failed(y, nx, status, x_fail, report)) return STEP_PLANT_ERROR;
        const double h6 = hs / 6.0;
        for (int c = 0; c < nx; ++c) x[c] = ((((k2[c] + k3[c]) * 2.0) + k1[c]) + k4[c]) * h6 + x[c];
    } else if (plan.method == METHOD_SYMPLECTIC_EULER) {
        for (int c = 0; c < nz; ++c) x[nz + c] = k1[nz + c] * hs + x[nz + c];
        for (int c = 0; c < nz; ++c) x[c] = x[nz + c] * hs + x[c];
    } else {
        for (int c = 0; c < nx; ++c) x[c] = k1[c] * hs + x[c];
    }
    return STEP_OK;
}

/// The explicit plan over the steps [s] of one period from t [s]; the first step's first slope by first_rhs.
template <class Plant>
int explicit_period(const ExplicitPlan& plan, double* x, int nx, const double* tau, Plant& plant, int64_t* status,
                    double t, const double* steps, int nsteps, double* x_fail, AdvanceReport& report) noexcept {
    double ts = t;
    for (int si = 0; si < nsteps; ++si) {
        const double hs = steps[si];
        const int code = explicit_step(plan, x, nx, tau, plant, status, si == 0, ts, hs, x_fail, report);
        if (code != STEP_OK) return code;
        ts += hs;
    }
    return STEP_OK;
}

}  // namespace coopctrl
