// One control period of a cooperative plant (planar or spatial, read from its PlantArgs) with any integration plan:
// Integrator.step on a plant's own rhs (coopctrl/integrators/stepping.py), the held inputs tau, on the core's
// schemes (explicit_schemes.h, implicit_schemes.h, adaptive_schemes.h) and plants (cooperative_planar.h,
// cooperative_spatial.h). The plan's state (a Newton matrix, the step carried over) is its own arrays, updated.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cstdint>
#include <string>
#include <vector>

#include "coopctrl/core/adaptive_plan_reader.h"
#include "coopctrl/core/adaptive_schemes.h"
#include "coopctrl/core/explicit_schemes.h"
#include "coopctrl/core/implicit_schemes.h"
#include "coopctrl/core/plan_reader.h"
#include "coopctrl/core/run_state.h"
#include "plants/core/cooperative_planar_work.h"
#include "plants/core/cooperative_spatial_work.h"
#include "plants/core/planar_plant_reader.h"
#include "plants/core/spatial_plant_reader.h"

namespace coopctrl::binding {

namespace {

using VectorOut = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Vector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using IntVectorOut = nb::ndarray<int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

/// A plant's right-hand side as the schemes' Plant; a period's first slope is evaluated afresh.
template <class Model, class Work, void (*Rhs)(const Model&, const double*, int, const double*, int64_t*,
                                                typename std::remove_reference<decltype(std::declval<Work&>().data)>::type&,
                                                double*) noexcept>
struct PlantRhs {
    const Model& model;
    Work& work;
    int nx;
    void rhs(const double* x, const double* tau, double, double* dx, int64_t* status) noexcept {
        Rhs(model, x, nx, tau, status, work.data, dx);
    }
    void first_rhs(const double* x, const double* tau, double t, double* dx, int64_t* status) noexcept {
        rhs(x, tau, t, dx, status);
    }
};

using PlanarRhs = PlantRhs<plants::PlanarCooperativeModel, plants::PlanarWork, &plants::planar_rhs>;
using SpatialRhs = PlantRhs<plants::SpatialCooperativeModel, plants::SpatialWork, &plants::spatial_rhs>;

template <class Plant>
int advance(nb::handle plan, double* x, int nx, const double* tau, Plant& plant, int64_t* status, double t,
            const double* steps, int nsteps, double* x_fail, StopReport& out) {
    const std::string kind = plan_kind(plan);
    AdvanceReport report;
    report.rhs_evaluations = out.rhs_evaluations;
    int code;
    if (kind == "ExplicitPlan") {
        code = explicit_period(read_explicit_plan(plan, nx), x, nx, tau, plant, status, t, steps, nsteps, x_fail,
                               report);
    } else if (kind == "ImplicitPlan") {
        std::vector<double> pinv_work;
        code = implicit_period(read_implicit_plan(plan, nx, pinv_work), x, nx, tau, plant, status, t, steps, nsteps,
                               x_fail, report);
        if (code == STEP_NEWTON_FAILED) {
            out.detail[0] = report.failed_step;
            out.detail[1] = report.newton_iterations;
            out.value[0] = report.last_correction;
            out.value[1] = report.failed_time;
        }
    } else if (kind == "EmbeddedPlan" || kind == "TRBDF2Plan") {
        TooSmallStep too_small;
        std::vector<double> pinv_work;
        if (kind == "EmbeddedPlan")
            code = embedded_advance(embedded_plan(plan, nx), x, nx, tau, plant, status, t, x_fail, report, too_small);
        else
            code = trbdf2_advance(trbdf2_plan(plan, nx, pinv_work), x, nx, tau, plant, status, t, x_fail, report,
                                  too_small);
        if (code == STEP_TOO_SMALL) {
            out.value[0] = too_small.step;
            out.value[1] = too_small.time;
        }
    } else {
        throw nb::type_error(("plan: a " + kind + ": expected an ExplicitPlan, ImplicitPlan, EmbeddedPlan or "
                              "TRBDF2Plan (coopctrl.integrators.compiled.make_plan)").c_str());
    }
    out.rhs_evaluations = report.rhs_evaluations;
    return code;
}

int plant_advance(nb::handle plan, VectorOut x, Vector tau, nb::handle P, IntVectorOut status, double t, Vector steps,
                  VectorOut x_fail, StopReport& out) {
    const int nx = static_cast<int>(x.shape(0));
    if (x_fail.shape(0) != x.shape(0)) throw nb::value_error("x_fail: expected the state's length");
    if (status.shape(0) != 2) throw nb::value_error("status: expected length 2");
    const bool spatial = nb::cast<int>(P.attr("bases").attr("ndim")) == 3;
    int code;
    if (spatial) {
        plants::binding::SpatialPlant plant(P);
        plants::SpatialWork work(plant.model);
        SpatialRhs rhs{plant.model, work, nx};
        code = advance(plan, x.data(), nx, tau.data(), rhs, status.data(), t, steps.data(),
                       static_cast<int>(steps.shape(0)), x_fail.data(), out);
    } else {
        plants::binding::PlanarPlant plant(P);
        plants::PlanarWork work(plant.model);
        PlanarRhs rhs{plant.model, work, nx};
        code = advance(plan, x.data(), nx, tau.data(), rhs, status.data(), t, steps.data(),
                       static_cast<int>(steps.shape(0)), x_fail.data(), out);
    }
    return code;
}

}  // namespace

void bind_plant_advance(nb::module_& m) {
    m.def("plant_advance", &plant_advance, nb::arg("plan"), nb::arg("x").noconvert(), nb::arg("tau"), nb::arg("P"),
          nb::arg("status").noconvert(), nb::arg("t"), nb::arg("steps"), nb::arg("x_fail").noconvert(),
          nb::arg("report"),
          "Advance x in place over one control period from t [s], a step per entry of steps [s] (an "
          "error-controlled plan: its own steps over the period), with the plan's scheme on the cooperative plant "
          "of P (PlantArgs), tau held; returns the StepCode (coopctrl/core/integration_plan.h). report (a "
          "StopReport): rhs_evaluations counted on; a failed Newton's detail = (step, iterations) and value = "
          "(last correction, time [s]); a step too small's value = (step [s], time [s]).");
}

}  // namespace coopctrl::binding
