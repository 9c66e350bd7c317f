#include "coopctrl/core/goldfarb_idnani.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace coopctrl {

namespace {

/// Cholesky H = L L^T and Linv = L^{-1} (lower triangular); L (n, n) is written into work.
/// Returns false if H is not positive definite.
bool factor(const double* H, double* Linv, double* work, int n) {
    double* L = work;
    for (int j = 0; j < n; ++j) {
        double s = H[j * n + j];
        for (int k = 0; k < j; ++k) s -= L[j * n + k] * L[j * n + k];
        if (!(s > 0.0) || !std::isfinite(s)) return false;
        const double ljj = std::sqrt(s);
        L[j * n + j] = ljj;
        for (int i = j + 1; i < n; ++i) {
            s = H[i * n + j];
            for (int k = 0; k < j; ++k) s -= L[i * n + k] * L[j * n + k];
            L[i * n + j] = s / ljj;
        }
    }
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) Linv[i * n + j] = 0.0;
    for (int j = 0; j < n; ++j) {
        Linv[j * n + j] = 1.0 / L[j * n + j];
        for (int i = j + 1; i < n; ++i) {
            double s = 0.0;
            for (int k = j; k < i; ++k) s += L[i * n + k] * Linv[k * n + j];
            Linv[i * n + j] = -s / L[i * n + i];
        }
    }
    return true;
}

/// Append the constraint whose d = J^T a is given (q -> q + 1): Givens rotations of the pairs (q, i) fold
/// d[q:] into d[q]; d[:q+1] becomes column q of R.
void add_constraint(double* JT, double* R, double* d, int q, int n) {
    for (int i = q + 1; i < n; ++i) {
        const double b = d[i];
        if (b == 0.0) continue;
        const double a = d[q];
        const double h = std::sqrt(a * a + b * b);
        const double c = a / h;
        const double s = b / h;
        d[q] = h;
        d[i] = 0.0;
        for (int j = 0; j < n; ++j) {
            const double t1 = JT[q * n + j];
            const double t2 = JT[i * n + j];
            JT[q * n + j] = c * t1 + s * t2;
            JT[i * n + j] = c * t2 - s * t1;
        }
    }
    for (int i = 0; i < q + 1; ++i) R[i * n + q] = d[i];
}

/// Remove active constraint k (0 <= k < q), q -> q - 1: shift R's columns (and act, u) left, restore the
/// triangle with Givens rotations on rows (j, j + 1) of R and J^T.
void drop_constraint(double* JT, double* R, double* u, int64_t* act, int k, int q, int n) {
    for (int j = k; j < q - 1; ++j) {
        for (int i = 0; i < j + 2; ++i) R[i * n + j] = R[i * n + j + 1];
        act[j] = act[j + 1];
        u[j] = u[j + 1];
    }
    u[q - 1] = u[q];
    u[q] = 0.0;
    for (int i = 0; i < q; ++i) R[i * n + q - 1] = 0.0;
    for (int j = k; j < q - 1; ++j) {
        const double a = R[j * n + j];
        const double b = R[(j + 1) * n + j];
        if (b == 0.0) continue;
        const double h = std::sqrt(a * a + b * b);
        const double c = a / h;
        const double s = b / h;
        R[j * n + j] = h;
        R[(j + 1) * n + j] = 0.0;
        for (int col = j + 1; col < q - 1; ++col) {
            const double t1 = R[j * n + col];
            const double t2 = R[(j + 1) * n + col];
            R[j * n + col] = c * t1 + s * t2;
            R[(j + 1) * n + col] = c * t2 - s * t1;
        }
        for (int col = 0; col < n; ++col) {
            const double t1 = JT[j * n + col];
            const double t2 = JT[(j + 1) * n + col];
            JT[j * n + col] = c * t1 + s * t2;
            JT[(j + 1) * n + col] = c * t2 - s * t1;
        }
    }
}

/// d = J^T a for a = sign * M[row] (non-zero in columns c0:c1); returns |d|^2.
double normal_dot_J(const double* JT, const double* M, int row, double sign, double* d, int n, int64_t c0,
                    int64_t c1) {
    double tot = 0.0;
    const double* Mr = M + static_cast<long>(row) * n;
    for (int i = 0; i < n; ++i) {
        double s = 0.0;
        for (int64_t j = c0; j < c1; ++j) s += JT[i * n + j] * Mr[j];
        s *= sign;
        d[i] = s;
        tot += s * s;
    }
    return tot;
}

double tail_norm2(const double* d, int q, int n) {
    double s = 0.0;
    for (int i = q; i < n; ++i) s += d[i] * d[i];
    return s;
}

/// M[row] . x over the row's non-zero columns.
double row_dot(const QP& qp, const GIWorkspace& ws, int64_t row, const double* x) {
    const double* Mr = qp.M + row * qp.n;
    double s = 0.0;
    for (int64_t j = ws.rfirst[row]; j < ws.rend[row]; ++j) s += Mr[j] * x[j];
    return s;
}

/// x, u of the minimiser on the active set: v = b_A - N^T x0, w = R^{-T} v, x = x0 + J_1 w, u = R^{-1} w.
void equality_point(const QP& qp, GIWorkspace& ws, int q, double* x) {
    const int n = qp.n;
    const double* JT = ws.JT;
    const double* R = ws.R;
    double* v = ws.v;
    double* u = ws.u;
    for (int i = 0; i < q; ++i) {
        const int64_t code = ws.act[i];
        const int64_t row = code >> 1;
        const double s = row_dot(qp, ws, row, ws.x0);
        if (code & 1)
            v[i] = s - qp.hi[row];  // b = -hi, a = -M_r: b - a^T x0 = -hi + M_r x0
        else
            v[i] = qp.lo[row] - s;
    }
    // forward substitution with R^T (lower)
    for (int i = 0; i < q; ++i) {
        double s = v[i];
        for (int k = 0; k < i; ++k) s -= R[k * n + i] * v[k];
        v[i] = s / R[i * n + i];
    }
    for (int j = 0; j < n; ++j) x[j] = ws.x0[j];
    for (int i = 0; i < q; ++i) {
        const double w = v[i];
        for (int j = 0; j < n; ++j) x[j] += JT[i * n + j] * w;
    }
    // back substitution u = R^{-1} w
    for (int i = q - 1; i >= 0; --i) {
        double s = v[i];
        for (int k = i + 1; k < q; ++k) s -= R[i * n + k] * u[k];
        u[i] = s / R[i * n + i];
    }
    u[q] = 0.0;
}

/// The fast path: is the minimiser on (equalities + the previous active set n_prev) the optimum? Returns q
/// (act, x, z written) or -1 (the caller then takes the factorised path). Y is ws.JT, the Gram factor ws.R.
int try_active_set(const QP& qp, GIWorkspace& ws, bool is_diag, int n_prev, double* x, double* z, double tol) {
    const int n_rows = qp.n_rows, n = qp.n, n_eq = qp.n_eq;
    const double* M = qp.M;
    const double* lo = qp.lo;
    const double* hi = qp.hi;
    const double* Linv = ws.Linv;
    double* Y = ws.JT;
    double* S = ws.R;
    double* u = ws.u;
    double* v = ws.v;
    double* t = ws.t;
    int64_t* act = ws.act;
    int64_t* mark = ws.mark;
    int64_t* sup_lo = ws.sup_lo;
    int64_t* sup_hi = ws.sup_hi;
    int q = 0;
    for (int k = 0; k < n_eq + n_prev; ++k) {
        int64_t code;
        if (k < n_eq)
            code = 2 * static_cast<int64_t>(k);
        else
            code = ws.prev[k - n_eq];
        const int64_t row = code >> 1;
        if (k >= n_eq) {
            if (row < n_eq || row >= n_rows || mark[row] != 0) continue;
            if (!std::isfinite((code & 1) ? hi[row] : lo[row])) continue;
        }
        if (q == n) return -1;
        const double sign = (code & 1) ? -1.0 : 1.0;
        // y = sign L^{-1} M[row] and its non-zero column range
        const int64_t first = ws.rfirst[row];
        const int64_t last = ws.rend[row] - 1;
        if (last < first) return -1;
        const double* Mr = M + row * n;
        if (is_diag) {
            for (int64_t j = first; j < last + 1; ++j) Y[q * n + j] = sign * Mr[j] * Linv[j * n + j];
            sup_hi[q] = last + 1;
        } else {
            for (int i = 0; i < n; ++i) {
                double acc = 0.0;
                for (int64_t j = first; j < i + 1; ++j) acc += Linv[i * n + j] * Mr[j];
                Y[q * n + i] = sign * acc;
            }
            sup_hi[q] = n;
        }
        sup_lo[q] = first;
        act[q] = code;
        mark[row] = 1;
        q += 1;
    }
    // Gram matrix S = Y Y^T (lower triangle) over overlapping column ranges, Cholesky in place
    for (int i = 0; i < q; ++i) {
        for (int j = 0; j < i + 1; ++j) {
            const int64_t a = std::max(sup_lo[i], sup_lo[j]);
            const int64_t b = std::min(sup_hi[i], sup_hi[j]);
            double acc = 0.0;
            for (int64_t c = a; c < b; ++c) acc += Y[i * n + c] * Y[j * n + c];
            S[i * n + j] = acc;
        }
    }
    for (int j = 0; j < q; ++j) {
        const double diag = S[j * n + j];
        double acc = diag;
        for (int c = 0; c < j; ++c) acc -= S[j * n + c] * S[j * n + c];
        if (!(acc > GI_GRAM_TOL * diag)) return -1;  // a (nearly) dependent row: the factorised path takes it
        const double ljj = std::sqrt(acc);
        S[j * n + j] = ljj;
        for (int i = j + 1; i < q; ++i) {
            acc = S[i * n + j];
            for (int c = 0; c < j; ++c) acc -= S[i * n + c] * S[j * n + c];
            S[i * n + j] = acc / ljj;
        }
    }
    // right-hand side v = b_A - N^T x0 and u = S^{-1} v
    for (int i = 0; i < q; ++i) {
        const int64_t code = act[i];
        const int64_t row = code >> 1;
        const double acc = row_dot(qp, ws, row, ws.x0);
        if (code & 1)
            v[i] = acc - hi[row];
        else
            v[i] = lo[row] - acc;
    }
    for (int i = 0; i < q; ++i) {
        double acc = v[i];
        for (int c = 0; c < i; ++c) acc -= S[i * n + c] * v[c];
        v[i] = acc / S[i * n + i];
    }
    for (int i = q - 1; i >= 0; --i) {
        double acc = v[i];
        for (int c = i + 1; c < q; ++c) acc -= S[c * n + i] * u[c];
        u[i] = acc / S[i * n + i];
        if (i >= n_eq && u[i] < 0.0) return -1;
    }
    // x = x0 + L^{-T} (Y^T u)
    for (int j = 0; j < n; ++j) t[j] = 0.0;
    for (int i = 0; i < q; ++i) {
        const double ui = u[i];
        for (int64_t j = sup_lo[i]; j < sup_hi[i]; ++j) t[j] += ui * Y[i * n + j];
    }
    if (is_diag) {
        for (int j = 0; j < n; ++j) x[j] = ws.x0[j] + Linv[j * n + j] * t[j];
    } else {
        for (int j = 0; j < n; ++j) {
            double acc = 0.0;
            for (int i = j; i < n; ++i) acc += Linv[i * n + j] * t[i];
            x[j] = ws.x0[j] + acc;
        }
    }
    // the active rows hold (the Gram solve was accurate) and every other row is within bounds?
    for (int i = 0; i < q; ++i) {
        const int64_t code = act[i];
        const int64_t row = code >> 1;
        const double acc = row_dot(qp, ws, row, x);
        const double b = (code & 1) ? hi[row] : lo[row];
        if (std::abs(acc - b) > tol * ws.rownorm[row]) return -1;
    }
    for (int row = n_eq; row < n_rows; ++row) {
        if (mark[row] != 0 || ws.rownorm[row] == 0.0) continue;
        const double acc = row_dot(qp, ws, row, x);
        if (lo[row] - acc > tol * ws.rownorm[row] || acc - hi[row] > tol * ws.rownorm[row]) return -1;
    }
    for (int i = 0; i < q; ++i) {
        const int64_t code = act[i];
        if (code & 1)
            z[code >> 1] = u[i];
        else
            z[code >> 1] = -u[i];
    }
    return q;
}

}  // namespace

GIWorkspace gi_workspace_view(int n, int n_rows, double* mats, double* vecs, double* rowv, int64_t* ints) noexcept {
    GIWorkspace ws{};
    ws.n = n;
    ws.n_rows = n_rows;
    const long nn = static_cast<long>(n) * n;
    const long n1 = n + 1;
    ws.JT = mats;
    ws.R = mats + nn;
    ws.Linv = mats + 2 * nn;
    ws.d = vecs;
    ws.zz = vecs + n1;
    ws.r = vecs + 2 * n1;
    ws.u = vecs + 3 * n1;
    ws.x0 = vecs + 4 * n1;
    ws.v = vecs + 5 * n1;
    ws.t = vecs + 6 * n1;
    ws.rownorm = rowv;
    static_assert(sizeof(GIWarmState) == 4 * sizeof(int64_t), "GIWarmState is ints[0:4]");
    ws.state = reinterpret_cast<GIWarmState*>(ints);
    ws.act = ints + 4;
    ws.prev = ints + 4 + n;
    ws.sup_lo = ints + 4 + 2 * n;
    ws.sup_hi = ints + 4 + 3 * n;
    ws.mark = ints + 4 + 4 * n;
    ws.rfirst = ints + 4 + 4 * n + n_rows;
    ws.rend = ints + 4 + 4 * n + 2 * n_rows;
    return ws;
}

int gi_solve(const QP& qp, double* x, double* z, GIWorkspace& ws, bool new_H, double tol, int64_t max_iter,
             int64_t* iterations) noexcept {
    const int n = qp.n;
    const int n_rows = qp.n_rows;
    const int n_eq = qp.n_eq;
    const double* M = qp.M;
    const double* lo = qp.lo;
    const double* hi = qp.hi;
    GIWarmState& st = *ws.state;
    double* JT = ws.JT;
    double* R = ws.R;
    double* Linv = ws.Linv;
    double* d = ws.d;
    double* zz = ws.zz;
    double* r = ws.r;
    double* u = ws.u;
    double* x0 = ws.x0;
    double* v = ws.v;
    double* rownorm = ws.rownorm;
    int64_t* act = ws.act;
    int64_t* prev = ws.prev;
    int64_t* mark = ws.mark;
    int64_t* rfirst = ws.rfirst;
    int64_t* rend = ws.rend;
    *iterations = 0;
    for (int i = 0; i < n_rows; ++i) z[i] = 0.0;
    // ---- factor of H (cached) and the unconstrained minimiser x0 = -H^{-1} g
    if (new_H || st.factor_valid == 0) {
        st.factor_valid = 0;
        if (!factor(qp.H, Linv, JT, n)) {
            st.active = 0;
            for (int j = 0; j < n; ++j) x[j] = 0.0;
            return GI_NOT_CONVEX;
        }
        st.factor_valid = 1;
        int64_t diag = 1;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < i; ++j)
                if (Linv[i * n + j] != 0.0) diag = 0;
        st.H_diagonal = diag;
    }
    for (int i = 0; i < n; ++i) {  // v = L^{-1} g
        double s = 0.0;
        for (int j = 0; j < i + 1; ++j) s += Linv[i * n + j] * qp.g[j];
        v[i] = s;
    }
    for (int j = 0; j < n; ++j) {  // x0 = -L^{-T} v
        double s = 0.0;
        for (int i = j; i < n; ++i) s += Linv[i * n + j] * v[i];
        x0[j] = -s;
        if (!std::isfinite(x0[j])) {
            st.active = 0;
            return GI_NOT_CONVEX;
        }
    }
    for (int i = 0; i < n_rows; ++i) {
        const double* Mi = M + static_cast<long>(i) * n;
        int c0 = 0;
        while (c0 < n && Mi[c0] == 0.0) c0 += 1;
        int c1 = n;
        while (c1 > c0 && Mi[c1 - 1] == 0.0) c1 -= 1;
        rfirst[i] = c0;
        rend[i] = c1;
        double s = 0.0;
        for (int j = c0; j < c1; ++j) s += Mi[j] * Mi[j];
        rownorm[i] = std::sqrt(s);
        mark[i] = 0;
        if (!std::isfinite(s) || std::isnan(lo[i]) || std::isnan(hi[i])) {
            st.active = 0;
            return GI_NOT_CONVEX;
        }
        if (s == 0.0 && (lo[i] > tol || hi[i] < -tol)) {
            // a zero row with a bound it cannot meet: inconsistent whatever x is
            st.active = 0;
            for (int j = 0; j < n; ++j) x[j] = x0[j];
            return GI_INFEASIBLE;
        }
    }
    // ---- fast path: the equalities and the previous active set may still be optimal
    const int n_prev = static_cast<int>(st.active);
    for (int i = 0; i < n_prev; ++i) prev[i] = act[i];
    int q = try_active_set(qp, ws, st.H_diagonal == 1, n_prev, x, z, tol);
    if (q >= 0) {
        st.active = q;
        st.fast_path = 1;
        return GI_SOLVED;
    }
    st.fast_path = 0;
    for (int i = 0; i < n_rows; ++i) mark[i] = 0;
    // ---- warm start: equalities, then the previous active inequalities, added without steps
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) JT[i * n + j] = Linv[i * n + j];
    q = 0;
    bool skipped_eq = false;
    for (int row = 0; row < n_eq; ++row) {
        if (q == n) {
            skipped_eq = true;
            break;
        }
        const double tot = normal_dot_J(JT, M, row, 1.0, d, n, rfirst[row], rend[row]);
        if (tail_norm2(d, q, n) <= GI_DEP_TOL * GI_DEP_TOL * tot) {
            skipped_eq = true;
            continue;
        }
        add_constraint(JT, R, d, q, n);
        act[q] = 2 * static_cast<int64_t>(row);
        mark[row] = 1;
        q += 1;
    }
    for (int i = 0; i < n_prev; ++i) {
        const int64_t code = prev[i];
        const int64_t row = code >> 1;
        if (row < n_eq || row >= n_rows || mark[row] != 0 || q == n) continue;
        double sign;
        if (code & 1) {
            if (!std::isfinite(hi[row])) continue;
            sign = -1.0;
        } else {
            if (!std::isfinite(lo[row])) continue;
            sign = 1.0;
        }
        const double tot = normal_dot_J(JT, M, static_cast<int>(row), sign, d, n, rfirst[row], rend[row]);
        if (tail_norm2(d, q, n) <= GI_DEP_TOL * GI_DEP_TOL * tot) continue;
        add_constraint(JT, R, d, q, n);
        act[q] = code;
        mark[row] = 1;
        q += 1;
    }
    equality_point(qp, ws, q, x);
    int64_t iters = 0;
    // drop warm rows with negative multipliers (most negative first) until dual feasible
    while (true) {
        int kmin = -1;
        double umin = 0.0;
        for (int i = 0; i < q; ++i) {
            if ((act[i] >> 1) >= n_eq && u[i] < umin) {
                umin = u[i];
                kmin = i;
            }
        }
        if (kmin < 0) break;
        mark[act[kmin] >> 1] = 0;
        drop_constraint(JT, R, u, act, kmin, q, n);
        q -= 1;
        iters += 1;
        equality_point(qp, ws, q, x);
    }
    if (skipped_eq) {
        // a dependent equality row must hold at the minimiser of the independent ones
        for (int row = 0; row < n_eq; ++row) {
            if (mark[row] == 0) {
                const double s = row_dot(qp, ws, row, x);
                if (std::abs(s - lo[row]) > tol * std::max(rownorm[row], 1e-300)) {
                    st.active = q;
                    *iterations = iters;
                    return GI_INFEASIBLE;
                }
            }
        }
    }
    // ---- the dual active-set iterations
    int status = GI_SOLVED;
    while (true) {
        // most violated side of an inactive inequality row (violation / |row|)
        int64_t p = -1;
        double worst = tol;
        for (int row = n_eq; row < n_rows; ++row) {
            if (mark[row] != 0 || rownorm[row] == 0.0) continue;
            const double s = row_dot(qp, ws, row, x);
            double viol = lo[row] - s;
            if (viol > worst * rownorm[row]) {
                worst = viol / rownorm[row];
                p = 2 * static_cast<int64_t>(row);
            }
            viol = s - hi[row];
            if (viol > worst * rownorm[row]) {
                worst = viol / rownorm[row];
                p = 2 * static_cast<int64_t>(row) + 1;
            }
        }
        if (p < 0) break;
        const int64_t prow = p >> 1;
        const double sign = (p & 1) ? -1.0 : 1.0;
        const double bp = (p & 1) ? -hi[prow] : lo[prow];
        u[q] = 0.0;
        // step for constraint p: repeated after each drop
        while (true) {
            if (iters >= max_iter) {
                status = GI_MAX_ITER;
                break;
            }
            iters += 1;
            const double s = row_dot(qp, ws, prow, x);
            const double sp = sign * s - bp;  // < 0 while violated
            const double tot = normal_dot_J(JT, M, static_cast<int>(prow), sign, d, n, rfirst[prow], rend[prow]);
            const double tail = tail_norm2(d, q, n);
            // r = R^{-1} d_1 and the blocking multiplier t1
            double t1 = std::numeric_limits<double>::infinity();
            int it1 = -1;
            for (int i = q - 1; i >= 0; --i) {
                double acc = d[i];
                for (int k = i + 1; k < q; ++k) acc -= R[i * n + k] * r[k];
                acc /= R[i * n + i];
                r[i] = acc;
            }
            for (int i = 0; i < q; ++i) {
                if ((act[i] >> 1) >= n_eq && r[i] > 0.0) {
                    const double t = u[i] / r[i];
                    if (t < t1) {
                        t1 = t;
                        it1 = i;
                    }
                }
            }
            if (tail <= GI_DEP_TOL * GI_DEP_TOL * tot || q == n) {
                // no primal step: a_p is in the span of the active normals
                if (it1 < 0) {
                    status = GI_INFEASIBLE;
                    break;
                }
                for (int i = 0; i < q; ++i) u[i] -= t1 * r[i];
                u[q] += t1;
                mark[act[it1] >> 1] = 0;
                drop_constraint(JT, R, u, act, it1, q, n);
                q -= 1;
                continue;
            }
            // primal direction zz = J_2 d_2; full step t2
            for (int j = 0; j < n; ++j) zz[j] = 0.0;
            for (int i = q; i < n; ++i) {
                const double di = d[i];
                if (di != 0.0)
                    for (int j = 0; j < n; ++j) zz[j] += JT[i * n + j] * di;
            }
            const double t2 = -sp / tail;  // z^T a_p = |d_2|^2
            const double t = (t2 <= t1) ? t2 : t1;
            for (int j = 0; j < n; ++j) x[j] += t * zz[j];
            for (int i = 0; i < q; ++i) u[i] -= t * r[i];
            u[q] += t;
            if (t2 <= t1) {
                add_constraint(JT, R, d, q, n);
                act[q] = p;
                mark[prow] = 1;
                q += 1;
                break;
            }
            mark[act[it1] >> 1] = 0;
            drop_constraint(JT, R, u, act, it1, q, n);
            q -= 1;
        }
        if (status != GI_SOLVED) break;
    }
    st.active = q;
    // multipliers per row, in proxsuite's convention
    for (int i = 0; i < q; ++i) {
        const int64_t code = act[i];
        const int64_t row = code >> 1;
        if (code & 1)
            z[row] = u[i];
        else
            z[row] = -u[i];
    }
    *iterations = iters;
    return status;
}

int64_t gi_active_inequalities(const GIWorkspace& ws, int n_eq) noexcept {
    int64_t count = 0;
    for (int64_t i = 0; i < ws.state->active; ++i)
        if ((ws.act[i] >> 1) >= n_eq) count += 1;
    return count;
}

}  // namespace coopctrl
