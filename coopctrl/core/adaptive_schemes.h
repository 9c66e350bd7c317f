// The error-controlled schemes over one control period, the inputs held: the embedded pairs rk23 and rk45 with
// their step controllers, TR-BDF2 with its simplified Newton iteration, and the first step of a run
// (coopctrl/integrators/adaptive_plans.py, expression for expression: its module docstring states the schemes,
// the controllers and the step statistics). The Plant is that of explicit_schemes.h; an autonomous plant ignores
// the time, a Python f gets each stage's time.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "coopctrl/core/adaptive_plan.h"
#include "coopctrl/core/dense.h"
#include "coopctrl/core/explicit_schemes.h"
#include "coopctrl/core/implicit_schemes.h"
#include "coopctrl/core/integration_plan.h"

namespace coopctrl {

namespace adaptive_detail {

/// Python's max(a, b): b if b > a, else a (so a NaN in b gives a, a NaN in a gives a).
inline double py_max(double a, double b) noexcept { return b > a ? b : a; }
/// Python's min(a, b): b if b < a, else a.
inline double py_min(double a, double b) noexcept { return b < a ? b : a; }
inline int64_t py_max(int64_t a, int64_t b) noexcept { return b > a ? b : a; }

/// The statistics row of the tick k = round(t / T), or nullptr outside the plan's rows.
inline StepStatistics* tick_row(const StepControl& control, double t) noexcept {
    const int64_t k = static_cast<int64_t>(t / control.period + 0.5);
    return 0 <= k && k < control.ticks ? control.stats + k : nullptr;
}

inline void record(StepStatistics* row, int64_t accepted, int64_t rejected, int64_t evaluations,
                   double hmin) noexcept {
    if (row == nullptr) return;
    row->accepted = static_cast<double>(accepted);
    row->rejected = static_cast<double>(rejected);
    row->rhs_evaluations = static_cast<double>(evaluations);
    row->min_step = hmin;
}

/// sqrt(mean((e_c / (atol_c + rtol max(|x_c|, |xn_c|)))^2)); NaN if any term is.
inline double rms_scaled(const double* e, const double* x, const double* xn, const double* atol, double rtol,
                         int n) noexcept {
    double acc = 0.0;
    for (int c = 0; c < n; ++c) {
        const double sc = atol[c] + rtol * py_max(std::fabs(x[c]), std::fabs(xn[c]));
        const double v = e[c] / sc;
        acc += v * v;
    }
    return std::sqrt(acc / n);
}

/// TR-BDF2's coefficients: gamma = 2 - sqrt(2), d = gamma / 2, w = sqrt(2) / 4, and the error weights b - bh with
/// b = (w, w, d), bh = ((1 - w) / 3, (3 w + 1) / 3, d / 3).
struct TRBDF2Coefficients {
    double gamma, d, w, e1, e2, e3;
    TRBDF2Coefficients() noexcept {
        gamma = 2.0 - std::sqrt(2.0);
        d = gamma / 2.0;
        w = std::sqrt(2.0) / 4.0;
        e1 = w - (1.0 - w) / 3.0;
        e2 = w - (3.0 * w + 1.0) / 3.0;
        e3 = d - d / 3.0;
    }
};

/// What a TR-BDF2 stage's Newton iteration ended with.
enum StageResult : int { STAGE_CONVERGED = 0, STAGE_NOT_CONVERGED = 1, STAGE_PLANT_ERROR = 2 };

}  // namespace adaptive_detail

/// The first step [s] of a run (scipy's select_initial_step; Hairer, Norsett and Wanner I, II.4):
/// h0 = 0.01 |x| / |f0| in the tolerance norm (1e-6 s when either is below 1e-5), then
/// h1 = (0.01 / max(|f0|, |f1 - f0| / h0))^(1 / (order + 1)) from one explicit Euler step to y1 (f1 = f(y1));
/// min(100 h0, h1, interval). Returns -1.0 on a right-hand-side failure (y1 holds the state; not counted).
template <class Plant>
double initial_step(const double* x, int nx, const double* f0, double* y1, double* f1, const double* atol,
                    double rtol, double order, double interval, const double* tau, Plant& plant, int64_t* status,
                    double t) noexcept {
    using adaptive_detail::py_max;
    using adaptive_detail::py_min;
    const int n = nx;
    double d0 = 0.0, d1 = 0.0;
    for (int c = 0; c < n; ++c) {
        const double sc = atol[c] + std::fabs(x[c]) * rtol;
        const double vx = x[c] / sc, vf = f0[c] / sc;
        d0 += vx * vx;
        d1 += vf * vf;
    }
    d0 = std::sqrt(d0 / n);
    d1 = std::sqrt(d1 / n);
    double h0 = d0 < 1e-5 || d1 < 1e-5 ? 1e-6 : 0.01 * d0 / d1;
    h0 = py_min(h0, interval);
    for (int c = 0; c < n; ++c) y1[c] = x[c] + h0 * f0[c];
    plant.rhs(y1, tau, t + h0, f1, status);
    if (status[0] != 0) return -1.0;
    double d2 = 0.0;
    for (int c = 0; c < n; ++c) {
        const double sc = atol[c] + std::fabs(x[c]) * rtol;
        const double v = (f1[c] - f0[c]) / sc;
        d2 += v * v;
    }
    d2 = std::sqrt(d2 / n) / h0;
    const double h1 = d1 <= 1e-15 && d2 <= 1e-15 ? py_max(1e-6, h0 * 1e-3)
                                                  : std::pow(0.01 / py_max(d1, d2), 1.0 / (order + 1.0));
    return py_min(py_min(100.0 * h0, h1), interval);
}

/// The explicit pair over one control period [t, t + T], x (nx) advanced in place. Returns STEP_OK,
/// STEP_PLANT_ERROR (x_fail set) or STEP_TOO_SMALL (too_small set); the tick's statistics row is written (but at a
/// plant error), the run's evaluations counted on in report.rhs_evaluations.
template <class Plant>
int embedded_advance(const EmbeddedPlan& plan, double* x, int nx, const double* tau, Plant& plant, int64_t* status,
                     double t, double* x_fail, AdvanceReport& report, TooSmallStep& too_small) noexcept {
    using adaptive_detail::py_max;
    using adaptive_detail::py_min;
    const StepControl& st = plan.control;
    const double *A = plan.A, *B = plan.B, *C = plan.C, *E = plan.E, *atol = st.atol;
    double *K = plan.K, *y = plan.y, *ynew = plan.ynew;
    AdaptiveMemo& memo = *st.memo;
    const double rtol = st.rtol, min_step = st.min_step, safety = st.safety;
    const double min_factor = st.min_factor, max_factor = st.max_factor;
    const int controller = st.controller;
    const double period = st.period;
    const double kexp = st.error_order + 1.0;
    const double beta1 = 0.7 / kexp;
    const double beta2 = 0.4 / kexp;
    const int n = nx;
    const int s = plan.stages;
    double* K_first = K;          // row 0: the slope at the step's start
    double* K_last = K + s * n;   // row s: the slope at its end (first-same-as-last)
    const double t_end = t + period;
    StepStatistics* row = adaptive_detail::tick_row(st, t);
    const int64_t evals0 = report.rhs_evaluations;
    int64_t accepted = 0, rejected = 0;
    double hmin = std::numeric_limits<double>::infinity();
    plant.first_rhs(x, tau, t, K_first, status);  // the torque changed at t: a fresh first slope
    if (stage_failed(x, n, status, x_fail, report)) return STEP_PLANT_ERROR;
    double h_abs;
    if (controller == CONTROLLER_FIXED) {
        h_abs = memo.fixed_step;
    } else if (memo.carry > 0.0) {
        h_abs = memo.carry;
    } else {
        h_abs = initial_step(x, n, K_first, y, K_last, atol, rtol, st.error_order, period, tau, plant, status, t);
        report.rhs_evaluations += 1;
        if (h_abs < 0.0) {
            for (int c = 0; c < n; ++c) x_fail[c] = y[c];
            return STEP_PLANT_ERROR;
        }
    }
    double t_cur = t;
    while (t_cur < t_end) {
        bool step_rejected = false;
        double h, t_new;
        while (true) {
            if (h_abs < min_step && controller != CONTROLLER_FIXED) {
                too_small.step = h_abs;
                too_small.time = t_cur;
                for (int c = 0; c < n; ++c) x_fail[c] = x[c];
                adaptive_detail::record(row, accepted, rejected, report.rhs_evaluations - evals0, hmin);
                return STEP_TOO_SMALL;
            }
            const double proposal = h_abs;
            const double to_end = t_end - t_cur;
            if (controller == CONTROLLER_PI && h_abs < to_end && to_end < 2.0 * h_abs)
                h_abs = 0.5 * (t_end - t_cur);  // two even steps to the instant, not a sliver after a full one
            t_new = t_cur + h_abs;
            const bool clipped = t_new - t_end > 0.0 || h_abs < proposal;
            if (t_new - t_end > 0.0) t_new = t_end;
            h = t_new - t_cur;
            for (int i = 1; i < s; ++i) {
                for (int c = 0; c < n; ++c) {
                    double acc = 0.0;
                    for (int j = 0; j < i; ++j) acc += K[j * n + c] * A[i * s + j];
                    y[c] = acc * h + x[c];
                }
                plant.rhs(y, tau, t_cur + C[i] * h, K + i * n, status);
                if (stage_failed(y, n, status, x_fail, report)) return STEP_PLANT_ERROR;
            }
            for (int c = 0; c < n; ++c) {
                double acc = 0.0;
                for (int j = 0; j < s; ++j) acc += K[j * n + c] * B[j];
                ynew[c] = x[c] + h * acc;
            }
            plant.rhs(ynew, tau, t_new, K_last, status);
            if (stage_failed(ynew, n, status, x_fail, report)) return STEP_PLANT_ERROR;
            double err;
            if (controller == CONTROLLER_FIXED) {
                err = 0.0;
            } else {
                double acc2 = 0.0;
                for (int c = 0; c < n; ++c) {
                    double e = 0.0;
                    for (int j = 0; j <= s; ++j) e += K[j * n + c] * E[j];
                    e *= h;
                    const double sc = atol[c] + py_max(std::fabs(x[c]), std::fabs(ynew[c])) * rtol;
                    const double v = e / sc;
                    acc2 += v * v;
                }
                err = std::sqrt(acc2 / n);
            }
            if (err < 1.0) {
                double factor;
                if (controller == CONTROLLER_FIXED) {
                    factor = 1.0;
                } else if (err == 0.0) {
                    factor = max_factor;
                } else if (controller == CONTROLLER_PI && memo.error_prev > 0.0) {
                    factor = safety * std::pow(err, -beta1) * std::pow(memo.error_prev, beta2);
                    factor = py_min(max_factor, py_max(min_factor, factor));
                } else {
                    factor = py_min(max_factor, safety * std::pow(err, -1.0 / kexp));
                }
                if (step_rejected) factor = py_min(1.0, factor);
                h_abs = h * factor;
                if (controller != CONTROLLER_FIXED) memo.error_prev = py_max(err, 1e-4);
                // the landing cut the step, not the error: carry the step the error allowed
                if (clipped && proposal > h_abs) h_abs = proposal;
                break;
            }
            // rejected (a NaN error too: the step went where the plant is not defined)
            if (err == err)
                h_abs = h * py_max(min_factor, safety * std::pow(err, -1.0 / kexp));
            else
                h_abs = h * min_factor;
            rejected += 1;
            step_rejected = true;
        }
        for (int c = 0; c < n; ++c) {
            x[c] = ynew[c];
            K_first[c] = K_last[c];
        }
        t_cur = t_new;
        accepted += 1;
        if (h < hmin) hmin = h;
    }
    if (controller == CONTROLLER_FIXED) h_abs = memo.fixed_step;
    memo.carry = h_abs;
    adaptive_detail::record(row, accepted, rejected, report.rhs_evaluations - evals0, hmin);
    return STEP_OK;
}

namespace adaptive_detail {

/// plan.J = df/dx at x (fx = f(x)) by forward differences (implicit_schemes.h's jacobian_into); J becomes current
/// and fresh, and M (made for the old J) is dropped. False on a right-hand-side failure (x_fail set).
template <class Plant>
bool trbdf2_jacobian(const TRBDF2Plan& plan, const double* x, int nx, const double* tau, Plant& plant,
                     int64_t* status, double t, const double* fx, double* x_fail, AdvanceReport& report) noexcept {
    AdaptiveMemo& memo = *plan.control.memo;
    memo.jacobians += 1.0;
    if (!jacobian_into(plan.J, x, nx, tau, plant, status, t, fx, plan.xp, plan.fp, x_fail, report)) return false;
    memo.have_jacobian = 1.0;
    memo.fresh = 1.0;
    memo.gh = 0.0;
    return true;
}

/// plan.M = (I - gh J)^-1 (the pseudo-inverse where I - gh J is singular).
inline void trbdf2_iteration_matrix(const TRBDF2Plan& plan, int nx, double gh) noexcept {
    const double* J = plan.J;
    double* Ah = plan.Ah;
    const int n = nx;
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) Ah[r * n + c] = (r == c ? 1.0 : 0.0) - gh * J[r * n + c];
    if (!invert_into(Ah, n, plan.LU, plan.M)) pinv_into(Ah, n, plan.M, plan.pinv_work);
    plan.control.memo->gh = gh;
}

/// Solve k = f(known + gh k) by simplified Newton with plan.M from the predictor in k, at the time ts [s]; the
/// corrections are scaled by h and the tolerances at x.
template <class Plant>
StageResult trbdf2_stage(const TRBDF2Plan& plan, const double* known, double* k, int nx, const double* tau,
                         Plant& plant, int64_t* status, double gh, double h, const double* x, double ts,
                         double* x_fail, AdvanceReport& report) noexcept {
    const StepControl& st = plan.control;
    double *xs = plan.xs, *fs = plan.fs, *dk = plan.dk;
    const double* M = plan.M;
    const double* atol = st.atol;
    const double rtol = st.rtol, tol = plan.newton_tol;
    const int64_t max_iter = plan.max_iterations;
    const int n = nx;
    const double inf = std::numeric_limits<double>::infinity();
    double previous = inf;
    for (int64_t it = 0; it < max_iter; ++it) {
        for (int c = 0; c < n; ++c) xs[c] = k[c] * gh + known[c];
        plant.rhs(xs, tau, ts, fs, status);
        if (stage_failed(xs, n, status, x_fail, report)) return STAGE_PLANT_ERROR;
        for (int r = 0; r < n; ++r) {
            double acc = 0.0;
            for (int c = 0; c < n; ++c) acc += M[r * n + c] * (k[c] - fs[c]);
            dk[r] = acc;
        }
        double acc2 = 0.0;
        for (int c = 0; c < n; ++c) {
            k[c] -= dk[c];
            const double sc = atol[c] + rtol * std::fabs(x[c]);
            const double v = h * dk[c] / sc;
            acc2 += v * v;
        }
        const double size = std::sqrt(acc2 / n);
        if (!(size == size) || size == inf) return STAGE_NOT_CONVERGED;
        if (size <= tol) return STAGE_CONVERGED;
        const double rate = size / previous;
        if (it >= 1 && rate > 0.9) return STAGE_NOT_CONVERGED;
        if (it >= 1 && rate < 1.0 && rate / (1.0 - rate) * size <= tol) return STAGE_CONVERGED;
        previous = size;
    }
    return STAGE_NOT_CONVERGED;
}

}  // namespace adaptive_detail

/// TR-BDF2 over one control period [t, t + T], x (nx) advanced in place, in n equal steps h = T / n kept while
/// the controller's step stays in [h, 1.5 h] (adaptive_plans.py's module docstring). A stage whose Newton
/// iteration does not converge takes a Jacobian at x first, then quarters the remaining steps. Returns STEP_OK,
/// STEP_PLANT_ERROR (x_fail set) or STEP_TOO_SMALL (too_small set).
template <class Plant>
int trbdf2_advance(const TRBDF2Plan& plan, double* x, int nx, const double* tau, Plant& plant, int64_t* status,
                   double t, double* x_fail, AdvanceReport& report, TooSmallStep& too_small) noexcept {
    using adaptive_detail::py_max;
    using adaptive_detail::py_min;
    using adaptive_detail::StageResult;
    static const adaptive_detail::TRBDF2Coefficients coef;
    const StepControl& st = plan.control;
    AdaptiveMemo& memo = *st.memo;
    const double* atol = st.atol;
    double *k1 = plan.k1, *k2 = plan.k2, *k3 = plan.k3, *known = plan.known, *e = plan.e, *y = plan.y,
           *dk = plan.dk;
    const double rtol = st.rtol, min_step = st.min_step, safety = st.safety;
    const double min_factor = st.min_factor, max_factor = st.max_factor;
    const int controller = st.controller;
    const double period = st.period;
    const int n = nx;
    StepStatistics* row = adaptive_detail::tick_row(st, t);
    const int64_t evals0 = report.rhs_evaluations;
    int64_t accepted = 0, rejected = 0;
    double hmin = std::numeric_limits<double>::infinity();
    plant.first_rhs(x, tau, t, k1, status);
    if (stage_failed(x, n, status, x_fail, report)) return STEP_PLANT_ERROR;
    // the steps of this period: T / parts, parts kept while the proposed step stays in [T / parts, 1.5 T / parts]
    int64_t parts;
    double proposal = 0.0;
    if (controller == CONTROLLER_FIXED) {
        parts = py_max(int64_t{1}, static_cast<int64_t>(std::nearbyint(period / memo.fixed_step)));
    } else {
        proposal = memo.carry;
        if (proposal <= 0.0) {
            proposal = initial_step(x, n, k1, y, k2, atol, rtol, 2.0, period, tau, plant, status, t);
            report.rhs_evaluations += 1;
            if (proposal < 0.0) {
                for (int c = 0; c < n; ++c) x_fail[c] = y[c];
                return STEP_PLANT_ERROR;
            }
        }
        parts = static_cast<int64_t>(memo.parts);
        if (parts < 1 || proposal < period / static_cast<double>(parts) ||
            proposal > 1.5 * period / static_cast<double>(parts))
            parts = py_max(int64_t{1}, static_cast<int64_t>(std::ceil(period / proposal)));
    }
    double done = 0.0;  // the part of the period integrated [s]
    int64_t remaining_parts = parts;
    double h = period / static_cast<double>(parts);
    while (remaining_parts > 0) {
        if (h < min_step) {
            too_small.step = h;
            too_small.time = t + done;
            for (int c = 0; c < n; ++c) x_fail[c] = x[c];
            adaptive_detail::record(row, accepted, rejected, report.rhs_evaluations - evals0, hmin);
            return STEP_TOO_SMALL;
        }
        const double t_cur = t + done;
        if (memo.have_jacobian == 0.0) {
            if (!adaptive_detail::trbdf2_jacobian(plan, x, n, tau, plant, status, t_cur, k1, x_fail, report))
                return STEP_PLANT_ERROR;
        }
        const double gh = coef.d * h;
        if (memo.gh != gh) adaptive_detail::trbdf2_iteration_matrix(plan, n, gh);
        // stage 2: the trapezoidal rule to t + gamma h
        for (int c = 0; c < n; ++c) {
            known[c] = x[c] + gh * k1[c];
            k2[c] = k1[c];
        }
        StageResult code = adaptive_detail::trbdf2_stage(plan, known, k2, n, tau, plant, status, gh, h, x,
                                                         t_cur + coef.gamma * h, x_fail, report);
        if (code == adaptive_detail::STAGE_CONVERGED) {
            // stage 3: BDF2 to t + h
            for (int c = 0; c < n; ++c) {
                known[c] = x[c] + (coef.w * h) * (k1[c] + k2[c]);
                k3[c] = k2[c];
            }
            code = adaptive_detail::trbdf2_stage(plan, known, k3, n, tau, plant, status, gh, h, x, t_cur + h, x_fail,
                                                 report);
        }
        if (code == adaptive_detail::STAGE_PLANT_ERROR) return STEP_PLANT_ERROR;
        if (code == adaptive_detail::STAGE_NOT_CONVERGED) {  // a Jacobian at x first, then a smaller step
            rejected += 1;
            if (memo.fresh == 0.0) {
                memo.have_jacobian = 0.0;
            } else {
                remaining_parts *= 4;
                h = (period - done) / static_cast<double>(remaining_parts);
            }
            continue;
        }
        for (int c = 0; c < n; ++c) {
            y[c] = known[c] + gh * k3[c];  // x' = x + h (w k1 + w k2 + d k3)
            e[c] = h * (coef.e1 * k1[c] + coef.e2 * k2[c] + coef.e3 * k3[c]);
        }
        // Shampine's filter: M e
        const double* M = plan.M;
        for (int r = 0; r < n; ++r) {
            double acc = 0.0;
            for (int c = 0; c < n; ++c) acc += M[r * n + c] * e[c];
            dk[r] = acc;
        }
        const double err = controller == CONTROLLER_FIXED ? 0.0 : adaptive_detail::rms_scaled(dk, x, y, atol, rtol, n);
        if (err < 1.0) {
            for (int c = 0; c < n; ++c) {
                x[c] = y[c];
                k1[c] = k3[c];  // stiffly accurate: f(x') = k3 (first-same-as-last)
            }
            done += h;
            accepted += 1;
            remaining_parts -= 1;
            memo.fresh = 0.0;
            if (h < hmin) hmin = h;
            if (controller != CONTROLLER_FIXED) {
                const double factor =
                    err == 0.0 ? max_factor : py_min(max_factor, safety * std::pow(err, -1.0 / 3.0));
                proposal = h * py_max(factor, min_factor);
                memo.carry = proposal;
                if (remaining_parts > 0 && (proposal < h || proposal > 1.5 * h)) {  // re-plan the rest of the period
                    remaining_parts = py_max(int64_t{1}, static_cast<int64_t>(std::ceil((period - done) / proposal)));
                    h = (period - done) / static_cast<double>(remaining_parts);
                }
            }
            continue;
        }
        rejected += 1;
        const double factor = err == err ? py_max(min_factor, safety * std::pow(err, -1.0 / 3.0)) : min_factor;
        const double remaining = period - done;
        remaining_parts = py_max(remaining_parts + 1, static_cast<int64_t>(std::ceil(remaining / (h * factor))));
        h = remaining / static_cast<double>(remaining_parts);
    }
    memo.parts = static_cast<double>(parts);
    adaptive_detail::record(row, accepted, rejected, report.rhs_evaluations - evals0, hmin);
    return STEP_OK;
}

}  // namespace coopctrl
