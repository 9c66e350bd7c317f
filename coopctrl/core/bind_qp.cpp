// The load-distribution QP's kernels in coopctrl._core: the Goldfarb-Idnani solver (coopctrl/core/goldfarb_idnani.h)
// on the workspace tuple (mats, vecs, rowv, ints) of coopctrl.load_distribution.goldfarb_idnani.gi_workspace.
#include <string>

#include "coopctrl/core/goldfarb_idnani.h"
#include "plants/core/binding_checks.h"

namespace coopctrl::binding {

namespace nb = nanobind;
using plants::binding::expect;
using plants::binding::expect_length;
using plants::binding::Matrix;
using plants::binding::Vector;
using plants::binding::VectorOut;

using TensorOut = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using MatrixOut = plants::binding::MatrixOut;
using IntVectorOut = nb::ndarray<int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;

namespace {

std::string shape_text(size_t a, size_t b) { return "(" + std::to_string(a) + ", " + std::to_string(b) + ")"; }

/// The named views of the workspace tuple ws = (mats, vecs, rowv, ints) for n variables and n_rows rows.
GIWorkspace workspace(const nb::tuple& ws, size_t n, size_t n_rows) {
    expect(ws.size() == 4, "ws", "the tuple (mats, vecs, rowv, ints) of gi_workspace(n, n_rows)");
    TensorOut mats;
    MatrixOut vecs, rowv;
    IntVectorOut ints;
    expect(nb::try_cast(ws[0], mats, false), "ws[0] (mats)", "a C-contiguous float64 array (3, n, n)");
    expect(nb::try_cast(ws[1], vecs, false), "ws[1] (vecs)", "a C-contiguous float64 array (8, n + 1)");
    expect(nb::try_cast(ws[2], rowv, false), "ws[2] (rowv)", "a C-contiguous float64 array (2, n_rows)");
    expect(nb::try_cast(ws[3], ints, false), "ws[3] (ints)", "a C-contiguous int64 array (4 + 4 n + 3 n_rows)");
    expect(mats.shape(0) == 3 && mats.shape(1) == n && mats.shape(2) == n, "ws[0] (mats)",
           "shape (3, " + std::to_string(n) + ", " + std::to_string(n) + "): gi_workspace(n, n_rows) of this QP");
    expect(vecs.shape(0) == 8 && vecs.shape(1) == n + 1, "ws[1] (vecs)",
           "shape " + shape_text(8, n + 1) + ": gi_workspace(n, n_rows) of this QP");
    expect(rowv.shape(0) == 2 && rowv.shape(1) == n_rows, "ws[2] (rowv)",
           "shape " + shape_text(2, n_rows) + ": gi_workspace(n, n_rows) of this QP");
    expect_length(ints.shape(0), static_cast<size_t>(gi_ints_length(static_cast<int>(n), static_cast<int>(n_rows))),
                  "ws[3] (ints)");
    GIWorkspace view = gi_workspace_view(static_cast<int>(n), static_cast<int>(n_rows), mats.data(), vecs.data(),
                                         rowv.data(), ints.data());
    expect(view.state->active >= 0 && view.state->active <= static_cast<int64_t>(n), "ws[3][0] (active count)",
           "0 to n = " + std::to_string(n) + " (0 for a cold start), got " + std::to_string(view.state->active));
    return view;
}

nb::tuple solve(Matrix H, Vector g, Matrix M, Vector lo, Vector hi, int n_eq, VectorOut x, VectorOut z,
                nb::tuple ws, bool new_H, double tol, int64_t max_iter) {
    const size_t n = H.shape(0);
    const size_t n_rows = M.shape(0);
    expect(H.shape(1) == n, "H", "a square matrix, got shape " + shape_text(H.shape(0), H.shape(1)));
    expect_length(g.shape(0), n, "g");
    expect(M.shape(1) == n, "M", "n = " + std::to_string(n) + " columns (H is n x n), got " +
                                     std::to_string(M.shape(1)));
    expect_length(lo.shape(0), n_rows, "lo");
    expect_length(hi.shape(0), n_rows, "hi");
    expect(n_eq >= 0 && static_cast<size_t>(n_eq) <= n_rows, "n_eq",
           "0 to the rows of M (" + std::to_string(n_rows) + "), got " + std::to_string(n_eq));
    expect_length(x.shape(0), n, "x");
    expect_length(z.shape(0), n_rows, "z");
    expect(max_iter >= 0, "max_iter", "a non-negative iteration limit, got " + std::to_string(max_iter));
    GIWorkspace view = workspace(ws, n, n_rows);
    const QP qp{static_cast<int>(n), static_cast<int>(n_rows), n_eq, H.data(), g.data(), M.data(), lo.data(),
                hi.data()};
    int64_t iterations = 0;
    const int status = gi_solve(qp, x.data(), z.data(), view, new_H, tol, max_iter, &iterations);
    return nb::make_tuple(status, iterations);
}

int64_t active_inequalities(nb::tuple ws, int n_eq) {
    expect(ws.size() == 4, "ws", "the tuple (mats, vecs, rowv, ints) of gi_workspace(n, n_rows)");
    TensorOut mats;
    MatrixOut rowv;
    expect(nb::try_cast(ws[0], mats, false), "ws[0] (mats)", "a C-contiguous float64 array (3, n, n)");
    expect(nb::try_cast(ws[2], rowv, false), "ws[2] (rowv)", "a C-contiguous float64 array (2, n_rows)");
    const GIWorkspace view = workspace(ws, mats.shape(1), rowv.shape(1));
    return gi_active_inequalities(view, n_eq);
}


}  // namespace

void bind_qp(nb::module_& m) {
    m.attr("GI_SOLVED") = static_cast<int>(GI_SOLVED);
    m.attr("GI_INFEASIBLE") = static_cast<int>(GI_INFEASIBLE);
    m.attr("GI_MAX_ITER") = static_cast<int>(GI_MAX_ITER);
    m.attr("GI_NOT_CONVEX") = static_cast<int>(GI_NOT_CONVEX);
    m.def("gi_solve", &solve, nb::arg("H"), nb::arg("g"), nb::arg("M"), nb::arg("lo"), nb::arg("hi"),
          nb::arg("n_eq"), nb::arg("x").noconvert(), nb::arg("z").noconvert(), nb::arg("ws"), nb::arg("new_H"),
          nb::arg("tol"), nb::arg("max_iter"),
          "Solve min 1/2 x^T H x + g^T x s.t. M[:n_eq] x = lo[:n_eq], lo <= M x <= hi, warm started from the\n"
          "active set in ws (gi_workspace's tuple, shared with the numba solver); writes x and z (H x + g + M^T z\n"
          "= 0). Returns (status, iterations) (coopctrl/core/goldfarb_idnani.h).");
    m.def("gi_active_inequalities", &active_inequalities, nb::arg("ws"), nb::arg("n_eq"),
          "Number of inequality rows (>= n_eq) in the active set the last gi_solve with ws left.");
}

}  // namespace coopctrl::binding
