// A Python right-hand side f(t, x, u) -> dx as a scheme's Plant (explicit_schemes.h): the documented slower path
// for a plant written in Python. f's exception is kept and raised again by the binding after the advance
// (raise_python_plant_error); the scheme sees a failed evaluation (status[0] = STATUS_PYTHON_ERROR) and stops.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <cstring>
#include <exception>
#include <string>

namespace coopctrl::binding {

namespace nb = nanobind;

/// The plant's status code of a Python f that raised or answered a wrong shape.
constexpr int64_t STATUS_PYTHON_ERROR = -1000;

/// f(t, x, u) -> dx on a copy of x (the schemes reuse their work arrays), u the held inputs as the caller gave them.
struct PythonPlant {
    nb::callable f;
    nb::object tau;
    size_t nx;
    std::string error;  // why f's answer was refused
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

/// Raise what f raised, or the refusal of its answer, if either happened during the advance.
inline void raise_python_plant_error(const PythonPlant& plant) {
    if (plant.raised.is_valid()) {
        PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(plant.raised.ptr())), plant.raised.ptr());
        throw nb::python_error();
    }
    if (!plant.error.empty()) throw nb::value_error(plant.error.c_str());
}

}  // namespace coopctrl::binding
