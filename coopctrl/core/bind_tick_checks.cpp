// The tick's required wrench and guards in coopctrl._core (coopctrl/core/tick_checks.h).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <string>

#include "coopctrl/core/tick_checks.h"

namespace nb = nanobind;

namespace coopctrl::binding {

namespace {

using Vector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Matrix = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using VectorOut = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

void expect(bool ok, const char* name, const std::string& what) {
    if (!ok) throw nb::value_error((std::string(name) + ": expected " + what).c_str());
}

void required_wrench_py(bool spatial, double mass, Vector inertia, Vector gravity, Vector Y0, Vector dY0,
                        Vector ddY0, VectorOut out) {
    const size_t p = spatial ? 6 : 3;
    expect(inertia.shape(0) == (spatial ? 3u : 1u), "inertia", spatial ? "3 principal moments" : "1 moment");
    expect(gravity.shape(0) == (spatial ? 3u : 2u), "gravity", spatial ? "3 entries" : "2 entries");
    expect(Y0.shape(0) == p && dY0.shape(0) == p && ddY0.shape(0) == p && out.shape(0) == p,
           "Y0, dY0, ddY0, out", "length p");
    required_wrench(spatial, mass, inertia.data(), gravity.data(), Y0.data(), dY0.data(), ddY0.data(), out.data());
}

nb::tuple guards_py(bool spatial, Vector x, Matrix Y, Matrix rho, double band, double max_deformation) {
    const size_t p = spatial ? 6 : 3, npos = spatial ? 3 : 2;
    expect(Y.shape(1) == p && Y.shape(0) >= 1, "Y", "shape (m + 1, p)");
    const size_t m = Y.shape(0) - 1;
    expect(rho.shape(0) == m && rho.shape(1) == npos, "rho", "shape (m, npos)");
    int contact = 0;
    double deformation = 0.0;
    const int code = guards(spatial, x.data(), static_cast<int>(x.shape(0)), Y.data(), static_cast<int>(m),
                            rho.data(), band, max_deformation, &contact, &deformation);
    return nb::make_tuple(code, contact, deformation);
}

}  // namespace

void bind_tick_checks(nb::module_& m) {
    m.def("required_wrench", &required_wrench_py, nb::arg("spatial"), nb::arg("mass"), nb::arg("inertia"),
          nb::arg("gravity"), nb::arg("Y0"), nb::arg("dY0"), nb::arg("ddY0"), nb::arg("out"),
          "The object's required wrench w_N [N, N m] into out.");
    m.def("guards", &guards_py, nb::arg("spatial"), nb::arg("x"), nb::arg("Y"), nb::arg("rho"), nb::arg("band"),
          nb::arg("max_deformation"), "The tick's guards: (code, contact, deformation [m]).");
}

}  // namespace coopctrl::binding
