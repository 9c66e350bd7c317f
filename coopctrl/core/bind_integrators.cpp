// The fixed-step schemes in coopctrl._core (coopctrl/core/explicit_schemes.h, implicit_schemes.h), on a Python
// right-hand side f(t, x, u) -> dx: the documented slower path for a plant written in Python, and the check of
// the schemes against the Python integrators (tests/test_core_integrators.py).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <string>
#include <vector>

#include "coopctrl/core/dense.h"
#include "coopctrl/core/explicit_schemes.h"
#include "coopctrl/core/implicit_schemes.h"
#include "coopctrl/core/integration_plan.h"
#include "coopctrl/core/plan_reader.h"
#include "coopctrl/core/python_plant.h"

namespace nb = nanobind;

namespace coopctrl::binding {

namespace {

using ConstVector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Vector = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Matrix = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using MatrixOut = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

nb::dict report_dict(int code, const AdvanceReport& r) {
    nb::dict d;
    d["code"] = code;
    d["rhs_evaluations"] = r.rhs_evaluations;
    d["plant_status"] = nb::make_tuple(r.plant_status[0], r.plant_status[1]);
    d["failed_step"] = r.failed_step;
    d["newton_iterations"] = r.newton_iterations;
    d["last_correction"] = r.last_correction;
    d["failed_time"] = r.failed_time;
    return d;
}

/// Advance x in place over the steps of one period with the plan (an ExplicitPlan or an ImplicitPlan of
/// coopctrl.integrators.compiled.make_plan: its Newton state is updated) on f.
nb::dict zoh_advance(nb::object plan, nb::callable f, Vector x, nb::object tau, double t, ConstVector steps,
                     Vector x_fail) {
    const size_t nx = x.shape(0);
    if (x_fail.shape(0) != nx) throw nb::value_error("x_fail: expected the state's length");
    PythonPlant plant{f, tau, nx, {}, {}};
    int64_t status[2] = {0, 0};
    AdvanceReport report;
    int code;
    const std::string kind = plan_kind(plan);
    std::vector<double> pinv_work;
    const int n = static_cast<int>(nx), nsteps = static_cast<int>(steps.shape(0));
    if (kind == "ExplicitPlan") {
        code = explicit_period(read_explicit_plan(plan, n), x.data(), n, nullptr, plant, status, t, steps.data(),
                               nsteps, x_fail.data(), report);
    } else if (kind == "ImplicitPlan") {
        code = implicit_period(read_implicit_plan(plan, n, pinv_work), x.data(), n, nullptr, plant, status, t,
                               steps.data(), nsteps, x_fail.data(), report);
    } else {
        throw nb::type_error(("plan is a " + kind + ": expected an ExplicitPlan or an ImplicitPlan "
                              "(coopctrl.integrators.compiled.make_plan)").c_str());
    }
    raise_python_plant_error(plant);
    return report_dict(code, report);
}

void inverse(Matrix A, MatrixOut M) {
    const size_t n = A.shape(0);
    if (A.shape(1) != n || M.shape(0) != n || M.shape(1) != n) throw nb::value_error("A, M: expected (n, n) each");
    std::vector<double> LU(n * n);
    if (!invert_into(A.data(), static_cast<int>(n), LU.data(), M.data()))
        throw nb::value_error("A: singular (a zero pivot)");
}

void pseudo_inverse(Matrix A, MatrixOut M) {
    const size_t n = A.shape(0);
    if (A.shape(1) != n || M.shape(0) != n || M.shape(1) != n) throw nb::value_error("A, M: expected (n, n) each");
    std::vector<double> work(2 * n * n + n);
    pinv_into(A.data(), static_cast<int>(n), M.data(), work.data());
}

}  // namespace

void bind_integrators(nb::module_& m) {
    m.def("zoh_advance", &zoh_advance, nb::arg("plan"), nb::arg("f"), nb::arg("x"), nb::arg("tau").none(), nb::arg("t"),
          nb::arg("steps"), nb::arg("x_fail"),
          "Advance x in place over one period, a step per entry of steps [s], with the plan's scheme on a Python "
          "f(t, x, u) -> dx; returns the report (code: coopctrl/core/integration_plan.h's StepCode).");
    m.def("inverse", &inverse, nb::arg("A"), nb::arg("M"), "M = A^-1 by LU with partial pivoting.");
    m.def("pseudo_inverse", &pseudo_inverse, nb::arg("A"), nb::arg("M"),
          "M = pinv(A) (singular values below 1e-15 of the largest dropped).");
}

}  // namespace coopctrl::binding
