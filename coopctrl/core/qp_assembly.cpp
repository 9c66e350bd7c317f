#include "coopctrl/core/qp_assembly.h"

#include <cmath>

#include "coopctrl/core/linear_algebra.h"
#include "plants/core/cholesky.h"

namespace coopctrl {

void fill_grasp_rows(double* M, int ldM, const double* r, int m, int npos, const double* r0, bool spatial) noexcept {
    if (spatial) {
        for (int i = 0; i < m; ++i) {
            const double d0 = r[i * npos + 0] - r0[0];
            const double d1 = r[i * npos + 1] - r0[1];
            const double d2 = r[i * npos + 2] - r0[2];
            const int c = 6 * i;
            M[3 * ldM + c + 1] = -d2;
            M[3 * ldM + c + 2] = d1;
            M[4 * ldM + c + 0] = d2;
            M[4 * ldM + c + 2] = -d0;
            M[5 * ldM + c + 0] = -d1;
            M[5 * ldM + c + 1] = d0;
        }
    } else {
        for (int i = 0; i < m; ++i) {
            M[2 * ldM + 3 * i] = -(r[i * npos + 1] - r0[1]);
            M[2 * ldM + 3 * i + 1] = r[i * npos + 0] - r0[0];
        }
    }
}

bool pseudo_inverse_external(const double* M, int ldM, int k, const double* W_inv_diag, int n, const double* w,
                             double* external, double* A, int ldA, double* y) noexcept {
    for (int a = 0; a < k; ++a) {
        for (int b = a; b < k; ++b) {
            double s = 0.0;
            for (int c = 0; c < n; ++c) s += M[a * ldM + c] * W_inv_diag[c] * M[b * ldM + c];
            A[a * ldA + b] = s;
            A[b * ldA + a] = s;
        }
    }
    if (!plants::cholesky_solve(A, ldA, w, y, k)) return false;  // A = L L^T in place (lower triangle), then A y = w
    for (int c = 0; c < n; ++c) {
        double s = 0.0;
        for (int a = 0; a < k; ++a) s += M[a * ldM + c] * y[a];
        external[c] = W_inv_diag[c] * s;
    }
    return true;
}

bool fill_squeeze_basis(double* E, int ldE, const double* r, int m, int npos, int k) noexcept {
    int col = 0;
    for (int i = 0; i < m; ++i) {
        for (int j = i + 1; j < m; ++j) {
            double s = 0.0;
            for (int a = 0; a < npos; ++a) {
                const double t = r[j * npos + a] - r[i * npos + a];
                s += t * t;
            }
            const double length = std::sqrt(s);
            if (length < 1e-12) return false;
            for (int a = 0; a < npos; ++a) {
                const double t = (r[j * npos + a] - r[i * npos + a]) / length;
                E[(k * i + a) * ldE + col] = t;
                E[(k * j + a) * ldE + col] = -t;
            }
            col += 1;
        }
    }
    return true;
}

void fill_grip_rows(double* M, int ldM, int row0, const double* nrm, int m, int npos, int k) noexcept {
    for (int i = 0; i < m; ++i)
        for (int a = 0; a < npos; ++a) M[(row0 + i) * ldM + k * i + a] = nrm[i * npos + a];
}

void fill_friction_rows(double* M, int ldM, int row0, const double* nrm, int ldn, int m, int k, int nf, double mu_c,
                        const double* cos_phi, const double* sin_phi, bool spatial) noexcept {
    for (int i = 0; i < m; ++i) {
        if (spatial) {
            const double nx = nrm[i * ldn + 0], ny = nrm[i * ldn + 1], nz = nrm[i * ldn + 2];
            double ax, ay, az;
            if (std::abs(nx) < 0.9) {
                ax = 1.0 - nx * nx;
                ay = -nx * ny;
                az = -nx * nz;
            } else {
                ax = -ny * nx;
                ay = 1.0 - ny * ny;
                az = -ny * nz;
            }
            const double s = 1.0 / std::sqrt(ax * ax + ay * ay + az * az);
            const double t1x = ax * s, t1y = ay * s, t1z = az * s;
            const double t2x = ny * t1z - nz * t1y;
            const double t2y = nz * t1x - nx * t1z;
            const double t2z = nx * t1y - ny * t1x;
            for (int f = 0; f < nf; ++f) {
                double* row = M + static_cast<long>(row0 + nf * i + f) * ldM;
                const double c = cos_phi[f], sn = sin_phi[f];
                row[k * i] = c * t1x + sn * t2x - mu_c * nx;
                row[k * i + 1] = c * t1y + sn * t2y - mu_c * ny;
                row[k * i + 2] = c * t1z + sn * t2z - mu_c * nz;
            }
        } else {
            const double nx = nrm[i * ldn + 0], nz = nrm[i * ldn + 1];
            double* row = M + static_cast<long>(row0 + 2 * i) * ldM;
            row[k * i] = -nz - mu_c * nx;
            row[k * i + 1] = nx - mu_c * nz;
            row[ldM + k * i] = nz - mu_c * nx;
            row[ldM + k * i + 1] = -nx - mu_c * nz;
        }
    }
}

void fill_torque_rows(double* M, double* lo, double* hi, int ldM, int row0, const double* Jg, long arm_stride,
                      int ldJ, const int64_t* dofs, int m, int k, const double* tau_qp, const double* bias) noexcept {
    int row = row0;
    int j = 0;
    for (int i = 0; i < m; ++i) {
        const double* Ji = Jg + i * arm_stride;
        for (int64_t r = 0; r < dofs[i]; ++r) {
            for (int a = 0; a < k; ++a) M[static_cast<long>(row) * ldM + k * i + a] = Ji[a * ldJ + r];
            hi[row] = tau_qp[j] - bias[j];
            lo[row] = -tau_qp[j] - bias[j];
            row += 1;
            j += 1;
        }
    }
}

}  // namespace coopctrl
