// What every binding file of plants._core shares: the array types it accepts (float64, C-contiguous, on the CPU,
// passed without copies) and the one-line shape checks that raise ValueError naming the argument.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <string>

namespace plants::binding {

namespace nb = nanobind;

using Vector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Matrix = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using VectorOut = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using MatrixOut = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

/// Raise ValueError("NAME: expected WHAT") unless ok.
inline void expect(bool ok, const char* name, const std::string& what) {
    if (!ok) throw nb::value_error((std::string(name) + ": expected " + what).c_str());
}

/// Raise ValueError("NAME: expected length WANT, got GOT") unless got == want.
inline void expect_length(size_t got, size_t want, const char* name) {
    expect(got == want, name, "length " + std::to_string(want) + ", got " + std::to_string(got));
}

}  // namespace plants::binding
