// The load-distribution QP's kernels in coopctrl._core: the Goldfarb-Idnani solver (coopctrl/core/goldfarb_idnani.h)
// on the workspace tuple (mats, vecs, rowv, ints) of coopctrl.load_distribution.goldfarb_idnani.gi_workspace, and
// the QP's assembly and checks (coopctrl/core/qp_*.h). Each function
// checks that every index it will touch lies inside the arrays it is given, once, and calls the core.
#include <algorithm>
#include <cstddef>
#include <string>

#include "coopctrl/core/goldfarb_idnani.h"
#include "coopctrl/core/qp_answer_check.h"
#include "coopctrl/core/qp_assembly.h"
#include "coopctrl/core/qp_constants.h"
#include "coopctrl/core/qp_constants_reader.h"
#include "coopctrl/core/qp_contact_model.h"
#include "coopctrl/core/qp_elastic_assembly.h"
#include "coopctrl/core/linear_algebra.h"
#include "coopctrl/core/qp_tensions.h"
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
using IntVector = nb::ndarray<const int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Tensor = nb::ndarray<const double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;

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


// ---- the QP's assembly (coopctrl/core/qp_assembly.h)

int ld(const MatrixOut& a) { return static_cast<int>(a.shape(1)); }
int ld(const Matrix& a) { return static_cast<int>(a.shape(1)); }

void expect_at_least(const char* name, size_t rows, size_t cols, size_t want_rows, size_t want_cols) {
    expect(rows >= want_rows && cols >= want_cols, name,
           "at least " + shape_text(want_rows, want_cols) + ", got " + shape_text(rows, cols));
}

void grasp_rows(MatrixOut M, Matrix r, Vector r0, bool spatial) {
    const size_t k = spatial ? 6 : 3, npos = spatial ? 3 : 2, m = r.shape(0);
    expect_at_least("M", M.shape(0), M.shape(1), k, k * m);
    expect(r.shape(1) == npos, "r", std::to_string(npos) + " columns (the contact positions), got " +
                                        std::to_string(r.shape(1)));
    expect_length(r0.shape(0), npos, "r0");
    fill_grasp_rows(M.data(), ld(M), r.data(), static_cast<int>(m), static_cast<int>(npos), r0.data(), spatial);
}

bool pinv_external(Matrix M, int k, Vector W_inv_diag, Vector w, VectorOut external, MatrixOut A, VectorOut y) {
    const size_t n = W_inv_diag.shape(0);
    expect(k >= 0, "k", "a non-negative row count, got " + std::to_string(k));
    expect_at_least("M", M.shape(0), M.shape(1), k, n);
    expect(w.shape(0) >= static_cast<size_t>(k), "w", "at least k = " + std::to_string(k) + " entries");
    expect_length(external.shape(0), n, "external");
    expect_at_least("A", A.shape(0), A.shape(1), k, k);
    expect(y.shape(0) >= static_cast<size_t>(k), "y", "at least k = " + std::to_string(k) + " entries");
    return pseudo_inverse_external(M.data(), ld(M), k, W_inv_diag.data(), static_cast<int>(n), w.data(),
                                   external.data(), A.data(), ld(A), y.data());
}

bool squeeze_basis(MatrixOut E, Matrix r, int k) {
    const size_t m = r.shape(0), npos = r.shape(1);
    expect(k >= static_cast<int>(npos), "k", "at least the columns of r (" + std::to_string(npos) + ")");
    expect_at_least("E", E.shape(0), E.shape(1), k * m, m * (m - (m > 0)) / 2);
    return fill_squeeze_basis(E.data(), ld(E), r.data(), static_cast<int>(m), static_cast<int>(npos), k);
}

void grip_rows(MatrixOut M, int row0, Matrix nrm, int k) {
    const size_t m = nrm.shape(0), npos = nrm.shape(1);
    expect(row0 >= 0 && k >= static_cast<int>(npos), "row0, k", "row0 >= 0 and k >= the columns of nrm");
    expect_at_least("M", M.shape(0), M.shape(1), row0 + m, k * m);
    fill_grip_rows(M.data(), ld(M), row0, nrm.data(), static_cast<int>(m), static_cast<int>(npos), k);
}

void friction_rows(MatrixOut M, int row0, Matrix nrm, int k, int nf, double mu_c, Vector cos_phi, Vector sin_phi,
                   bool spatial) {
    const size_t m = nrm.shape(0);
    const size_t per = spatial ? static_cast<size_t>(nf) : 2;
    expect(nrm.shape(1) >= (spatial ? 3u : 2u), "nrm", spatial ? "3 columns (spatial)" : "2 columns (planar)");
    expect(row0 >= 0 && nf >= 0 && k >= (spatial ? 3 : 2), "row0, nf, k", "row0 >= 0, nf >= 0 and k >= npos");
    expect_at_least("M", M.shape(0), M.shape(1), row0 + per * m, k * m);
    if (spatial) {
        expect(cos_phi.shape(0) >= static_cast<size_t>(nf), "cos_phi", "at least nf entries");
        expect(sin_phi.shape(0) >= static_cast<size_t>(nf), "sin_phi", "at least nf entries");
    }
    fill_friction_rows(M.data(), ld(M), row0, nrm.data(), static_cast<int>(nrm.shape(1)), static_cast<int>(m), k, nf,
                       mu_c, cos_phi.data(), sin_phi.data(), spatial);
}

void torque_rows(MatrixOut M, VectorOut lo, VectorOut hi, int row0, Tensor Jg, IntVector dofs, int k, Vector tau_qp,
                 Vector bias) {
    const size_t m = dofs.shape(0);
    expect(Jg.shape(0) >= m && Jg.shape(1) >= static_cast<size_t>(k), "Jg", "shape (>= m, >= k, >= max dofs)");
    size_t total = 0;
    for (size_t i = 0; i < m; ++i) {
        expect(dofs(i) >= 0 && static_cast<size_t>(dofs(i)) <= Jg.shape(2), "dofs",
               "0 to the columns of Jg (" + std::to_string(Jg.shape(2)) + ") per arm");
        total += static_cast<size_t>(dofs(i));
    }
    expect(row0 >= 0 && k >= 0, "row0, k", "non-negative");
    expect_at_least("M", M.shape(0), M.shape(1), row0 + total, k * m);
    expect(lo.shape(0) >= row0 + total && hi.shape(0) >= row0 + total, "lo, hi", "at least row0 + sum(dofs) entries");
    expect(tau_qp.shape(0) >= total && bias.shape(0) >= total, "tau_qp, bias", "at least sum(dofs) entries");
    fill_torque_rows(M.data(), lo.data(), hi.data(), ld(M), row0, Jg.data(),
                     static_cast<long>(Jg.shape(1) * Jg.shape(2)), static_cast<int>(Jg.shape(2)), dofs.data(),
                     static_cast<int>(m), k, tau_qp.data(), bias.data());
}

// ---- the answer's check (coopctrl/core/qp_answer_check.h)

void expect_answer(const Matrix& M, const Vector& lo, const Vector& hi, const Vector& x, int n) {
    expect(n >= 0 && static_cast<size_t>(n) <= M.shape(1) && static_cast<size_t>(n) <= x.shape(0), "n",
           "0 to the columns of M and the length of x");
    expect_length(lo.shape(0), M.shape(0), "lo");
    expect_length(hi.shape(0), M.shape(0), "hi");
}

nb::tuple violation(Matrix M, Vector lo, Vector hi, Vector x, int n) {
    expect_answer(M, lo, hi, x, n);
    double viol, scale;
    answer_violation(M.data(), ld(M), static_cast<int>(M.shape(0)), lo.data(), hi.data(), x.data(), n, &viol, &scale);
    return nb::make_tuple(viol, scale);
}

double tolerance(Vector lo, Vector hi, int k, double viol, double scale, double eps_abs, double rho) {
    expect_length(hi.shape(0), lo.shape(0), "hi");
    return answer_tolerance(lo.data(), hi.data(), static_cast<int>(lo.shape(0)), k, viol, scale, eps_abs, rho);
}

bool ok(Matrix M, Vector lo, Vector hi, Vector x, int n, int k, double eps_abs, double rho) {
    expect_answer(M, lo, hi, x, n);
    return answer_ok(M.data(), ld(M), static_cast<int>(M.shape(0)), lo.data(), hi.data(), x.data(), n, k, eps_abs,
                     rho);
}

int64_t families(Vector g, Vector z, int z0, int n, int n_in, int m, int64_t row_grip, int64_t row_fric,
                 int64_t n_fric, int64_t row_tau) {
    expect(n >= 0 && static_cast<size_t>(n) <= g.shape(0), "n", "0 to the length of g");
    expect(z0 >= 0 && n_in >= 0 && static_cast<size_t>(z0 + n_in) <= z.shape(0), "z0, n_in",
           "z0 + n_in within the length of z (" + std::to_string(z.shape(0)) + ")");
    return binding_families(g.data(), z.data(), z0, n, n_in, m, row_grip, row_fric, n_fric, row_tau);
}


// ---- the contact model (coopctrl/core/qp_contact_model.h)

void normals(Matrix Y, bool spatial, MatrixOut nrm, MatrixOut R) {
    const size_t m = nrm.shape(0), p = spatial ? 6 : 3, npos = spatial ? 3 : 2;
    expect(Y.shape(0) == m + 1 && Y.shape(1) >= p, "Y", "shape (m + 1, " + std::to_string(p) + "), m = rows of nrm");
    expect(nrm.shape(1) >= npos, "nrm", "at least " + std::to_string(npos) + " columns");
    expect(R.shape(0) == 3 && R.shape(1) == 3, "R", "shape (3, 3)");
    contact_normals(Y.data(), ld(Y), spatial, nrm.data(), ld(nrm), static_cast<int>(m), R.data());
}

void expect_shape(const char* name, size_t got0, size_t got1, size_t got2, size_t want0, size_t want1,
                  size_t want2) {
    expect(got0 == want0 && got1 == want1 && got2 == want2, name,
           "shape (" + std::to_string(want0) + ", " + std::to_string(want1) + ", " + std::to_string(want2) +
               "), got (" + std::to_string(got0) + ", " + std::to_string(got1) + ", " + std::to_string(got2) + ")");
}

void expect_shape(const char* name, size_t got0, size_t got1, size_t want0, size_t want1) {
    expect(got0 == want0 && got1 == want1, name, "shape " + shape_text(want0, want1) + ", got " +
                                                     shape_text(got0, got1));
}

void torque_model_binding(bool spatial, Matrix Y, Matrix ddYn, Tensor W, Matrix w_free, Tensor H, Matrix h, Tensor J,
                          Matrix Jdq, IntVector arm_kind, IntVector arm_dof, TensorOut Jg, VectorOut bias,
                          VectorOut Wa, VectorOut rhs_t, VectorOut qdd, IntVectorOut piv, MatrixOut wv, TensorOut wm,
                          TensorOut R3) {
    const size_t m = arm_kind.shape(0), p = spatial ? 6 : 3, nmax = H.shape(1);
    expect_length(arm_dof.shape(0), m, "arm_dof");
    expect_shape("Y", Y.shape(0), Y.shape(1), m + 1, p);
    expect_shape("ddYn", ddYn.shape(0), ddYn.shape(1), m + 1, p);
    expect_shape("W", W.shape(0), W.shape(1), W.shape(2), m + 1, p, p);
    expect_shape("w_free", w_free.shape(0), w_free.shape(1), m + 1, p);
    expect_shape("H", H.shape(0), H.shape(1), H.shape(2), m, nmax, nmax);
    expect_shape("h", h.shape(0), h.shape(1), m, nmax);
    expect_shape("J", J.shape(0), J.shape(1), J.shape(2), m, p, nmax);
    expect_shape("Jdq", Jdq.shape(0), Jdq.shape(1), m, p);
    size_t total = 0, nbig = 0;
    for (size_t i = 0; i < m; ++i) {
        const size_t ni = static_cast<size_t>(arm_dof(i));
        expect(arm_dof(i) >= 0 && (arm_kind(i) != 0 ? ni == p : ni <= nmax), "arm_dof",
               "0 to nmax joints per arm (p for a contact point)");
        total += ni;
        nbig = std::max(nbig, ni);
    }
    expect(Jg.shape(0) == m && Jg.shape(1) == p && Jg.shape(2) >= std::max(p, nmax), "Jg",
           "shape (m, p, >= max(p, nmax))");
    expect(bias.shape(0) >= total, "bias", "at least sum(arm_dof) = " + std::to_string(total) + " entries");
    expect(Wa.shape(0) >= p && rhs_t.shape(0) >= p, "Wa, rhs_t", "at least p entries");
    const size_t ldw = wm.shape(2);
    expect(qdd.shape(0) >= std::max(p, nbig) && piv.shape(0) >= std::max(p, nbig), "qdd, piv",
           "at least max(p, nmax) entries");
    expect(wm.shape(0) >= WORK_MATRICES && wm.shape(1) == ldw && ldw >= std::max(p, nbig), "wm",
           "shape (4, nmax, nmax) with nmax >= p (control_work)");
    expect(wv.shape(0) >= WORK_VECTORS && wv.shape(1) == ldw, "wv", "shape (8, nmax) as wm (control_work)");
    expect(R3.shape(0) >= 3 && R3.shape(1) == 3 && R3.shape(2) == 3, "R3", "shape (>= 3, 3, 3)");
    const TorqueModelInputs in{static_cast<int>(m), static_cast<int>(p), static_cast<int>(nmax), Y.data(),
                               ddYn.data(), W.data(), w_free.data(), H.data(), h.data(), J.data(), Jdq.data(),
                               arm_kind.data(), arm_dof.data()};
    TorqueModel out{Jg.data(), static_cast<int>(Jg.shape(2)), bias.data()};
    TorqueModelWork work{Wa.data(), rhs_t.data(), qdd.data(), piv.data(), wv.data(), wm.data(),
                         static_cast<int>(ldw), R3.data()};
    torque_model(spatial, in, out, work);
}

// ---- the pair tensions (coopctrl/core/qp_tensions.h)

void tensions(Matrix E, Matrix F, int npos, Vector desired, MatrixOut W, MatrixOut V, VectorOut sigma, VectorOut out) {
    const size_t R = E.shape(0), P = E.shape(1);
    const size_t rows = P <= R ? R : P, cols = P <= R ? P : R;
    expect(npos >= 1 && R % static_cast<size_t>(npos) == 0, "npos", "a divisor of the rows of E");
    expect(F.shape(0) >= R / npos && F.shape(1) >= static_cast<size_t>(npos), "F", "shape (>= R / npos, >= npos)");
    expect_length(desired.shape(0), P, "desired");
    expect_shape("W", W.shape(0), W.shape(1), rows, cols);
    expect_shape("V", V.shape(0), V.shape(1), cols, cols);
    expect_length(sigma.shape(0), cols, "sigma");
    expect_length(out.shape(0), P, "out");
    pair_tensions(E.data(), static_cast<int>(R), static_cast<int>(P), F.data(), ld(F), npos, desired.data(), W.data(),
                  V.data(), sigma.data(), out.data());
}

// ---- the elastic split (coopctrl/core/qp_elastic_assembly.h)

nb::tuple elastic_split(Matrix M, int k, Tensor K_obj, Vector Y0, bool spatial, MatrixOut K, MatrixOut P, Vector w,
                        VectorOut external, MatrixOut KGt, MatrixOut A, VectorOut y, MatrixOut Rb, MatrixOut work) {
    const size_t m = K_obj.shape(0), p = K_obj.shape(1), n = m * p;
    expect(K_obj.shape(2) == p && p == (spatial ? 6u : 3u), "K_obj", spatial ? "shape (m, 6, 6)" : "shape (m, 3, 3)");
    expect(k >= 0, "k", "a non-negative row count");
    expect_at_least("M", M.shape(0), M.shape(1), k, n);
    expect_length(Y0.shape(0), p, "Y0");
    expect_shape("K", K.shape(0), K.shape(1), n, n);
    expect_shape("P", P.shape(0), P.shape(1), n, n);
    expect(w.shape(0) >= static_cast<size_t>(k), "w", "at least k entries");
    expect_length(external.shape(0), n, "external");
    expect_at_least("KGt", KGt.shape(0), KGt.shape(1), n, k);
    expect_at_least("A", A.shape(0), A.shape(1), k, k);
    expect(y.shape(0) >= static_cast<size_t>(k), "y", "at least k entries");
    expect_shape("Rb", Rb.shape(0), Rb.shape(1), p, p);
    expect_shape("work", work.shape(0), work.shape(1), p, 2 * p);
    ElasticSplit e{static_cast<int>(m), static_cast<int>(p), k, M.data(), ld(M), K_obj.data(), Y0.data(), w.data(),
                   K.data(), P.data(), external.data(), KGt.data(), ld(KGt), A.data(), ld(A), y.data(), Rb.data(),
                   work.data()};
    bool changed = false;
    const int code = fill_elastic_split(e, spatial, &changed);
    return nb::make_tuple(code, changed);
}


// ---- the QP's constants (coopctrl/core/qp_constants.h)


nb::tuple answer_check_stage(Matrix M, Vector lo, Vector hi, Vector g, Vector x, Vector z, int k, int m,
                             nb::handle constants) {
    const size_t n = M.shape(1), n_rows = M.shape(0);
    expect_length(lo.shape(0), n_rows, "lo");
    expect_length(hi.shape(0), n_rows, "hi");
    expect_length(g.shape(0), n, "g");
    expect_length(x.shape(0), n, "x");
    expect_length(z.shape(0), n_rows, "z");
    expect(k >= 0 && static_cast<size_t>(k) <= n_rows, "k", "0 to the rows of M");
    QPConstants c{};
    c.n = static_cast<int>(n);
    c.numbers = read_qp_numbers(constants);
    c.rows = read_qp_rows(constants);
    const QP qp{static_cast<int>(n), static_cast<int>(n_rows), k, nullptr, g.data(), M.data(), lo.data(), hi.data()};
    int64_t families = 0;
    const bool ok = qp_answer_check(c, qp, x.data(), z.data(), m, &families);
    return nb::make_tuple(ok, families);
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
          "active set in ws (gi_workspace's tuple); writes x and z (H x + g + M^T z\n"
          "= 0). Returns (status, iterations) (coopctrl/core/goldfarb_idnani.h).");
    m.def("gi_active_inequalities", &active_inequalities, nb::arg("ws"), nb::arg("n_eq"),
          "Number of inequality rows (>= n_eq) in the active set the last gi_solve with ws left.");

    m.def("fill_grasp_rows", &grasp_rows, nb::arg("M").noconvert(), nb::arg("r"), nb::arg("r0"), nb::arg("spatial"),
          "Write the moment-arm entries of G = M[:k] for contacts r about r0 (coopctrl/core/qp_assembly.h).");
    m.def("pseudo_inverse_external", &pinv_external, nb::arg("M"), nb::arg("k"), nb::arg("W_inv_diag"), nb::arg("w"),
          nb::arg("external").noconvert(), nb::arg("A").noconvert(), nb::arg("y").noconvert(),
          "external = W^-1 G^T (G W^-1 G^T)^-1 w with G = M[:k]; False if G W^-1 G^T is not positive definite.");
    m.def("fill_squeeze_basis", &squeeze_basis, nb::arg("E").noconvert(), nb::arg("r"), nb::arg("k"),
          "Virtual-linkage columns of E; False if two contacts coincide.");
    m.def("fill_grip_rows", &grip_rows, nb::arg("M").noconvert(), nb::arg("row0"), nb::arg("nrm"), nb::arg("k"),
          "min_grip rows: row row0 + i holds n_i on arm i's force entries.");
    m.def("fill_friction_rows", &friction_rows, nb::arg("M").noconvert(), nb::arg("row0"), nb::arg("nrm"), nb::arg("k"),
          nb::arg("nf"), nb::arg("mu_c"), nb::arg("cos_phi"), nb::arg("sin_phi"), nb::arg("spatial"),
          "friction rows (the inscribed pyramid), nf per contact spatial, 2 planar.");
    m.def("fill_torque_rows", &torque_rows, nb::arg("M").noconvert(), nb::arg("lo").noconvert(),
          nb::arg("hi").noconvert(), nb::arg("row0"), nb::arg("Jg"), nb::arg("dofs"), nb::arg("k"), nb::arg("tau_qp"),
          nb::arg("bias"), "torque_limits rows J_i^T with lo = -tau_qp - bias, hi = tau_qp - bias [N m].");
    m.def("answer_violation", &violation, nb::arg("M"), nb::arg("lo"), nb::arg("hi"), nb::arg("x"), nb::arg("n"),
          "(v, s): the largest violation of lo <= M x <= hi and max |M x| (coopctrl/core/qp_answer_check.h).");
    m.def("answer_tolerance", &tolerance, nb::arg("lo"), nb::arg("hi"), nb::arg("k"), nb::arg("viol"),
          nb::arg("scale"), nb::arg("eps_abs"), nb::arg("rho"), "The answer's tolerance [N, N m].");
    m.def("answer_ok", &ok, nb::arg("M"), nb::arg("lo"), nb::arg("hi"), nb::arg("x"), nb::arg("n"), nb::arg("k"),
          nb::arg("eps_abs"), nb::arg("rho"), "Whether x[:n] is finite and within the answer's tolerance.");
    m.def("binding_families", &families, nb::arg("g"), nb::arg("z"), nb::arg("z0"), nb::arg("n"), nb::arg("n_in"),
          nb::arg("m"), nb::arg("row_grip"), nb::arg("row_fric"), nb::arg("n_fric"), nb::arg("row_tau"),
          "The mask of the families with a non-zero multiplier (FAMILY_MIN_GRIP | FAMILY_FRICTION | FAMILY_TORQUE).");
    m.attr("WORK_VECTORS") = WORK_VECTORS;
    m.attr("WORK_MATRICES") = WORK_MATRICES;
    m.def("contact_normals_into", &normals, nb::arg("Y"), nb::arg("spatial"), nb::arg("nrm").noconvert(),
          nb::arg("R").noconvert(), "The contacts' inward unit normals into nrm (coopctrl/core/qp_contact_model.h).");
    m.def("torque_model_into", &torque_model_binding, nb::arg("spatial"), nb::arg("Y"), nb::arg("ddYn"), nb::arg("W"),
          nb::arg("w_free"), nb::arg("H"), nb::arg("h"), nb::arg("J"), nb::arg("Jdq"), nb::arg("arm_kind"),
          nb::arg("arm_dof"), nb::arg("Jg").noconvert(), nb::arg("bias").noconvert(), nb::arg("Wa").noconvert(),
          nb::arg("rhs_t").noconvert(), nb::arg("qdd").noconvert(), nb::arg("piv").noconvert(),
          nb::arg("wv").noconvert(), nb::arg("wm").noconvert(), nb::arg("R3").noconvert(),
          "Write the torque model tau_i = Jg_i^T F_i + bias_i of every arm (coopctrl/core/qp_contact_model.h).");
    m.def("pair_tensions_into", &tensions, nb::arg("E"), nb::arg("F"), nb::arg("npos"), nb::arg("desired"),
          nb::arg("W").noconvert(), nb::arg("V").noconvert(), nb::arg("sigma").noconvert(), nb::arg("out").noconvert(),
          "The pair tensions [N] of the forces F on the pair columns E into out (coopctrl/core/qp_tensions.h).");
    m.def("fill_elastic_split", &elastic_split, nb::arg("M"), nb::arg("k"), nb::arg("K_obj"), nb::arg("Y0"),
          nb::arg("spatial"), nb::arg("K").noconvert(), nb::arg("P").noconvert(), nb::arg("w"),
          nb::arg("external").noconvert(), nb::arg("KGt").noconvert(), nb::arg("A").noconvert(),
          nb::arg("y").noconvert(), nb::arg("Rb").noconvert(), nb::arg("work").noconvert(),
          "Fill K, P and external of the elastic split; (code, P_changed) (coopctrl/core/qp_elastic_assembly.h).");
    m.def("qp_answer_check", &answer_check_stage, nb::arg("M"), nb::arg("lo"), nb::arg("hi"), nb::arg("g"),
          nb::arg("x"), nb::arg("z"), nb::arg("k"), nb::arg("m"), nb::arg("constants"),
          "(ok, families): the tick's check of a solved QP with the constants (a QPConstants: eps_abs, answer_rho,\n"
          "min_grip_row, friction_row, torque_row, facets, ...) read by name (coopctrl/core/qp_constants_reader.h).");
}

}  // namespace coopctrl::binding
