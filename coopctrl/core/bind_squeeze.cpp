// The tick's squeeze in coopctrl._core (coopctrl/core/squeeze.h), with the numba kernel's signature
// (coopctrl.loop.squeeze.pair_squeeze_into; the SqueezeWork arrays of squeeze_workspace passed one by one).
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <string>

#include "coopctrl/core/squeeze.h"
#include "plants/core/binding_checks.h"

namespace coopctrl::binding {

namespace {

namespace nb = nanobind;
using plants::binding::expect;
using plants::binding::expect_length;
using plants::binding::Matrix;
using plants::binding::MatrixOut;
using plants::binding::Vector;
using plants::binding::VectorOut;

std::string shape_text(size_t a, size_t b) { return "(" + std::to_string(a) + ", " + std::to_string(b) + ")"; }

void squeeze(Matrix r, Matrix F, Vector desired, MatrixOut E, MatrixOut W, MatrixOut V, VectorOut sigma,
             VectorOut out) {
    const size_t m = r.shape(0), npos = r.shape(1), p = F.shape(1);
    const size_t P = m * (m - (m > 0)) / 2, R = m * npos;
    const size_t rows = P <= R ? R : P, cols = P <= R ? P : R;
    expect(npos == 2 || npos == 3, "r", "(m, 2) planar or (m, 3) spatial contact positions");
    expect(F.shape(0) == m && p >= npos, "F", "shape (m = " + std::to_string(m) + ", p >= " + std::to_string(npos) +
                                                  "), got " + shape_text(F.shape(0), p));
    expect_length(desired.shape(0), P, "desired");
    expect(E.shape(0) == R && E.shape(1) == P, "E", "shape " + shape_text(R, P));
    expect(W.shape(0) == rows && W.shape(1) == cols, "W", "shape " + shape_text(rows, cols));
    expect(V.shape(0) == cols && V.shape(1) == cols, "V", "shape " + shape_text(cols, cols));
    expect_length(sigma.shape(0), cols, "sigma");
    expect_length(out.shape(0), P, "out");
    SqueezeWork work{desired.data(), E.data(), W.data(), V.data(), sigma.data()};
    pair_squeeze(r.data(), static_cast<int>(m), static_cast<int>(npos), F.data(), static_cast<int>(p), work,
                 out.data());
}

}  // namespace

void bind_squeeze(nb::module_& m) {
    m.def("pair_squeeze_into", &squeeze, nb::arg("r"), nb::arg("F"), nb::arg("desired"), nb::arg("E").noconvert(),
          nb::arg("W").noconvert(), nb::arg("V").noconvert(), nb::arg("sigma").noconvert(),
          nb::arg("out").noconvert(),
          "The squeeze [N] of the wrenches F (m, p) at the contacts r (m, npos) into out (coopctrl/core/squeeze.h): "
          "NaN where F or r is not finite, two contacts coincide or the pairs are ill-conditioned.");
}

}  // namespace coopctrl::binding
