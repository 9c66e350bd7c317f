// The error-controlled schemes in coopctrl._core (coopctrl/core/adaptive_schemes.h) on the Python plans of
// coopctrl.integrators.adaptive_plans.adaptive_plan (an EmbeddedPlan or a TRBDF2Plan, read by field name and
// advanced in place: the step carried over, the Newton matrix and the statistics rows are the plan's own arrays),
// on a planar cooperative plant's PlantArgs, or on a Python f(t, x, u) (the documented slower path).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "coopctrl/core/adaptive_plan.h"
#include "coopctrl/core/adaptive_plan_reader.h"
#include "coopctrl/core/adaptive_schemes.h"
#include "coopctrl/core/integration_plan.h"
#include "coopctrl/core/python_plant.h"
#include "coopctrl/core/run_state.h"
#include "plants/core/binding_checks.h"
#include "plants/core/cooperative_planar.h"
#include "plants/core/planar_plant_reader.h"

namespace coopctrl::binding {

namespace {

namespace nb = nanobind;
using plants::binding::expect;
using plants::binding::expect_length;
using Vector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using VectorOut = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using MatrixIn = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using MatrixOut = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using IntVectorOut = nb::ndarray<int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

/// The plan's scheme over one period on the plant; out: the evaluations counted on, and a STEP_TOO_SMALL's
/// value = (step [s], time [s]).
template <class Plant>
int advance(nb::handle plan, VectorOut x, const double* tau, Plant& plant, int64_t* status, double t,
            VectorOut x_fail, StopReport& out) {
    const size_t nx = x.shape(0);
    expect_length(x_fail.shape(0), nx, "x_fail");
    const std::string kind = nb::cast<std::string>(plan.type().attr("__name__"));
    AdvanceReport report;
    report.rhs_evaluations = out.rhs_evaluations;
    TooSmallStep too_small;
    int code;
    const int n = static_cast<int>(nx);
    if (kind == "EmbeddedPlan") {
        const EmbeddedPlan p = embedded_plan(plan, nx);
        code = embedded_advance(p, x.data(), n, tau, plant, status, t, x_fail.data(), report, too_small);
    } else if (kind == "TRBDF2Plan") {
        std::vector<double> pinv_work;
        const TRBDF2Plan p = trbdf2_plan(plan, nx, pinv_work);
        code = trbdf2_advance(p, x.data(), n, tau, plant, status, t, x_fail.data(), report, too_small);
    } else {
        throw nb::type_error(("plan: an EmbeddedPlan or a TRBDF2Plan (coopctrl.integrators.adaptive_plans."
                              "adaptive_plan) expected, got a " + kind).c_str());
    }
    out.rhs_evaluations = report.rhs_evaluations;
    if (code == STEP_TOO_SMALL) {
        out.value[0] = too_small.step;
        out.value[1] = too_small.time;
    }
    return code;
}

/// A planar cooperative plant as the schemes' Plant: plants/core's planar_rhs on the model read from PlantArgs
/// (autonomous: the time is not used).
struct PlanarRhs {
    const plants::PlanarCooperativeModel& model;
    plants::PlanarCooperativeData& data;
    int nx;
    void rhs(const double* x, const double* tau, double, double* dx, int64_t* status) noexcept {
        plants::planar_rhs(model, x, nx, tau, status, data, dx);
    }
    void first_rhs(const double* x, const double* tau, double t, double* dx, int64_t* status) noexcept {
        rhs(x, tau, t, dx, status);
    }
};

/// The planar plant of P, checked against the state's and the inputs' lengths.
void expect_planar_sizes(const plants::binding::PlanarPlant& plant, size_t nx, size_t ntau) {
    int joints = 0;
    for (const auto& arm : plant.arms) joints = std::max(joints, arm.q_offset + arm.dof);
    expect(nx == 2 * static_cast<size_t>(joints + 3), "x",
           "length 2 nz = " + std::to_string(2 * (joints + 3)) + " (the plant's state), got " + std::to_string(nx));
    expect_length(ntau, static_cast<size_t>(joints), "tau");
}

int advance_on_plant(nb::handle plan, VectorOut x, Vector tau, nb::handle P, IntVectorOut status, double t,
                     VectorOut x_fail, StopReport& out) {
    plants::binding::PlanarPlant plant(P);
    expect_planar_sizes(plant, x.shape(0), tau.shape(0));
    expect_length(status.shape(0), 2, "status");
    plants::binding::PlanarWork work(plant.model);
    PlanarRhs rhs{plant.model, work.data, static_cast<int>(x.shape(0))};
    return advance(plan, x, tau.data(), rhs, status.data(), t, x_fail, out);
}

int advance_on_f(nb::handle plan, nb::callable f, VectorOut x, nb::object tau, double t, VectorOut x_fail,
                 StopReport& out) {
    PythonPlant plant{f, tau, x.shape(0), {}, {}};
    int64_t status[2] = {0, 0};
    const int code = advance(plan, x, nullptr, plant, status, t, x_fail, out);
    raise_python_plant_error(plant);
    return code;
}

double initial_step_on_plant(Vector x, Vector f0, VectorOut y1, VectorOut f1, Vector atol, double rtol, double order,
                             double interval, Vector tau, nb::handle P, IntVectorOut status) {
    const size_t nx = x.shape(0);
    plants::binding::PlanarPlant plant(P);
    expect_planar_sizes(plant, nx, tau.shape(0));
    expect_length(f0.shape(0), nx, "f0");
    expect_length(y1.shape(0), nx, "y1");
    expect_length(f1.shape(0), nx, "f1");
    expect_length(atol.shape(0), nx, "atol");
    expect_length(status.shape(0), 2, "status");
    plants::binding::PlanarWork work(plant.model);
    PlanarRhs rhs{plant.model, work.data, static_cast<int>(nx)};
    return initial_step(x.data(), static_cast<int>(nx), f0.data(), y1.data(), f1.data(), atol.data(), rtol, order,
                        interval, tau.data(), rhs, status.data(), 0.0);
}

}  // namespace

void bind_adaptive(nb::module_& m) {
    m.def("adaptive_advance", &advance_on_plant, nb::arg("plan"), nb::arg("x").noconvert(), nb::arg("tau"),
          nb::arg("P"), nb::arg("status").noconvert(), nb::arg("t"), nb::arg("x_fail").noconvert(),
          nb::arg("report"),
          "Advance x in place over one control period [t, t + T] with an error-controlled plan (rk23, rk45: "
          "EmbeddedPlan; trbdf2: TRBDF2Plan) on a planar cooperative plant (its PlantArgs P): the plan's memo and "
          "stats, status, x_fail and report (a StopReport: rhs_evaluations counted on, a STEP_TOO_SMALL's value = "
          "(step [s], time [s])) written; returns the StepCode.");
    m.def("adaptive_advance_f", &advance_on_f, nb::arg("plan"), nb::arg("f"), nb::arg("x").noconvert(),
          nb::arg("tau").none(), nb::arg("t"), nb::arg("x_fail").noconvert(), nb::arg("report"),
          "adaptive_advance on a Python f(t, x, u) -> dx (called at each stage's time); f's exception is raised "
          "again.");
    m.def("adaptive_initial_step", &initial_step_on_plant, nb::arg("x"), nb::arg("f0"), nb::arg("y1").noconvert(),
          nb::arg("f1").noconvert(), nb::arg("atol"), nb::arg("rtol"), nb::arg("order"), nb::arg("interval"),
          nb::arg("tau"), nb::arg("P"), nb::arg("status").noconvert(),
          "The first step [s] of a run on a planar cooperative plant (adaptive_plans.initial_step); -1.0 on a "
          "right-hand-side failure.");
    // where the core reads and writes the plan's packed arrays, for the test against adaptive_plans' S_*, M_*, STAT_*
    nb::dict settings, memo, statistics;
    settings["rtol"] = static_cast<int>(SETTING_RTOL);
    settings["min_step"] = static_cast<int>(SETTING_MIN_STEP);
    settings["safety"] = static_cast<int>(SETTING_SAFETY);
    settings["min_factor"] = static_cast<int>(SETTING_MIN_FACTOR);
    settings["max_factor"] = static_cast<int>(SETTING_MAX_FACTOR);
    settings["error_order"] = static_cast<int>(SETTING_ERROR_ORDER);
    settings["controller"] = static_cast<int>(SETTING_CONTROLLER);
    settings["period"] = static_cast<int>(SETTING_PERIOD);
    settings["newton_tol"] = static_cast<int>(SETTING_NEWTON_TOL);
    settings["max_iterations"] = static_cast<int>(SETTING_MAX_ITERATIONS);
#define COOPCTRL_SLOT(dict, type, field) dict[#field] = offsetof(type, field) / sizeof(double)
    COOPCTRL_SLOT(memo, AdaptiveMemo, carry);
    COOPCTRL_SLOT(memo, AdaptiveMemo, error_prev);
    COOPCTRL_SLOT(memo, AdaptiveMemo, fixed_step);
    COOPCTRL_SLOT(memo, AdaptiveMemo, parts);
    COOPCTRL_SLOT(memo, AdaptiveMemo, gh);
    COOPCTRL_SLOT(memo, AdaptiveMemo, have_jacobian);
    COOPCTRL_SLOT(memo, AdaptiveMemo, jacobians);
    COOPCTRL_SLOT(memo, AdaptiveMemo, fresh);
    COOPCTRL_SLOT(statistics, StepStatistics, accepted);
    COOPCTRL_SLOT(statistics, StepStatistics, rejected);
    COOPCTRL_SLOT(statistics, StepStatistics, rhs_evaluations);
    COOPCTRL_SLOT(statistics, StepStatistics, min_step);
#undef COOPCTRL_SLOT
    m.attr("ADAPTIVE_SETTINGS") = settings;
    m.attr("ADAPTIVE_MEMO") = memo;
    m.attr("STEP_STATISTICS") = statistics;
}

}  // namespace coopctrl::binding
