// An error-controlled integration plan (coopctrl.integrators.adaptive_plans.adaptive_plan's EmbeddedPlan or
// TRBDF2Plan namedtuple) read by its field names into the core's plan (adaptive_plan.h), its arrays shared: the step
// carried over, the Newton matrix and the statistics rows are written in the plan's own arrays.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstddef>
#include <string>
#include <vector>

#include "coopctrl/core/adaptive_plan.h"
#include "plants/core/binding_checks.h"

namespace coopctrl::binding {

namespace adaptive_reader {

namespace nb = nanobind;
using plants::binding::expect;
using VectorOut = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using MatrixIn = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using MatrixOut = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

constexpr size_t MEMO_LENGTH = sizeof(AdaptiveMemo) / sizeof(double);
constexpr size_t STATISTICS_COLUMNS = sizeof(StepStatistics) / sizeof(double);

inline std::string field_name(const char* name) { return std::string("plan.") + name; }

/// plan.NAME, a float64 C-contiguous (n,) array, written in place.
inline double* plan_vector(nb::handle plan, const char* name, size_t n) {
    VectorOut a;
    const std::string what = field_name(name);
    expect(nb::try_cast(plan.attr(name), a, false) && a.shape(0) == n, what.c_str(),
           "a C-contiguous float64 array of shape (" + std::to_string(n) + ",)");
    return a.data();
}

/// plan.NAME, a float64 C-contiguous (rows, cols) array, written in place.
inline double* plan_matrix(nb::handle plan, const char* name, size_t rows, size_t cols) {
    MatrixOut a;
    const std::string what = field_name(name);
    expect(nb::try_cast(plan.attr(name), a, false) && a.shape(0) == rows && a.shape(1) == cols, what.c_str(),
           "a C-contiguous float64 array of shape (" + std::to_string(rows) + ", " + std::to_string(cols) + ")");
    return a.data();
}

/// The settings, tolerances, memo and statistics rows both plans share.
inline StepControl step_control(nb::handle plan, size_t nx) {
    const double* settings = plan_vector(plan, "settings", SETTING_COUNT);
    StepControl c{};
    c.period = settings[SETTING_PERIOD];
    c.atol = plan_vector(plan, "atol", nx);
    c.rtol = settings[SETTING_RTOL];
    c.min_step = settings[SETTING_MIN_STEP];
    c.safety = settings[SETTING_SAFETY];
    c.min_factor = settings[SETTING_MIN_FACTOR];
    c.max_factor = settings[SETTING_MAX_FACTOR];
    c.error_order = settings[SETTING_ERROR_ORDER];
    const int controller = static_cast<int>(settings[SETTING_CONTROLLER]);
    expect(controller == CONTROLLER_PI || controller == CONTROLLER_ELEMENTARY || controller == CONTROLLER_FIXED,
           "plan.settings[S_CONTROLLER]", "0 (PI), 1 (elementary) or 2 (fixed), got " + std::to_string(controller));
    c.controller = static_cast<StepController>(controller);
    c.memo = reinterpret_cast<AdaptiveMemo*>(plan_vector(plan, "memo", MEMO_LENGTH));
    MatrixOut stats;
    expect(nb::try_cast(plan.attr("stats"), stats, false) && stats.shape(1) == STATISTICS_COLUMNS, "plan.stats",
           "a C-contiguous float64 array of shape (ticks, " + std::to_string(STATISTICS_COLUMNS) + ")");
    c.stats = reinterpret_cast<StepStatistics*>(stats.data());
    c.ticks = static_cast<int64_t>(stats.shape(0));
    return c;
}

inline EmbeddedPlan embedded_plan(nb::handle plan, size_t nx) {
    EmbeddedPlan p{};
    p.control = step_control(plan, nx);
    MatrixIn A;
    expect(nb::try_cast(plan.attr("A"), A, false) && A.shape(0) == A.shape(1) && A.shape(0) > 0, "plan.A",
           "a C-contiguous float64 square tableau (s, s)");
    const size_t s = A.shape(0);
    p.stages = static_cast<int>(s);
    p.A = A.data();
    p.B = plan_vector(plan, "B", s);
    p.C = plan_vector(plan, "C", s);
    p.E = plan_vector(plan, "E", s + 1);
    p.K = plan_matrix(plan, "K", s + 1, nx);
    p.y = plan_vector(plan, "y", nx);
    p.ynew = plan_vector(plan, "ynew", nx);
    return p;
}

inline TRBDF2Plan trbdf2_plan(nb::handle plan, size_t nx, std::vector<double>& pinv_work) {
    TRBDF2Plan p{};
    p.control = step_control(plan, nx);
    const double* settings = plan_vector(plan, "settings", SETTING_COUNT);
    p.newton_tol = settings[SETTING_NEWTON_TOL];
    p.max_iterations = static_cast<int64_t>(settings[SETTING_MAX_ITERATIONS]);
    p.J = plan_matrix(plan, "J", nx, nx);
    p.Ah = plan_matrix(plan, "Ah", nx, nx);
    p.LU = plan_matrix(plan, "LU", nx, nx);
    p.M = plan_matrix(plan, "M", nx, nx);
    p.k1 = plan_vector(plan, "k1", nx);
    p.k2 = plan_vector(plan, "k2", nx);
    p.k3 = plan_vector(plan, "k3", nx);
    p.known = plan_vector(plan, "known", nx);
    p.xs = plan_vector(plan, "xs", nx);
    p.fs = plan_vector(plan, "fs", nx);
    p.dk = plan_vector(plan, "dk", nx);
    p.e = plan_vector(plan, "e", nx);
    p.y = plan_vector(plan, "y", nx);
    p.xp = plan_vector(plan, "xp", nx);
    p.fp = plan_vector(plan, "fp", nx);
    pinv_work.resize(2 * nx * nx + nx);
    p.pinv_work = pinv_work.data();
    return p;
}

}  // namespace adaptive_reader

using adaptive_reader::embedded_plan;
using adaptive_reader::trbdf2_plan;

}  // namespace coopctrl::binding
