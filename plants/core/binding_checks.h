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
/// A C-contiguous float64 array of any dimension (checked by the function that takes it).
using AnyArray = nb::ndarray<const double, nb::c_contig, nb::device::cpu>;
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

/// The samples of node rows Y and rates dY of N nodes of p coordinates: 1 for (N, p), B for (B, N, p); dY of Y's
/// shape.
inline size_t node_rows_samples(const AnyArray& Y, const AnyArray& dY, size_t N, size_t p) {
    const size_t d = Y.ndim();
    const std::string rows = "(" + std::to_string(N) + ", " + std::to_string(p) + ")";
    expect((d == 2 || d == 3) && Y.shape(d - 2) == N && Y.shape(d - 1) == p, "Y",
           rows + ": a pose per node of the plant, or (samples, " + rows.substr(1));
    bool same = dY.ndim() == d;
    for (size_t k = 0; same && k < d; ++k) same = dY.shape(k) == Y.shape(k);
    expect(same, "dY", "the shape of Y: a rate per node of the plant");
    return d == 2 ? 1 : Y.shape(0);
}

}  // namespace plants::binding
