// The singly diagonally implicit Runge-Kutta schemes (implicit midpoint, implicit Euler) over one control period,
// the inputs held (coopctrl/integrators/compiled.py's docstring and DiagonallyImplicitRungeKutta's state the stages,
// the simplified Newton iteration, the Jacobian reuse and the stopping tests). The Plant is that of
// explicit_schemes.h.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "coopctrl/core/dense.h"
#include "coopctrl/core/explicit_schemes.h"
#include "coopctrl/core/integration_plan.h"

namespace coopctrl {

/// J = df/dx (nx x nx, row-major) at x (fx = f(x)) by forward differences: column j is (f(x + d_j e_j) - fx) / d_j
/// with d_j = sqrt(eps) max(|x_j|, 1) rounded to a representable increment; xp, fp (nx,) work. Returns false on a
/// right-hand-side failure (x_fail set).
template <class Plant>
bool jacobian_into(double* J, const double* x, int nx, const double* tau, Plant& plant, int64_t* status, double t,
                   const double* fx, double* xp, double* fp, double* x_fail, AdvanceReport& report) noexcept {
    const double sqrt_eps = std::sqrt(std::numeric_limits<double>::epsilon());
    for (int c = 0; c < nx; ++c) xp[c] = x[c];
    for (int j = 0; j < nx; ++j) {
        const double xj = x[j];
        double d = sqrt_eps * std::fmax(std::fabs(xj), 1.0);
        xp[j] = xj + d;
        d = xp[j] - xj;  // the exactly representable increment
        plant.rhs(xp, tau, t, fp, status);
        if (stage_failed(xp, nx, status, x_fail, report)) return false;
        for (int r = 0; r < nx; ++r) J[r * nx + j] = (fp[r] - fx[r]) / d;
        xp[j] = xj;
    }
    return true;
}

/// plan.M = (I - gh J)^-1 with J the forward-difference Jacobian at x (fx = f(x)); the pseudo-inverse where the
/// matrix is singular. Returns false on a right-hand-side failure (x_fail set).
template <class Plant>
bool refresh_iteration_matrix(const ImplicitPlan& plan, const double* x, int nx, const double* tau, Plant& plant,
                              int64_t* status, double t, const double* fx, double gh, double* x_fail,
                              AdvanceReport& report) noexcept {
    double* A = plan.A;
    plan.memo[2] += 1.0;
    if (!jacobian_into(A, x, nx, tau, plant, status, t, fx, plan.xp, plan.fp, x_fail, report)) return false;
    for (int r = 0; r < nx; ++r)
        for (int j = 0; j < nx; ++j) A[r * nx + j] = (r == j ? 1.0 : 0.0) - gh * A[r * nx + j];
    if (!invert_into(A, nx, plan.LU, plan.M)) pinv_into(A, nx, plan.M, plan.pinv_work);
    return true;
}

/// One step h [s] of the implicit plan on x in place. Returns STEP_OK, STEP_PLANT_ERROR, or STEP_NEWTON_FAILED
/// with the failed stage's iterations and last correction h max|dk| in *iterations, *correction.
template <class Plant>
int sdirk_step(const ImplicitPlan& plan, double* x, int nx, const double* tau, Plant& plant, int64_t* status,
               double t, double h, double* x_fail, AdvanceReport& report, int64_t* iterations,
               double* correction_out) noexcept {
    const double sqrt_eps = std::sqrt(std::numeric_limits<double>::epsilon());
    const double inf = std::numeric_limits<double>::infinity();
    const double rtol = plan.rtol, atol = plan.atol, reuse_rate = plan.reuse_rate;
    const int64_t max_iterations = plan.max_iterations;
    const int s = plan.stages;
    const double *tableau = plan.tableau, *weights = plan.weights, *nodes = plan.nodes;
    double *M = plan.M, *slopes = plan.slopes, *predictors = plan.predictors, *memo = plan.memo;
    double *known = plan.known, *k = plan.k, *xs = plan.xs, *fs = plan.fs, *dk = plan.dk;
    const int n = nx;
    const double gamma = tableau[0];
    // a matrix made for another step, or dropped after a slow step: a cold start (no predictors)
    bool have_M = memo[0] != 0.0 && memo[1] == h;
    const bool warm = have_M;
    const double gh = gamma * h;
    bool fresh = false;  // M was evaluated during this step
    bool slow = false;   // some stage converged slower than reuse_rate
    const double xmax = max_abs(x, n);
    const double tol = atol + rtol * xmax;
    for (int i = 0; i < s; ++i) {
        const double ts = t + nodes[i] * h;
        for (int c = 0; c < n; ++c) known[c] = x[c];  // S_i = x + h sum_{j<i} a_ij k_j
        for (int j = 0; j < i; ++j) {
            const double a = tableau[i * s + j];
            if (a != 0.0) {
                const double ah = a * h;
                for (int c = 0; c < n; ++c) known[c] += ah * slopes[j * n + c];
            }
        }
        if (warm) {
            for (int c = 0; c < n; ++c) k[c] = predictors[i * n + c];
        } else if (i == 0) {  // the explicit slope as predictor
            plant.rhs(x, tau, t, k, status);
            if (stage_failed(x, n, status, x_fail, report)) return STEP_PLANT_ERROR;
        } else {
            for (int c = 0; c < n; ++c) k[c] = slopes[(i - 1) * n + c];
        }
        double previous = inf, rate = 0.0, correction = 0.0;
        int64_t total = 0;
        while (true) {
            for (int c = 0; c < n; ++c) xs[c] = k[c] * gh + known[c];
            plant.rhs(xs, tau, ts, fs, status);
            if (stage_failed(xs, n, status, x_fail, report)) return STEP_PLANT_ERROR;
            if (!have_M) {
                if (!refresh_iteration_matrix(plan, xs, n, tau, plant, status, ts, fs, gh, x_fail, report))
                    return STEP_PLANT_ERROR;
                memo[0] = 1.0;
                memo[1] = h;
                have_M = true;
                fresh = true;
                previous = inf;
            }
            for (int r = 0; r < n; ++r) {  // dk = M (k - fs)
                double acc = 0.0;
                for (int c = 0; c < n; ++c) acc += M[r * n + c] * (k[c] - fs[c]);
                dk[r] = acc;
            }
            for (int c = 0; c < n; ++c) k[c] -= dk[c];
            total += 1;
            correction = h * max_abs(dk, n);
            if (correction <= tol || correction <= tol + rtol * h * max_abs(k, n)) break;
            if (!std::isfinite(correction)) {
                if (fresh) {
                    memo[0] = 0.0;
                    *iterations = total;
                    *correction_out = correction;
                    return STEP_NEWTON_FAILED;
                }
                plant.rhs(x, tau, t, k, status);  // the stale matrix threw the iterate away: restart
                if (stage_failed(x, n, status, x_fail, report)) return STEP_PLANT_ERROR;
                have_M = false;
                continue;
            }
            rate = correction / previous;
            const double hk = h * max_abs(k, n);
            if (fresh && rate > 0.5 && correction <= sqrt_eps * (hk > xmax ? hk : xmax))
                break;  // stagnating at the round-off floor of f: as converged as it can be
            if (total >= max_iterations) {
                memo[0] = 0.0;
                *iterations = total;
                *correction_out = correction;
                return STEP_NEWTON_FAILED;
            }
            if (rate > reuse_rate) have_M = false;  // slow: evaluate the Jacobian again at the current iterate
            previous = correction;
        }
        slow = slow || !(total <= 2 || rate <= reuse_rate);
        for (int c = 0; c < n; ++c) slopes[i * n + c] = k[c];
    }
    if (slow) memo[0] = 0.0;  // slow this step: refresh at the start of the next one
    for (int i = 0; i < s * n; ++i) predictors[i] = slopes[i];
    for (int i = 0; i < s; ++i) {
        const double bh = weights[i] * h;
        for (int c = 0; c < n; ++c) x[c] += bh * slopes[i * n + c];
    }
    return STEP_OK;
}

/// The implicit plan over the steps [s] of one period from t [s].
template <class Plant>
int implicit_period(const ImplicitPlan& plan, double* x, int nx, const double* tau, Plant& plant, int64_t* status,
                    double t, const double* steps, int nsteps, double* x_fail, AdvanceReport& report) noexcept {
    double ts = t;
    for (int si = 0; si < nsteps; ++si) {
        const double hs = steps[si];
        int64_t iterations = 0;
        double correction = 0.0;
        const int code = sdirk_step(plan, x, nx, tau, plant, status, ts, hs, x_fail, report, &iterations,
                                    &correction);
        if (code == STEP_NEWTON_FAILED) {
            report.failed_step = si;
            report.newton_iterations = iterations;
            report.last_correction = correction;
            report.failed_time = ts;
        }
        if (code != STEP_OK) return code;
        ts += hs;
    }
    return STEP_OK;
}

}  // namespace coopctrl
