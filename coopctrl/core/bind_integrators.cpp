// The fixed-step schemes in coopctrl._core (coopctrl/core/explicit_schemes.h, implicit_schemes.h), on a Python
// right-hand side f(t, x, u) -> dx: the documented slower path for a plant written in Python, and the check of
// the schemes against the Python integrators (tests/test_core_integrators.py).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>

#include <cstring>
#include <string>
#include <vector>

#include "coopctrl/core/dense.h"
#include "coopctrl/core/explicit_schemes.h"
#include "coopctrl/core/implicit_schemes.h"
#include "coopctrl/core/integration_plan.h"

namespace nb = nanobind;

namespace coopctrl::binding {

namespace {

using Array = nb::ndarray<double, nb::c_contig, nb::device::cpu>;
using ConstVector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Vector = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Matrix = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using MatrixOut = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

/// The plant's status code of a Python f that raised (the exception is raised again after the advance).
constexpr int64_t STATUS_PYTHON_ERROR = -1000;

/// A Python f(t, x, u) -> dx as the schemes' Plant: f gets a copy of x (the schemes reuse their work arrays).
struct PythonPlant {
    nb::callable f;
    nb::object tau;  // the held inputs, as the numpy array the caller gave
    size_t nx;
    std::string error;  // what f raised, or why its answer was refused
    nb::object raised;  // the exception f raised

    void rhs(const double* x, const double*, double t, double* dx, int64_t* status) {
        status[0] = 0;
        status[1] = 0;
        try {
            double* copy = new double[nx];
            std::memcpy(copy, x, nx * sizeof(double));
            nb::capsule owner(copy, [](void* p) noexcept { delete[] static_cast<double*>(p); });
            nb::object xs = nb::cast(nb::ndarray<nb::numpy, double, nb::ndim<1>>(copy, {nx}, owner));
            nb::object out = f(t, xs, tau);
            auto values = nb::cast<nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>>(
                nb::module_::import_("numpy").attr("ascontiguousarray")(out, "float64"));
            if (values.shape(0) != nx) {
                error = "f(t, x, u) returned shape (" + std::to_string(values.shape(0)) + ",): expected (" +
                        std::to_string(nx) + ",), the state's shape (dz, ddz)";
                status[0] = STATUS_PYTHON_ERROR;
                return;
            }
            std::memcpy(dx, values.data(), nx * sizeof(double));
        } catch (nb::python_error& e) {
            raised = nb::borrow(e.value());
            status[0] = STATUS_PYTHON_ERROR;
        } catch (const std::exception& e) {
            error = e.what();
            status[0] = STATUS_PYTHON_ERROR;
        }
    }
    void first_rhs(const double* x, const double* tau_, double t, double* dx, int64_t* status) {
        rhs(x, tau_, t, dx, status);
    }
};

double* vector_field(nb::handle plan, const char* name, size_t n) {
    auto a = nb::cast<Vector>(plan.attr(name));
    if (a.shape(0) != n)
        throw nb::value_error((std::string("plan.") + name + ": expected length " + std::to_string(n)).c_str());
    return a.data();
}

double* matrix_field(nb::handle plan, const char* name, size_t rows, size_t cols) {
    auto a = nb::cast<MatrixOut>(plan.attr(name));
    if (a.shape(0) != rows || a.shape(1) != cols)
        throw nb::value_error((std::string("plan.") + name + ": expected shape (" + std::to_string(rows) + ", " +
                               std::to_string(cols) + ")").c_str());
    return a.data();
}

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
    const std::string kind = nb::cast<std::string>(plan.type().attr("__name__"));
    std::vector<double> pinv_work;
    if (kind == "ExplicitPlan") {
        ExplicitPlan p{};
        p.method = nb::cast<int64_t>(plan.attr("method"));
        p.k1 = vector_field(plan, "k1", nx);
        p.k2 = vector_field(plan, "k2", nx);
        p.k3 = vector_field(plan, "k3", nx);
        p.k4 = vector_field(plan, "k4", nx);
        p.y = vector_field(plan, "y", nx);
        code = explicit_period(p, x.data(), static_cast<int>(nx), nullptr, plant, status, t, steps.data(),
                               static_cast<int>(steps.shape(0)), x_fail.data(), report);
    } else if (kind == "ImplicitPlan") {
        ImplicitPlan p{};
        auto settings = nb::cast<ConstVector>(plan.attr("settings"));
        if (settings.shape(0) != 4) throw nb::value_error("plan.settings: expected (rtol, atol, max_iterations, reuse_rate)");
        p.rtol = settings(0);
        p.atol = settings(1);
        p.max_iterations = static_cast<int64_t>(settings(2));
        p.reuse_rate = settings(3);
        auto tableau = nb::cast<Matrix>(plan.attr("tableau"));
        const size_t s = tableau.shape(0);
        if (tableau.shape(1) != s) throw nb::value_error("plan.tableau: expected a square table");
        p.stages = static_cast<int>(s);
        p.tableau = tableau.data();
        p.weights = vector_field(plan, "weights", s);
        p.nodes = vector_field(plan, "nodes", s);
        p.M = matrix_field(plan, "M", nx, nx);
        p.A = matrix_field(plan, "A", nx, nx);
        p.LU = matrix_field(plan, "LU", nx, nx);
        p.slopes = matrix_field(plan, "slopes", s, nx);
        p.predictors = matrix_field(plan, "predictors", s, nx);
        p.known = vector_field(plan, "known", nx);
        p.k = vector_field(plan, "k", nx);
        p.xs = vector_field(plan, "xs", nx);
        p.fs = vector_field(plan, "fs", nx);
        p.dk = vector_field(plan, "dk", nx);
        p.xp = vector_field(plan, "xp", nx);
        p.fp = vector_field(plan, "fp", nx);
        p.memo = vector_field(plan, "memo", 3);
        pinv_work.resize(2 * nx * nx + nx);
        p.pinv_work = pinv_work.data();
        code = implicit_period(p, x.data(), static_cast<int>(nx), nullptr, plant, status, t, steps.data(),
                               static_cast<int>(steps.shape(0)), x_fail.data(), report);
    } else {
        throw nb::type_error(("plan is a " + kind + ": expected an ExplicitPlan or an ImplicitPlan "
                              "(coopctrl.integrators.compiled.make_plan)").c_str());
    }
    if (plant.raised.is_valid()) {
        PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(plant.raised.ptr())), plant.raised.ptr());
        throw nb::python_error();
    }
    if (!plant.error.empty()) throw nb::value_error(plant.error.c_str());
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
