#include "coopctrl/core/preflight_ik.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "coopctrl/core/angle_wrap.h"
#include "plants/core/frames.h"

namespace coopctrl {

namespace {

/// The spatial forward kinematics' work for an arm of n joints.
struct TipWork {
    std::vector<double> axes, points;     // the DH kernel's
    std::vector<plants::ChainBody> chain;  // the chain kernel's
    explicit TipWork(int n) : axes(3 * n), points(3 * n), chain(n + 1) {}
};

/// The node frame's world pose T (4x4) and geometric Jacobian Jg (6 x n).
void arm_tip(const SpatialIKArm& arm, const double* q, TipWork& w, double* T, double* Jg) noexcept {
    if (arm.kind == IK_KIND_DH)
        plants::dh_arm_tip(arm.dh, q, w.axes.data(), w.points.data(), T, Jg);
    else
        plants::chain_arm_tip(arm.chain, q, w.chain.data(), T, Jg);
}

/// q_new = clip(q + Je^T (Je Je^T + lam I)^-1 e, lower, upper): Je (m x n), the Cholesky factor of the SPD A
/// (m x m) in its lower triangle, y (m) scratch.
void dls_trial(const double* Je, int m, int n, const double* e, double lam, const double* q, const double* lower,
               const double* upper, double* A, double* y, double* q_new) noexcept {
    for (int i = 0; i < m; ++i)
        for (int j = 0; j <= i; ++j) {
            double s = 0.0;
            for (int k = 0; k < n; ++k) s += Je[i * n + k] * Je[j * n + k];
            if (i == j) s += lam;
            A[i * m + j] = s;
        }
    for (int j = 0; j < m; ++j) {  // A = L L^T in the lower triangle
        double d = A[j * m + j];
        for (int k = 0; k < j; ++k) d -= A[j * m + k] * A[j * m + k];
        d = std::sqrt(d);
        A[j * m + j] = d;
        for (int i = j + 1; i < m; ++i) {
            double s = A[i * m + j];
            for (int k = 0; k < j; ++k) s -= A[i * m + k] * A[j * m + k];
            A[i * m + j] = s / d;
        }
    }
    for (int i = 0; i < m; ++i) {
        double s = e[i];
        for (int k = 0; k < i; ++k) s -= A[i * m + k] * y[k];
        y[i] = s / A[i * m + i];
    }
    for (int i = m - 1; i >= 0; --i) {
        double s = y[i];
        for (int k = i + 1; k < m; ++k) s -= A[k * m + i] * y[k];
        y[i] = s / A[i * m + i];
    }
    for (int k = 0; k < n; ++k) {
        double s = q[k];
        for (int i = 0; i < m; ++i) s += Je[i * n + k] * y[i];
        q_new[k] = std::min(std::max(s, lower[k]), upper[k]);
    }
}

/// The damped least-squares iteration's state for an arm of n joints and a task of m rows.
struct DLSWork {
    std::vector<double> Je, Je_new, e, e_new, A, y, q_new;
    DLSWork(int m, int n) : Je(m * n), Je_new(m * n), e(m), e_new(m), A(m * m), y(m), q_new(n) {}
};

/// The damped least squares from q (clipped to its limits), which gets the answer: error(q, Je, e) writes the
/// error e (rows) and its Jacobian Je at q and returns the cost |e|^2; converged(e) says when to stop. A trial that
/// lowers the cost is taken and the damping lowered (x 0.3, down to 1e-12), else raised (x 5, up to 1e6).
template <class Error, class Converged>
bool dls_minimize(DLSWork& w, int rows, int n, const double* lower, const double* upper, double* q, Error error,
                  Converged converged) {
    for (int k = 0; k < n; ++k) q[k] = std::min(std::max(q[k], lower[k]), upper[k]);
    double cost = error(q, w.Je.data(), w.e.data());
    double lam = 1e-2;
    for (int it = 0; it < IK_MAX_ITERATIONS; ++it) {
        if (converged(w.e.data())) break;
        dls_trial(w.Je.data(), rows, n, w.e.data(), lam, q, lower, upper, w.A.data(), w.y.data(), w.q_new.data());
        const double cost_new = error(w.q_new.data(), w.Je_new.data(), w.e_new.data());
        if (cost_new < cost) {
            std::copy(w.q_new.begin(), w.q_new.end(), q);
            std::swap(w.e, w.e_new);
            std::swap(w.Je, w.Je_new);
            cost = cost_new;
            lam = std::max(lam * 0.3, 1e-12);
        } else {
            lam *= 5.0;
            if (lam > 1e6) break;
        }
    }
    return converged(w.e.data());
}

/// The spatial pose error e (6) and geometric Jacobian Jg at q; returns |e|^2.
double spatial_error(const SpatialIKArm& arm, const double* p_target, const double* R_target, const double* q,
                     TipWork& w, double* T, double* Jg, double* M, double* e) noexcept {
    arm_tip(arm, q, w, T, Jg);
    for (int i = 0; i < 3; ++i) {
        e[i] = p_target[i] - T[i * 4 + 3];
        for (int j = 0; j < 3; ++j)
            M[i * 3 + j] = R_target[i * 3 + 0] * T[j * 4 + 0] + R_target[i * 3 + 1] * T[j * 4 + 1] +
                           R_target[i * 3 + 2] * T[j * 4 + 2];
    }
    plants::rotation_vector(M, e + 3);
    return e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3] + e[4] * e[4] + e[5] * e[5];
}

bool spatial_converged(const double* e, double tol) noexcept {
    return std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) <= tol &&
           std::sqrt(e[3] * e[3] + e[4] * e[4] + e[5] * e[5]) <= tol;
}

/// The spatial iteration from q, which gets the answer; returns whether it converged.
bool spatial_dls(const SpatialIKArm& arm, const IKSettings& settings, const double* p_target, const double* R_target,
                 double* q) {
    const int n = arm.dof();
    TipWork tip(n);
    DLSWork w(6, n);
    double T[16], M[9];
    return dls_minimize(
        w, 6, n, arm.lower, arm.upper, q,
        [&](const double* qq, double* Je, double* e) {
            return spatial_error(arm, p_target, R_target, qq, tip, T, Je, M, e);
        },
        [&](const double* e) { return spatial_converged(e, settings.tolerance); });
}

/// The null-space step d = (I - J_g^+ J_g)(posture - q) at q and |d|, as numba computes
/// np.linalg.pinv(Jg) @ Jg and P @ (posture - q): the SVD (dgesdd, 'S'), the reciprocal singular values above
/// 1e-15 of the largest applied to the smaller factor, the product by dgemm into the column-major pinv, then
/// dgemm and dgemv with the transposes numba passes for its row-major and column-major operands.
struct NullSpace {
    const SpatialIKArm& arm;
    const DenseRoutines& dense;
    int n, minmn;
    TipWork tip;
    std::vector<double> Jg, acpy, s, u, vt, JpJ, P, v, work;
    std::vector<int> iwork;
    double T[16];

    NullSpace(const SpatialIKArm& a, const DenseRoutines& r)
        : arm(a), dense(r), n(a.dof()), minmn(std::min(6, n)), tip(n), Jg(6 * n), acpy(6 * n), s(minmn),
          u(minmn * 6), vt(n * minmn), JpJ(n * n), P(n * n), v(n), iwork(8 * minmn) {}

    /// Returns POSTURE_OK with *norm = |d|, or the failure of the pseudo-inverse.
    PostureStatus operator()(const double* posture, const double* q, double* d, double* norm) {
        const int m = 6;
        arm_tip(arm, q, tip, T, Jg.data());
        for (int i = 0; i < m * n; ++i)
            if (!std::isfinite(Jg[i])) return POSTURE_NOT_FINITE;
        for (int r = 0; r < m; ++r)  // a copy in Fortran order
            for (int c = 0; c < n; ++c) acpy[r + c * m] = Jg[r * n + c];
        char jobz = 'S';
        int M = m, N = n, lda = m, ldu = m, ldvt = minmn, lwork = -1, info = 0;
        double query = 0.0;
        dense.gesdd(&jobz, &M, &N, acpy.data(), &lda, s.data(), u.data(), &ldu, vt.data(), &ldvt, &query, &lwork,
                    iwork.data(), &info);
        if (info < 0) return POSTURE_SVD_FAILED;
        lwork = static_cast<int>(query);
        work.assign(std::max(lwork, 1), 0.0);
        dense.gesdd(&jobz, &M, &N, acpy.data(), &lda, s.data(), u.data(), &ldu, vt.data(), &ldvt, work.data(),
                    &lwork, iwork.data(), &info);
        if (info != 0) return POSTURE_SVD_FAILED;
        const double cut_at = s[0] * 1e-15;
        int cut_idx = 0;
        for (int k = 0; k < minmn; ++k)
            if (s[k] > cut_at) {
                s[k] = 1. / s[k];
                cut_idx = k;
            }
        cut_idx += 1;
        if (m >= n) {  // vt as numba's (n, minmn) array
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < cut_idx; ++j) vt[i * minmn + j] = vt[i * minmn + j] * s[j];
        } else {  // u as numba's (minmn, m) array
            for (int i = 0; i < cut_idx; ++i) {
                const double s_local = s[i];
                for (int j = 0; j < minmn; ++j) u[i * m + j] = u[i * m + j] * s_local;
            }
        }
        char tc = 'C';
        double one = 1.0, zero = 0.0;
        int gm = n, gn = m, gk = cut_idx, ldvt2 = minmn, ldu2 = m, ldc = n;
        dense.gemm(&tc, &tc, &gm, &gn, &gk, &one, vt.data(), &ldvt2, u.data(), &ldu2, &zero, acpy.data(), &ldc);
        // JpJ = pinv(Jg) @ Jg (pinv column-major n x m with ld n, Jg row-major; the result row-major)
        char tn = 'n', tt = 't';
        int mm_m = n, mm_n = n, mm_k = m, ld_jg = n, ld_x = n, ld_out = n;
        dense.gemm(&tn, &tt, &mm_m, &mm_n, &mm_k, &one, Jg.data(), &ld_jg, acpy.data(), &ld_x, &zero, JpJ.data(),
                   &ld_out);
        for (int r = 0; r < n; ++r)
            for (int c = 0; c < n; ++c) P[r * n + c] = (r == c ? 1.0 : 0.0) - JpJ[r * n + c];
        for (int k = 0; k < n; ++k) v[k] = posture[k] - q[k];
        int mv_m = n, mv_n = n, ld_p = n, inc = 1;
        dense.gemv(&tt, &mv_m, &mv_n, &one, P.data(), &ld_p, v.data(), &inc, &zero, d, &inc);
        double sum = 0.0;  // np.sum(d * d): in order
        for (int k = 0; k < n; ++k) sum += d[k] * d[k];
        *norm = std::sqrt(sum);
        return POSTURE_OK;
    }
};

}  // namespace

bool spatial_ik(const SpatialIKArm& arm, const IKSettings& settings, const double* target, double* q) {
    double R_target[9];
    plants::rotation_zyx(target + 3, R_target);
    return spatial_dls(arm, settings, target, R_target, q);
}

PostureStatus spatial_refine_posture(const SpatialIKArm& arm, const IKSettings& settings, const DenseRoutines& dense,
                                     const double* posture, const double* target, double* q) {
    const int n = arm.dof();
    double R_target[9];
    plants::rotation_zyx(target + 3, R_target);
    std::vector<double> d(n), d_new(n), trial(n);
    NullSpace null_space(arm, dense);
    double r = 0.0;
    PostureStatus status = null_space(posture, q, d.data(), &r);
    if (status != POSTURE_OK) return status;
    double step = settings.posture_step;
    for (int it = 0; it < settings.posture_iterations; ++it) {
        if (r <= 1e-10) break;
        for (int k = 0; k < n; ++k) trial[k] = std::min(std::max(q[k] + step * d[k], arm.lower[k]), arm.upper[k]);
        if (spatial_dls(arm, settings, target, R_target, trial.data())) {
            double r_new = 0.0;
            status = null_space(posture, trial.data(), d_new.data(), &r_new);
            if (status != POSTURE_OK) return status;
            if (r_new < r) {
                std::copy(trial.begin(), trial.end(), q);
                std::swap(d, d_new);
                r = r_new;
                step = std::min(1.0, 2.0 * step);
                continue;
            }
        }
        step *= 0.5;
        if (step < 1e-3) break;
    }
    return POSTURE_OK;
}

bool planar_ik(const PlanarIKArm& arm, const IKSettings& settings, const double* target, double* q) {
    const int n = arm.arm.dof;
    std::vector<double> dq(n, 0.0), H(n * n), h(n), chain((n + 1) * plants::PLANAR_WORK_WIDTH);
    double Y[3], Jdq[3];
    DLSWork w(3, n);
    auto error = [&](const double* qq, double* Je, double* e) {
        plants::planar_arm_terms(arm.arm, qq, dq.data(), H.data(), n, h.data(), Y, Je, n, Jdq, chain.data());
        e[0] = target[0] - Y[0];
        e[1] = target[1] - Y[1];
        e[2] = wrap_angle(target[2] - Y[2]);
        return e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    };
    auto converged = [&](const double* e) {
        return std::sqrt(e[0] * e[0] + e[1] * e[1]) <= settings.tolerance && std::abs(e[2]) <= settings.tolerance;
    };
    return dls_minimize(w, 3, n, arm.lower, arm.upper, q, error, converged);
}

bool square_joint_rates(const double* J, int m, int p, int ldJ, const double* dY, int lddY, const int64_t* dofs,
                        double* out, int ldout) noexcept {
    double A[36], b[6];  // p <= 6
    for (int i = 0; i < m; ++i) {
        if (dofs[i] != p) return false;
        const double* Ji = J + static_cast<long>(i) * p * ldJ;
        double* oi = out + static_cast<long>(i) * ldout;
        for (int r = 0; r < p; ++r) {
            b[r] = dY[(i + 1) * lddY + r];
            for (int c = 0; c < p; ++c) A[r * p + c] = Ji[r * ldJ + c];
        }
        for (int c = 0; c < p; ++c) {
            int piv = c;
            for (int r = c + 1; r < p; ++r)
                if (std::abs(A[r * p + c]) > std::abs(A[piv * p + c])) piv = r;
            if (A[piv * p + c] == 0.0) return false;
            if (piv != c) {
                for (int k = 0; k < p; ++k) std::swap(A[c * p + k], A[piv * p + k]);
                std::swap(b[c], b[piv]);
            }
            for (int r = c + 1; r < p; ++r) {
                const double f = A[r * p + c] / A[c * p + c];
                for (int k = c; k < p; ++k) A[r * p + k] -= f * A[c * p + k];
                b[r] -= f * b[c];
            }
        }
        for (int r = p - 1; r >= 0; --r) {
            double s = b[r];
            for (int k = r + 1; k < p; ++k) s -= A[r * p + k] * oi[k];
            oi[r] = s / A[r * p + r];
        }
    }
    return true;
}

}  // namespace coopctrl
