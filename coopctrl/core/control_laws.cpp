#include "coopctrl/core/control_laws.h"

#include <cmath>

#include "coopctrl/core/angle_wrap.h"
#include "coopctrl/core/linear_algebra.h"
#include "plants/core/frames.h"

namespace coopctrl {

namespace {

/// F = W a + w_free + S, the node's wrench on the arm [N, N m].
void node_wrench(const double* W, const double* w_free, const double* S, const double* a_cmd, int p,
                 double* F) noexcept {
    for (int r = 0; r < p; ++r) {
        double s = w_free[r] + S[r];
        for (int c = 0; c < p; ++c) s += W[r * p + c] * a_cmd[c];
        F[r] = s;
    }
}

}  // namespace

bool node_torque(const double* W, const double* w_free, const double* S, const double* H, int ldH, const double* h,
                 const double* J, int ldJ, const double* Jdq, const double* a_cmd, bool contact_point, int n, int p,
                 ControlWork& work, double* tau) noexcept {
    double* F = work.vector(0);
    node_wrench(W, w_free, S, a_cmd, p, F);
    if (contact_point) {
        for (int r = 0; r < p; ++r) tau[r] = F[r];
        return true;
    }
    double* rhs = work.vector(1);
    double* qdd = work.vector(2);
    for (int r = 0; r < p; ++r) rhs[r] = a_cmd[r] - Jdq[r];
    const bool ok = lu_factor(J, ldJ, n, work.matrix(0), work.nmax, work.piv);
    if (ok)
        lu_solve_factored(work.matrix(0), work.nmax, work.piv, n, rhs, qdd);
    else
        for (int c = 0; c < n; ++c) qdd[c] = 0.0;
    for (int r = 0; r < n; ++r) {
        double s = h[r];
        for (int c = 0; c < n; ++c) s += H[r * ldH + c] * qdd[c];
        for (int c = 0; c < p; ++c) s += J[c * ldJ + r] * F[c];
        tau[r] = s;
    }
    return ok;
}

bool node_torque_redundant(const double* W, const double* w_free, const double* S, const double* H, int ldH,
                           const double* h, const double* J, int ldJ, const double* Jdq, const double* a_cmd,
                           const double* tau_posture, int n, int p, ControlWork& work, double* tau) noexcept {
    const int ld = work.nmax;
    double* F = work.vector(0);
    node_wrench(W, w_free, S, a_cmd, p, F);
    double* rhs = work.vector(3);
    for (int r = 0; r < p; ++r) rhs[r] = a_cmd[r] - Jdq[r];
    double* qdd = work.vector(4);
    if (!consistent_acceleration(W, p, H, ldH, J, ldJ, p, rhs, n, work.vectors, work.matrices, ld, work.piv, qdd)) {
        for (int c = 0; c < n; ++c) tau[c] = 0.0;
        return false;
    }
    // the null space: tau_0 - J^T A^-1 X^T tau_0 (X^T = J N^-1); A is factored in matrix 3, piv
    const double* X = work.matrix(1);
    double* z = work.vector(5);
    for (int c = 0; c < p; ++c) {
        double s = 0.0;
        for (int r = 0; r < n; ++r) s += X[r * ld + c] * tau_posture[r];
        z[c] = s;
    }
    lu_solve_factored(work.matrix(3), ld, work.piv, p, z, z);
    for (int r = 0; r < n; ++r) {
        double s = 0.0;
        for (int c = 0; c < n; ++c) s += H[r * ldH + c] * qdd[c];
        double jf = 0.0, jz = 0.0;
        for (int a = 0; a < p; ++a) {
            jf += J[a * ldJ + r] * F[a];
            jz += J[a * ldJ + r] * z[a];
        }
        tau[r] = (((h[r] + s) + jf) + tau_posture[r]) - jz;
    }
    return true;
}

void pose_error(const double* target, const double* Y, int p, int npos, double* out) noexcept {
    for (int a = 0; a < p; ++a) {
        double e = target[a] - Y[a];
        if (a >= npos) e = wrap_angle(e);
        out[a] = e;
    }
}

void acceleration_from_error(const double* err, const double* dY_ref, const double* dY, const double* ddY_ref,
                             double Kp, double Kd, int p, double* a_cmd) noexcept {
    for (int a = 0; a < p; ++a) a_cmd[a] = ddY_ref[a] + Kd * (dY_ref[a] - dY[a]) + Kp * err[a];
}

void tracking_acceleration(const double* target, const double* Y, const double* dY_ref, const double* dY,
                           const double* ddY_ref, double Kp, double Kd, int p, int npos, double* err,
                           double* a_cmd) noexcept {
    pose_error(target, Y, p, npos, err);
    acceleration_from_error(err, dY_ref, dY, ddY_ref, Kp, Kd, p, a_cmd);
}

void leader_target(const double* Y_nominal, const double* increment, const double* offset, int p,
                   double* out) noexcept {
    for (int a = 0; a < p; ++a) out[a] = Y_nominal[a] + increment[a] + offset[a];
}

void follower_correction(const double* F_cmd, const double* F_seen, double* integral, double T, double kp,
                         double ki, double integral_limit, bool force_loop, int p, double* corr) noexcept {
    for (int a = 0; a < p; ++a) corr[a] = F_cmd[a];
    if (!force_loop) return;
    for (int a = 0; a < p; ++a) {
        const double e = F_cmd[a] - F_seen[a];
        double v = integral[a] + e * T;
        if (v < -integral_limit)
            v = -integral_limit;
        else if (v > integral_limit)
            v = integral_limit;
        integral[a] = v;
        corr[a] = F_cmd[a] + kp * e + ki * v;
    }
}

bool pose_increment(bool spatial, const double* C, const double* F, const double* Y0, const double* Yi,
                    ControlWork& work, double* out) noexcept {
    if (!spatial) {
        const auto [s, c] = plants::sin_cos(Y0[2]);
        const double f0 = c * F[0] + s * F[1];
        const double f1 = -s * F[0] + c * F[1];
        const double f2 = F[2];
        const double d0 = C[0] * f0 + C[1] * f1 + C[2] * f2;
        const double d1 = C[3] * f0 + C[4] * f1 + C[5] * f2;
        const double d2 = C[6] * f0 + C[7] * f1 + C[8] * f2;
        out[0] = c * d0 - s * d1;
        out[1] = s * d0 + c * d1;
        out[2] = d2;
        return true;
    }
    double* R0 = work.R;
    double* Ri = work.R + 9;
    double* Linv = work.R + 18;
    double* Fo = work.v;
    double* d = work.v + 6;
    double* dth = work.v + 12;
    plants::rotation_zyx(Y0 + 3, R0);
    for (int a = 0; a < 3; ++a) {
        Fo[a] = R0[0 * 3 + a] * F[0] + R0[1 * 3 + a] * F[1] + R0[2 * 3 + a] * F[2];
        Fo[3 + a] = R0[0 * 3 + a] * F[3] + R0[1 * 3 + a] * F[4] + R0[2 * 3 + a] * F[5];
    }
    for (int a = 0; a < 6; ++a) {
        double s = 0.0;
        for (int b = 0; b < 6; ++b) s += C[a * 6 + b] * Fo[b];
        d[a] = s;
    }
    for (int a = 0; a < 3; ++a) {
        out[a] = R0[a * 3 + 0] * d[0] + R0[a * 3 + 1] * d[1] + R0[a * 3 + 2] * d[2];
        dth[a] = R0[a * 3 + 0] * d[3] + R0[a * 3 + 1] * d[4] + R0[a * 3 + 2] * d[5];
    }
    if (!plants::body_rate_map_inverse(Yi + 3, Linv)) {
        for (int a = 0; a < 3; ++a) out[3 + a] = 0.0;
        return false;
    }
    plants::rotation_zyx(Yi + 3, Ri);
    double* wb = work.v;  // Fo is no longer needed
    for (int a = 0; a < 3; ++a)
        wb[a] = Ri[0 * 3 + a] * dth[0] + Ri[1 * 3 + a] * dth[1] + Ri[2 * 3 + a] * dth[2];
    for (int a = 0; a < 3; ++a)
        out[3 + a] = Linv[a * 3 + 0] * wb[0] + Linv[a * 3 + 1] * wb[1] + Linv[a * 3 + 2] * wb[2];
    return true;
}

bool follower_acceleration(bool spatial, const double* C, const double* corr, const double* Y0,
                           const double* Y_rigid, const double* Y, const double* dY_ref, const double* dY,
                           const double* ddY_ref, double Kp, double Kd, int p, int npos, ControlWork& work,
                           double* target, double* err, double* a_cmd) noexcept {
    if (!pose_increment(spatial, C, corr, Y0, Y_rigid, work, target)) return false;
    for (int a = 0; a < p; ++a) target[a] += Y_rigid[a];
    tracking_acceleration(target, Y, dY_ref, dY, ddY_ref, Kp, Kd, p, npos, err, a_cmd);
    return true;
}

void posture_torque(const double* H, int ldH, const double* q, const double* dq, const double* q_rest, int n,
                    double Kp, double Kd, double* out) noexcept {
    double tr = 0.0;
    for (int c = 0; c < n; ++c) tr += H[c * ldH + c];
    const double m_bar = tr / n;
    for (int c = 0; c < n; ++c) out[c] = m_bar * (Kp * (q_rest[c] - q[c]) - Kd * dq[c]);
}

bool arm_torque(bool contact, int n, int p, const double* W, const double* w_free, const double* S,
                const double* H, int ldH, const double* h, const double* J, int ldJ, const double* Jdq,
                const double* a_cmd, const double* q, const double* dq, const double* q_rest,
                const double* posture_gain, ControlWork& work, double* tau) noexcept {
    if (!contact && n > p) {
        posture_torque(H, ldH, q, dq, q_rest, n, posture_gain[0], posture_gain[1], work.posture);
        return node_torque_redundant(W, w_free, S, H, ldH, h, J, ldJ, Jdq, a_cmd, work.posture, n, p, work, tau);
    }
    return node_torque(W, w_free, S, H, ldH, h, J, ldJ, Jdq, a_cmd, contact, n, p, work, tau);
}

}  // namespace coopctrl
