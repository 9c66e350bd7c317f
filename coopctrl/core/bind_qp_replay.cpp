// The load-distribution QP solved over a recorded sequence of problems in one compiled loop (benchmarks/
// bench_compiled_qp.py): each tick's arrays copied into fixed buffers, as the tick's assembly writes them in place,
// then, with `solve`, the warm-started Goldfarb-Idnani solve (goldfarb_idnani.h) on one workspace, as the tick
// solves it. The solve's cost per tick is the loop with solves less the loop with copies only.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <vector>

#include "coopctrl/core/goldfarb_idnani.h"

namespace coopctrl::binding {

namespace {

namespace nb = nanobind;
using F1 = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using F2 = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using F3 = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using I1 = nb::ndarray<int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

void replay(F2 P, F2 g, F3 M, F2 lo, F2 hi, int n_eq, nb::tuple ws, F2 X, I1 status, I1 iterations, int64_t start,
            int64_t stop, bool solve, double tol, int64_t max_iter) {
    const size_t n = P.shape(0), rows = M.shape(1), ticks = g.shape(0);
    if (P.shape(1) != n || g.shape(1) != n || M.shape(0) != ticks || M.shape(2) != n || lo.shape(0) != ticks ||
        lo.shape(1) != rows || hi.shape(0) != ticks || hi.shape(1) != rows || X.shape(0) != ticks || X.shape(1) != n ||
        status.shape(0) != ticks || iterations.shape(0) != ticks)
        throw nb::value_error("P (n, n), g (S, n), M (S, rows, n), lo, hi (S, rows), X (S, n), status, iterations (S,)");
    if (start < 0 || stop > static_cast<int64_t>(ticks) || start > stop) throw nb::value_error("start, stop: ticks");
    F3 mats;
    F2 vecs, rowv;
    I1 ints;
    if (ws.size() != 4 || !nb::try_cast(ws[0], mats, false) || !nb::try_cast(ws[1], vecs, false) ||
        !nb::try_cast(ws[2], rowv, false) || !nb::try_cast(ws[3], ints, false) || mats.shape(1) != n ||
        rowv.shape(1) != rows)
        throw nb::value_error("ws: expected gi_workspace(n, rows) of these problems");
    GIWorkspace view = gi_workspace_view(static_cast<int>(n), static_cast<int>(rows), mats.data(), vecs.data(),
                                         rowv.data(), ints.data());
    std::vector<double> gb(n), Mb(rows * n), lob(rows), hib(rows), x(n), z(rows);
    nb::gil_scoped_release release;
    for (int64_t s = start; s < stop; ++s) {
        for (size_t c = 0; c < n; ++c) gb[c] = g(s, c);
        const double* Ms = M.data() + s * rows * n;
        for (size_t c = 0; c < rows * n; ++c) Mb[c] = Ms[c];
        for (size_t c = 0; c < rows; ++c) lob[c] = lo(s, c), hib[c] = hi(s, c);
        if (!solve) continue;
        const QP qp{static_cast<int>(n), static_cast<int>(rows), n_eq, P.data(), gb.data(), Mb.data(), lob.data(),
                    hib.data()};
        int64_t iters = 0;
        status(s) = gi_solve(qp, x.data(), z.data(), view, s == 0, tol, max_iter, &iters);
        iterations(s) = iters;
        for (size_t c = 0; c < n; ++c) X(s, c) = x[c];
    }
}

}  // namespace

void bind_qp_replay(nb::module_& m) {
    m.def("gi_replay", &replay, nb::arg("P"), nb::arg("g"), nb::arg("M"), nb::arg("lo"), nb::arg("hi"),
          nb::arg("n_eq"), nb::arg("ws"), nb::arg("X").noconvert(), nb::arg("status").noconvert(),
          nb::arg("iterations").noconvert(), nb::arg("start"), nb::arg("stop"), nb::arg("solve"), nb::arg("tol"),
          nb::arg("max_iter"),
          "Ticks start:stop of a recorded QP sequence in one compiled loop: each tick's g, M, lo, hi copied into "
          "fixed buffers, then with solve the warm-started gi_solve on ws; X, status, iterations written per tick.");
}

}  // namespace coopctrl::binding
