#include "coopctrl/core/qp_contact_model.h"

#include <cmath>

#include "coopctrl/core/linear_algebra.h"
#include "plants/core/frames.h"

namespace coopctrl {

void contact_normals(const double* Y, int ldY, bool spatial, double* nrm, int ldn, int m, double* R) noexcept {
    const int npos = spatial ? 3 : 2;
    for (int i = 0; i < m; ++i) {
        double* ni = nrm + static_cast<long>(i) * ldn;
        const double* Yk = Y + static_cast<long>(i + 1) * ldY;
        if (spatial) {
            plants::rotation_zyx(Yk + 3, R);
            for (int a = 0; a < 3; ++a) ni[a] = R[a * 3 + 0];
        } else {
            ni[0] = std::cos(Yk[2]);
            ni[1] = std::sin(Yk[2]);
        }
        double s = 0.0;
        for (int a = 0; a < npos; ++a) s += ni[a] * ni[a];
        const double length = std::sqrt(s);
        for (int a = 0; a < npos; ++a) ni[a] = ni[a] / length;
    }
}

void torque_model(bool spatial, const TorqueModelInputs& in, TorqueModel& out, TorqueModelWork& work) noexcept {
    const int m = in.m;
    const int p = spatial ? 6 : 3;
    const int nmax = in.nmax;
    const int nJ = out.Jg_cols;
    double* Wa = work.Wa;
    double* rhs_t = work.rhs_t;
    double* qdd = work.qdd;
    long j0 = 0;
    for (int i = 0; i < m; ++i) {
        const int ni = static_cast<int>(in.arm_dof[i]);
        const int kk = i + 1;
        const double* Wk = in.W + static_cast<long>(kk) * p * p;
        double* Jgi = out.Jg + static_cast<long>(i) * p * nJ;
        // W_k ddYn_k + w_free_k
        for (int a = 0; a < p; ++a) {
            double s = in.w_free[kk * p + a];
            for (int b = 0; b < p; ++b) s += Wk[a * p + b] * in.ddYn[kk * p + b];
            Wa[a] = s;
        }
        if (in.arm_kind[i] != 0) {  // contact point: tau = F + W a + w
            for (int a = 0; a < p; ++a) {
                for (int b = 0; b < p; ++b) Jgi[a * nJ + b] = a == b ? 1.0 : 0.0;
                out.bias[j0 + a] = Wa[a];
            }
            j0 += ni;
            continue;
        }
        const double* Ji = in.J + static_cast<long>(i) * p * nmax;  // (p, nmax): columns :ni are the arm's
        const double* Hi = in.H + static_cast<long>(i) * nmax * nmax;
        for (int a = 0; a < p; ++a) rhs_t[a] = in.ddYn[kk * p + a] - in.Jdq[i * p + a];
        bool okq;
        if (ni == p)
            okq = lu_solve(Ji, nmax, rhs_t, p, work.wm, work.ldw, work.piv, qdd);
        else
            okq = consistent_acceleration(Wk, p, Hi, nmax, Ji, nmax, p, rhs_t, ni, work.wv, work.wm, work.ldw,
                                          work.piv, qdd);
        if (!okq)
            for (int c = 0; c < ni; ++c) qdd[c] = 0.0;
        for (int r = 0; r < ni; ++r) {
            double s = in.h[i * nmax + r];
            for (int c = 0; c < ni; ++c) s += Hi[r * nmax + c] * qdd[c];
            for (int a = 0; a < p; ++a) s += Ji[a * nmax + r] * Wa[a];
            out.bias[j0 + r] = s;
        }
        if (spatial) {
            // R(A) L(A): the analytic Jacobian's angular rows to world angular velocity
            double* RA = work.R3;
            double* LA = work.R3 + 9;
            double* RL = work.R3 + 18;
            const double* A = in.Y + static_cast<long>(kk) * p + 3;
            plants::rotation_zyx(A, RA);
            plants::body_rate_map(A, LA);
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b)
                    RL[a * 3 + b] = RA[a * 3 + 0] * LA[0 * 3 + b] + RA[a * 3 + 1] * LA[1 * 3 + b] +
                                    RA[a * 3 + 2] * LA[2 * 3 + b];
            for (int r = 0; r < ni; ++r) {
                for (int a = 0; a < 3; ++a) {
                    Jgi[a * nJ + r] = Ji[a * nmax + r];
                    double s = 0.0;
                    for (int b = 0; b < 3; ++b) s += RL[a * 3 + b] * Ji[(3 + b) * nmax + r];
                    Jgi[(3 + a) * nJ + r] = s;
                }
            }
        } else {
            for (int r = 0; r < ni; ++r)
                for (int a = 0; a < p; ++a) Jgi[a * nJ + r] = Ji[a * nmax + r];
        }
        j0 += ni;
    }
}

}  // namespace coopctrl
